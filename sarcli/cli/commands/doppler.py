"""``sarcli doppler``: Doppler centroid (with ambiguity) and Doppler rate of a raw product -> doppler.h5."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress_bar
from sarcli.errors import SarcliError

JSON_BLOCK_KEYS = ("range_m", "azimuth_time_s", "fdc_baseband_hz", "quality", "ambiguity", "fdc_hz", "fr_hz_per_s",
                   "valid", "outlier", "margin_prf")


def _degrees(text: str, name: str) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in text.split(","))
    except ValueError:
        raise SarcliError(f"{name} must be 'RANGE,AZIMUTH' degrees, e.g. 2,1; got {text!r}") from None
    if not (0 <= a <= 6 and 0 <= b <= 6):
        raise SarcliError(f"{name} degrees must be in 0..6, got {text!r}")
    return a, b


def doppler(
    raw_path: Path = typer.Argument(..., help="Raw product (HDF5) from 'sarcli simulate' or 'sarcli ingest'."),
    output: Path = typer.Option(None, "-o", "--output", help="Doppler product to write (default: none)."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary and the block table as JSON."),
    plot: Path = typer.Option(None, "--plot", help="PNG of fdc and fr against range and azimuth."),
    estimator: str = typer.Option("cde", "--estimator",
                                  help="cde | sde | rc-cde (CDE after range compression) | lb (look balance on "
                                       "the focused scene: robust to scene contrast, needs > 2 look apertures)."),
    gain_steps: str = typer.Option("auto", "--gain-steps",
                                   help="Receiver-gain steps recovered from the echo and undone: auto (quantized "
                                        "products without AGC records) | on | off."),
    lb_band: float = typer.Option(0.6, "--lb-band", help="Look-balance processed band, fraction of the PRF."),
    az_block: int = typer.Option(2048, "--az-block", help="Azimuth lines per block (seed: 2048)."),
    rg_block: int = typer.Option(128, "--rg-block", help="Range samples per block (seed: 128)."),
    ambiguity: str = typer.Option("auto", "--ambiguity",
                                  help="auto | orbit | data (MLCC+MLBF) | none; auto = orbit if present."),
    ambiguity_value: int = typer.Option(None, "--ambiguity-value", help="Force the scene ambiguity number."),
    fr_method: str = typer.Option("auto", "--fr-method",
                                  help="auto | orbit (exact d2R/deta2) | seed (look angle re-solved) | mapdrift."),
    fdc_model: str = typer.Option("vector", "--fdc-model", help="Geometric model: vector | closed (seed eq. 6)."),
    fit_degree: str = typer.Option("2,1", "--fit-degree", help="Block fit degrees RANGE,AZIMUTH (no orbit)."),
    n_nodes: int = typer.Option(None, "--hermite-nodes", help="Hermite interpolation nodes (default: orbit's)."),
    small_angle: bool = typer.Option(False, "--small-angle", help="Small-angle attitude rotation (seed)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No human-readable summary on stderr."),
) -> None:
    """Estimate the Doppler centroid (baseband CDE + ambiguity) and the Doppler rate.

    The baseband centroid comes from the echoes (CDE per block, seed 2048 x 128); the PRF ambiguity
    from the orbit + attitude model when the product has state vectors, else from the data (MLCC +
    MLBF, with a confidence); the Doppler rate exactly from the orbit, or by map-drift autofocus.

    Examples:

      sarcli doppler raw.h5 -o doppler.h5

      sarcli doppler raw.h5 --json --plot doppler.png

      sarcli doppler vancouver.h5 --ambiguity data --az-block 1536 --json

      sarcli doppler vancouver.h5 --estimator lb --az-block 512
    """
    from sarcli.doppler.api import estimate_doppler
    from sarcli.io.doppler_product import write_doppler
    from sarcli.io.raw import read_raw

    degrees = _degrees(fit_degree, "--fit-degree")
    raw = read_raw(raw_path)
    with progress_bar(5, label="doppler") as bar:
        model = estimate_doppler(raw, az_block=az_block, rg_block=rg_block, estimator=estimator,
                                 ambiguity=ambiguity, ambiguity_value=ambiguity_value, fr_method=fr_method,
                                 fdc_model=fdc_model, fit_degree=degrees, n_nodes=n_nodes,
                                 exact_attitude=not small_angle, gain_steps=gain_steps, lb_band_fraction=lb_band,
                                 progress=lambda _stage: bar.update(1))
    if output is not None:
        write_doppler(output, model, inputs=(raw_path,))
    if plot is not None:
        from sarcli.doppler.plot import plot_doppler

        plot_doppler(plot, model)
    s = model.summary
    info(f"fdc {s['fdc_hz']:.2f} Hz = baseband {s['fdc_baseband_hz']:.2f} Hz + ({s['ambiguity']}) x PRF "
         f"[{s['ambiguity_source']}, confidence {s['ambiguity_confidence']:.3f}, margin "
         f"{s['ambiguity_margin_prf']:.3f} PRF]; fr {s['fr_hz_per_s']:.3f} Hz/s [{s['fr_method']}]; "
         f"{s['n_valid_blocks']}/{s['n_blocks']} blocks valid, {s['n_outlier_blocks']} flagged", quiet or as_json)
    if s.get("gain_steps"):
        info(f"undid {len(s['gain_steps'])} receiver-gain step(s) found in the echo (line, dB): "
             + ", ".join(f"{m} {d:+.2f}" for m, d in s["gain_steps"]), quiet or as_json)
    if as_json:
        out = dict(s)
        out["output"] = str(output) if output is not None else None
        n = len(model.blocks["range_m"])
        out["blocks"] = [{k: model.blocks[k][i] for k in JSON_BLOCK_KEYS} for i in range(n)]
        emit_json(out)


def register(app: typer.Typer) -> None:
    app.command("doppler")(doppler)
