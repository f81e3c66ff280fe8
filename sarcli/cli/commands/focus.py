"""``sarcli focus``: raw echo product -> focused SLC (HDF5), amplitude GeoTIFFs and a quicklook.

Parses the options into :class:`sarcli.workflows.focus.Config`, runs the workflow, prints the report.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress_bar
from sarcli.errors import ConfigError

# option -> the focuser option it sets (only when given: a focuser gets what the user asked for)
_KNOBS = {"range_window": "range_window", "azimuth_window": "azimuth_window",
          "azimuth_bandwidth": "azimuth_bandwidth_hz", "range_band_fraction": "range_bandwidth_fraction",
          "rcmc": "rcmc", "rcmc_oversample": "rcmc_oversample", "orbit_timing": "orbit_timing", "src": "src",
          "block_lines": "block_lines", "replica": "use_replica"}


def focus(
    raw_path: Path = typer.Argument(..., help="Raw echo product (HDF5, from simulate or ingest)."),
    output: Path = typer.Option(..., "-o", "--output", help="SLC product to write (HDF5)."),
    doppler: Path = typer.Option(None, "--doppler", help="Doppler product (from 'sarcli doppler'); "
                                 "estimated from the data when omitted."),
    fdc: float = typer.Option(None, "--fdc", help="Use this absolute Doppler centroid (Hz) instead (with --fr)."),
    fr: float = typer.Option(None, "--fr", help="Use this Doppler rate (Hz/s, negative) at mid-swath (with --fdc)."),
    accept_unresolved: bool = typer.Option(False, "--accept-unresolved-ambiguity",
                                           help="Use a Doppler model whose PRF ambiguity is unresolved."),
    algorithm: str = typer.Option("rd", "--algorithm", help="Focuser: rd (Range-Doppler), backprojection, "
                                  "ffbp (fast factorized backprojection), optical, a plug-in, or auto (the cheapest "
                                  "whose predicted error meets --quality)."),
    quality: str = typer.Option(None, "--quality", help="What --algorithm auto must meet, e.g. "
                                "irw=0.02,pslr=1,phase=0.1 (the default: IRW within 2 %, PSLR within 1 dB, peak "
                                "phase within 0.1 rad of the ideal; time=SECONDS: the longest predicted run)."),
    channel: int = typer.Option(0, "--channel", help="Receive channel to focus (0 = /echo)."),
    height: float = typer.Option(0.0, "--height", help="Terrain height above the WGS-84 ellipsoid, m (default 0)."),
    dem: Path = typer.Option(None, "--dem", help="DEM raster (any GDAL format and CRS) for the terrain."),
    dem_geoid: str = typer.Option(None, "--dem-geoid", metavar="[egm96|egm2008]",
                                  help="The DEM's heights are above this geoid: egm96 | "
                                  "egm2008 (default: above the ellipsoid)."),
    range_window: str = typer.Option(None, "--range-window", help="rect | hamming[:a] | kaiser[:beta] "
                                     "(default kaiser:2.5)."),
    azimuth_window: str = typer.Option(None, "--azimuth-window", help="rect | hamming[:a] | kaiser[:beta]."),
    azimuth_bandwidth: float = typer.Option(None, "--azimuth-bandwidth", help="Processed Doppler band, Hz "
                                            "(default 0.8 PRF)."),
    range_band_fraction: float = typer.Option(None, "--range-band-fraction", help="Processed part of the chirp "
                                              "band (0..1], default 1."),
    rcmc: str = typer.Option(None, "--rcmc", help="RCMC interpolator: nearest, linear, sinc4, sinc8 (default), "
                             "sinc16."),
    rcmc_oversample: int = typer.Option(None, "--rcmc-oversample", help="Range upsampling before RCMC (1 or 2)."),
    orbit_timing: bool = typer.Option(None, "--orbit-timing/--no-orbit-timing", help="Correct the zero-Doppler "
                                      "time and phase of the hyperbolic model from the orbit (default on)."),
    src: bool = typer.Option(None, "--src/--no-src", help="Secondary range compression (default on)."),
    double: bool = typer.Option(False, "--double", help="Process in complex128 (default complex64)."),
    block_lines: int = typer.Option(None, "--block-lines", help="Lines per block (memory; the image does not "
                                    "depend on it). RD default 4096."),
    replica: bool = typer.Option(None, "--replica/--no-replica", help="Use the product's chirp replica."),
    sets: list[str] = typer.Option(None, "--set", help="KEY=VALUE option of the focuser (JSON value, else a "
                                   "string); repeatable. Overrides the options above."),
    geotiff: Path = typer.Option(None, "--geotiff", help="Map-projected amplitude GeoTIFF (UTM, or --crs)."),
    geotiff_slant: Path = typer.Option(None, "--geotiff-slant", help="Slant-range amplitude GeoTIFF with "
                                       "lat/lon GCPs."),
    crs: str = typer.Option(None, "--crs", help="CRS of --geotiff, e.g. EPSG:32610 (default: UTM zone)."),
    spacing: float = typer.Option(None, "--pixel-spacing", help="Map pixel spacing, m (default: the coarser "
                                  "of ground range and azimuth)."),
    geotiff_compression: str = typer.Option(
        "deflate", "--geotiff-compression", metavar="[deflate|zstd|none]",
        help="Tile compression of the GeoTIFFs: deflate (the widest support), zstd (about 2x faster to "
             "compress, same size; GDAL >= 2.3 reads it) or none (twice the size: no-data corners stored whole)."),
    looks_az: int = typer.Option(1, "--looks-az", help="Azimuth looks for the GeoTIFFs/quicklook."),
    looks_rg: int = typer.Option(1, "--looks-rg", help="Range looks for the GeoTIFFs/quicklook."),
    quicklook: Path = typer.Option(None, "--quicklook", help="Quicklook PNG of the amplitude (dB)."),
    radiometry: str = typer.Option(None, "--radiometry", metavar="[beta0|sigma0|gamma0]",
                                   help="GeoTIFFs in calibrated backscatter (dB band, units in the tags); gamma0 "
                                   "terrain-flattened over --dem."),
    noise_subtraction: bool = typer.Option(False, "--noise-subtraction", help="Subtract the noise floor (NESZ) "
                                           "from the --radiometry GeoTIFFs."),
    workers: int = typer.Option(None, "--workers", help="Focus the blocks in parallel on a local Dask cluster of "
                                "this many processes (the same image)."),
    scheduler: str = typer.Option(None, "--scheduler", metavar="ADDRESS", help="Focus the blocks on this Dask "
                                  "scheduler (tcp://host:8786; the raw file must be visible to its workers)."),
    device: str = typer.Option(None, "--device", metavar="[cpu|cuda]", envvar="SARCLI_DEVICE",
                               help="Where the focuser runs: cpu (default) or cuda (rd, csa, omegak, backprojection "
                               "and ffbp; needs a GPU and the gpu extra, docs/parallel.md)."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON report on stdout."),
) -> None:
    """Focus a stripmap raw product into a single-look complex image.

    The Range-Doppler algorithm processes azimuth blocks with overlap (bounded memory; the image does
    not depend on the block size): range compression (replica or nominal chirp), optional SRC, RCMC
    in the range-Doppler domain with the range-dependent Doppler centroid and rate, azimuth matched
    filter, and a per-line correction to the model at each line's time. Lines of the SLC are
    zero-Doppler times. The Doppler comes from --doppler, from --fdc/--fr, or is estimated from the
    data; the terrain (orbit timing, backprojection, geocoding) from --height or --dem. --json
    reports the Doppler and rate used, the time per stage and the peak memory.

    Examples:

      sarcli focus raw.h5 -o slc.h5 --doppler doppler.h5 --geotiff amp.tif --quicklook q.png

      sarcli focus raw.h5 -o slc.h5 --geotiff-slant amp_sr.tif --crs EPSG:32610 --json

      sarcli focus vancouver.h5 -o slc.h5 --fdc -6900 --fr -1733 --looks-az 4 --quicklook q.png

      sarcli focus raw.h5 -o slc.h5 --dem srtm.tif --dem-geoid egm96 --geotiff amp.tif

      sarcli focus raw.h5 -o bp.h5 --algorithm backprojection --set lines=[900,1000] --range-window rect

      sarcli focus raw.h5 -o wk.h5 --algorithm omegak --set stolt_kernel=sinc8

      sarcli focus big_raw.h5 -o slc.h5 --fdc -6690 --fr -1990 --workers 2

      sarcli focus raw.h5 -o slc.h5 --device cuda    # on the GPU (pip install 'sarcli[gpu]')

      sarcli focus raw.h5 -o slc.h5 --geotiff sigma0.tif --radiometry sigma0 --looks-az 4

      sarcli focus raw.h5 -o slc.h5 --algorithm auto --quality irw=0.02,pslr=1,phase=0.1 --json
    """
    given = {"range_window": range_window, "azimuth_window": azimuth_window, "azimuth_bandwidth": azimuth_bandwidth,
             "range_band_fraction": range_band_fraction, "rcmc": rcmc, "rcmc_oversample": rcmc_oversample,
             "orbit_timing": orbit_timing, "src": src, "block_lines": block_lines, "replica": replica}
    if azimuth_bandwidth is not None and not (math.isfinite(azimuth_bandwidth) and azimuth_bandwidth > 0):
        raise ConfigError(f"--azimuth-bandwidth must be a positive number of Hz, got {azimuth_bandwidth}")
    if range_band_fraction is not None and not (math.isfinite(range_band_fraction) and 0 < range_band_fraction <= 1):
        raise ConfigError(f"--range-band-fraction must be in (0, 1], got {range_band_fraction}")
    options = {_KNOBS[k]: v for k, v in given.items() if v is not None}
    if double:
        options["precision"] = "double"
    options.update(parse_sets(sets or []))
    from sarcli.workflows.focus import Config, run

    config = Config(raw=raw_path, output=output, doppler=doppler, fdc=fdc, fr=fr, algorithm=algorithm,
                    options=options, height_m=height, dem=dem, dem_geoid=_geoid(dem_geoid), geotiff=geotiff,
                    geotiff_slant=geotiff_slant, geotiff_compression=geotiff_compression, quicklook=quicklook,
                    crs=crs, pixel_spacing_m=spacing,
                    looks_az=looks_az, looks_rg=looks_rg, channel=channel,
                    accept_unresolved_ambiguity=accept_unresolved, workers=workers, scheduler=scheduler,
                    radiometry=radiometry, noise_subtraction=noise_subtraction, device=_device(device),
                    quality=quality)
    with progress_bar(1, label="focusing") as bar:
        def progress(label: str, done: int, total: int) -> None:
            bar.length = total
            bar.update(1)

        rep = run(config, progress=progress)
    if as_json:  # the workflow has printed each warning once (its log); the report lists them
        emit_json(rep.to_dict())
    else:
        for line in rep.lines():
            info(line)


def _device(name: str | None) -> str | None:
    """``--device`` (or ``SARCLI_DEVICE``) checked: cpu | cuda, or None when neither is given."""
    if name is None or not name.strip():
        return None
    d = name.strip().lower()
    if d not in ("cpu", "cuda"):
        raise ConfigError(f"--device must be cpu or cuda, got {name!r}")
    return d


def _geoid(name: str | None):
    if name is not None and name not in ("egm96", "egm2008"):
        raise ConfigError(f"--dem-geoid must be egm96 or egm2008, got {name!r}")
    return name


def parse_sets(items: list[str]) -> dict:
    """``["a=1", "b=hamming"]`` -> {"a": 1, "b": "hamming"} (JSON values where they parse)."""
    out = {}
    for it in items:
        key, eq, val = it.partition("=")
        if not eq or not key.strip():
            raise ConfigError(f"--set {it!r}: expected KEY=VALUE")
        try:
            out[key.strip()] = json.loads(val)
        except json.JSONDecodeError:
            out[key.strip()] = val
    return out


def register(app: typer.Typer) -> None:
    app.command("focus")(focus)
