"""``sarcli doppler``: Doppler centroid (with ambiguity) and Doppler rate of a raw product -> doppler.h5.

Parses the options into a :class:`sarcli.workflows.doppler.Config`, runs the workflow, prints the report.
"""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress_bar, require_output_folders
from sarcli.errors import ConfigError


def _degrees(text: str, name: str) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in text.split(","))
    except ValueError:
        raise ConfigError(f"{name} must be 'RANGE,AZIMUTH' degrees, e.g. 2,1; got {text!r}") from None
    return a, b


def doppler(
    raw_path: Path = typer.Argument(..., help="Raw product (HDF5) from 'sarcli simulate' or 'sarcli ingest'."),
    output: Path = typer.Option(None, "-o", "--output", help="Doppler product to write (default: none)."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary and the block table as JSON."),
    plot: Path = typer.Option(None, "--plot", help="PNG of fdc and fr against range and azimuth."),
    height: float = typer.Option(0.0, "--height", help="Terrain height under the scene, metres above the WGS-84 "
                                 "ellipsoid (for the geometric model; stored in the product)."),
    dem: Path = typer.Option(None, "--dem", help="DEM raster (any GDAL format and CRS) for the terrain."),
    dem_geoid: str = typer.Option(None, "--dem-geoid", metavar="[egm96|egm2008]",
                                  help="The DEM's heights are above this geoid: egm96 | "
                                  "egm2008 (default: above the ellipsoid)."),
    estimator: str = typer.Option("cde", "--estimator",
                                  help="cde | sde | rc-cde (CDE after range compression) | lb (look balance on "
                                       "the focused scene: robust to scene contrast, needs > 2 look apertures) | "
                                       "a registered plug-in."),
    gain_steps: str = typer.Option("auto", "--gain-steps", metavar="[auto|on|off]",
                                   help="Receiver-gain steps recovered from the echo and undone: auto (quantized "
                                        "products without AGC records) | on | off."),
    lb_band: float = typer.Option(0.6, "--lb-band", help="Look-balance processed band, fraction of the PRF."),
    az_block: int = typer.Option(2048, "--az-block", help="Azimuth lines per block ([Koh2003, §5]: 2048)."),
    rg_block: int = typer.Option(128, "--rg-block", help="Range samples per block ([Koh2003, §5]: 128)."),
    ambiguity: str = typer.Option("auto", "--ambiguity", metavar="[auto|orbit|data|none]",
                                  help="auto | orbit | data (MLCC+MLBF) | none; auto = orbit if present."),
    ambiguity_value: int = typer.Option(None, "--ambiguity-value", help="Force the scene ambiguity number."),
    fr_method: str = typer.Option("auto", "--fr-method", metavar="[auto|orbit|seed|mapdrift]",
                                  help="auto | orbit (exact d2R/deta2) | seed ([Koh2003]: look angle re-solved) "
                                       "| mapdrift."),
    fdc_model: str = typer.Option("vector", "--fdc-model", metavar="[vector|closed]",
                                  help="Geometric model: vector | closed ([Koh2003, eq. 6])."),
    fit_degree: str = typer.Option("2,1", "--fit-degree", help="Block fit degrees RANGE,AZIMUTH (no orbit)."),
    n_nodes: int = typer.Option(None, "--hermite-nodes", help="Hermite interpolation nodes (default: orbit's)."),
    small_angle: bool = typer.Option(False, "--small-angle", help="Small-angle attitude rotation ([Koh2003, eq. 1])."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No human-readable summary on stderr."),
) -> None:
    """Estimate the Doppler centroid (baseband CDE + ambiguity) and the Doppler rate.

    The baseband centroid comes from the echoes (CDE per block, 2048 x 128 as in [Koh2003, §5]); the PRF ambiguity
    from the orbit + attitude model when the product has state vectors, else from the data (MLCC +
    MLBF, with a confidence); the Doppler rate exactly from the orbit, or by map-drift autofocus.
    An ambiguity nothing could decide is reported (ambiguity_resolved false) with a warning.

    Examples:

      sarcli doppler raw.h5 -o doppler.h5

      sarcli doppler raw.h5 --json --plot doppler.png --height 350

      sarcli doppler vancouver.h5 --ambiguity data --az-block 1536 --json

      sarcli doppler vancouver.h5 --estimator lb --az-block 512
    """
    from sarcli.config import from_mapping
    from sarcli.workflows.doppler import Config, run

    options = {"estimator": estimator, "gain_steps": gain_steps, "lb_band_fraction": lb_band, "az_block": az_block,
               "rg_block": rg_block, "ambiguity": ambiguity, "ambiguity_value": ambiguity_value,
               "fr_method": fr_method, "fdc_model": fdc_model, "fit_degree": _degrees(fit_degree, "--fit-degree"),
               "n_nodes": n_nodes, "exact_attitude": not small_angle}
    config = from_mapping(Config, {"raw": raw_path, "output": output, "plot": plot, "height_m": height, "dem": dem,
                                   "dem_geoid": dem_geoid,
                                   "options": options}, "sarcli doppler")
    require_output_folders(output, plot)
    with progress_bar(5, label="doppler") as bar:
        report = run(config, progress=lambda _stage, _done, _total: bar.update(1))
    for w in report.warnings:
        info(f"sarcli: warning: {w}")
    for line in report.lines():
        info(line, quiet or as_json)
    if as_json:
        emit_json(report.to_dict())


def register(app: typer.Typer) -> None:
    app.command("doppler")(doppler)
