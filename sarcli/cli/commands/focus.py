"""``sarcli focus``: raw echo product -> focused SLC (HDF5), amplitude GeoTIFFs and a quicklook."""

from __future__ import annotations

import resource
import time
import warnings
from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress_bar, require_output_folders
from sarcli.errors import SarcliError


def _doppler_model(raw, shape, doppler_path: Path | None, fdc: float | None, fr: float | None, quiet: bool):
    """The Doppler model: from doppler.h5, from published (fdc, fr), or estimated from the data now."""
    if doppler_path is not None:
        if fdc is not None or fr is not None:
            raise SarcliError("give either --doppler or --fdc/--fr, not both")
        from sarcli.io.doppler_product import read_doppler

        return read_doppler(doppler_path), f"read from {doppler_path.name}"
    if (fdc is None) != (fr is None):
        raise SarcliError("--fdc and --fr go together (centroid Hz and Doppler rate Hz/s)")
    if fdc is not None:
        from sarcli.model.constants import C_LIGHT
        from sarcli.model.doppler import GeometricDoppler

        r_mid = raw.radar.first_range_m + (shape[1] // 2) * C_LIGHT / (2 * raw.radar.range_sampling_rate_hz)
        return (GeometricDoppler.from_centroid_and_rate(fdc, fr, r_mid, raw.radar.wavelength_m),
                f"given: fdc {fdc:.1f} Hz, fr {fr:.2f} Hz/s at {r_mid:.0f} m")
    info("no --doppler given: the Doppler centroid and rate are estimated from the data", quiet)
    return _LazyDoppler(raw), "estimated from the data"


def focus(
    raw_path: Path = typer.Argument(..., help="Raw echo product (HDF5, from simulate or ingest)."),
    output: Path = typer.Option(..., "-o", "--output", help="SLC product to write (HDF5)."),
    doppler: Path = typer.Option(None, "--doppler", help="Doppler product (from 'sarcli doppler'); "
                                 "estimated from the data when omitted."),
    fdc: float = typer.Option(None, "--fdc", help="Use this absolute Doppler centroid (Hz) instead (with --fr)."),
    fr: float = typer.Option(None, "--fr", help="Use this Doppler rate (Hz/s, negative) at mid-swath (with --fdc)."),
    algorithm: str = typer.Option("rd", "--algorithm", help="rd (Range-Doppler), backprojection, or a plug-in."),
    channel: int = typer.Option(0, "--channel", help="Receive channel to focus (0 = /echo)."),
    range_window: str = typer.Option("kaiser:2.5", "--range-window", help="rect | hamming[:a] | kaiser[:beta]."),
    azimuth_window: str = typer.Option("kaiser:2.5", "--azimuth-window", help="rect | hamming[:a] | kaiser[:beta]."),
    azimuth_bandwidth: float = typer.Option(None, "--azimuth-bandwidth", help="Processed Doppler band, Hz "
                                            "(default 0.8 PRF)."),
    range_band_fraction: float = typer.Option(1.0, "--range-band-fraction", help="Processed part of the chirp "
                                              "band (0..1]."),
    rcmc: str = typer.Option("sinc8", "--rcmc", help="RCMC interpolator: nearest, linear, sinc4, sinc8, sinc16."),
    rcmc_oversample: int = typer.Option(2, "--rcmc-oversample", help="Range upsampling before RCMC (1 or 2)."),
    orbit_timing: bool = typer.Option(True, "--orbit-timing/--no-orbit-timing", help="Correct the zero-Doppler "
                                      "time and phase of the hyperbolic model from the orbit (Earth orbits)."),
    sets: list[str] = typer.Option(None, "--set", help="KEY=VALUE processing knob for the algorithm "
                                   "(JSON value, else a string); repeatable. Overrides the options above."),
    src: bool = typer.Option(True, "--src/--no-src", help="Secondary range compression."),
    double: bool = typer.Option(False, "--double", help="Process in complex128 (default complex64)."),
    block_lines: int = typer.Option(4096, "--block-lines", help="Azimuth FFT length per block (memory bound)."),
    replica: bool = typer.Option(True, "--replica/--no-replica", help="Use the product's chirp replica."),
    geotiff: Path = typer.Option(None, "--geotiff", help="Map-projected amplitude GeoTIFF (UTM, or --crs)."),
    geotiff_slant: Path = typer.Option(None, "--geotiff-slant", help="Slant-range amplitude GeoTIFF with "
                                       "lat/lon GCPs."),
    crs: str = typer.Option(None, "--crs", help="CRS of --geotiff, e.g. EPSG:32610 (default: UTM zone)."),
    spacing: float = typer.Option(None, "--pixel-spacing", help="Map pixel spacing, m (default: the coarser "
                                  "of ground range and azimuth)."),
    looks_az: int = typer.Option(1, "--looks-az", help="Azimuth looks for the GeoTIFFs/quicklook."),
    looks_rg: int = typer.Option(1, "--looks-rg", help="Range looks for the GeoTIFFs/quicklook."),
    quicklook: Path = typer.Option(None, "--quicklook", help="Quicklook PNG of the amplitude (dB)."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON report on stdout."),
) -> None:
    """Focus a stripmap raw product into a single-look complex image.

    The Range-Doppler algorithm processes azimuth blocks with overlap (bounded memory): range
    compression (replica or nominal chirp), optional SRC, RCMC in the range-Doppler domain with the
    range-dependent Doppler centroid and rate, azimuth matched filter. Lines of the SLC are
    zero-Doppler times. The Doppler comes from --doppler, from --fdc/--fr, or is estimated from the
    data. --json reports the Doppler and rate used, the time per stage and the peak memory.

    Examples:

      sarcli focus raw.h5 -o slc.h5 --doppler doppler.h5 --geotiff amp.tif --quicklook q.png

      sarcli focus raw.h5 -o slc.h5 --geotiff-slant amp_sr.tif --crs EPSG:32610 --json

      sarcli focus vancouver.h5 -o slc.h5 --fdc -6900 --fr -1733 --looks-az 4 --quicklook q.png

      sarcli focus raw.h5 -o bp.h5 --algorithm backprojection --range-window rect
    """
    import numpy as np

    from sarcli.focus import algorithms
    from sarcli.focus.rda import focus_stream, make_knobs
    from sarcli.io.h5common import open_product
    from sarcli.io.raw import raw_shape, read_raw
    from sarcli.io.slc import slc_writer, write_slc
    from sarcli.model.slc import SLC

    t_start = time.perf_counter()
    _check_output_options(looks_az, looks_rg, crs, spacing, azimuth_bandwidth, range_band_fraction)
    require_output_folders(output, geotiff, geotiff_slant, quicklook)
    knobs = {"range_window": range_window, "azimuth_window": azimuth_window,
             "azimuth_bandwidth_hz": azimuth_bandwidth, "range_bandwidth_fraction": range_band_fraction,
             "rcmc": rcmc, "src": src, "precision": "double" if double else "single", "block_lines": block_lines,
             "use_replica": replica, "rcmc_oversample": rcmc_oversample, "orbit_timing": orbit_timing}
    fn = algorithms.get(algorithm)
    if algorithm in ("rd", "backprojection"):
        knobs.update(_parse_sets(sets or []))
        make_knobs(**knobs)  # refuse bad values before any work
    else:  # a plug-in gets only what the user set for it
        knobs = _parse_sets(sets or [])
    # the estimator and the non-RD algorithms need the echo in memory; the RD path streams it otherwise
    in_memory = (doppler is None and fdc is None) or algorithm != "rd"
    raw = read_raw(raw_path, load_echo=in_memory)
    shape = raw.shape if in_memory else raw_shape(raw_path)
    if (geotiff or geotiff_slant) and (raw.orbit is None or raw.orbit.frame == "LOCAL"):
        raise SarcliError(f"{raw_path}: GeoTIFF needs an Earth orbit (ECI/ECEF state vectors); this product has "
                          f"{'none' if raw.orbit is None else 'a LOCAL (flat) frame'}: drop --geotiff/--geotiff-slant")
    if not 0 <= channel < raw.n_channels:
        raise SarcliError(f"{raw_path}: product has {raw.n_channels} channel(s), channel {channel} requested")
    t0 = time.perf_counter()
    model, how = _doppler_model(raw, shape, doppler, fdc, fr, as_json)
    if isinstance(model, _LazyDoppler) and algorithm in ("rd", "backprojection"):
        model.fdc(raw.radar.first_range_m, 0.0)  # these need it: estimate now, timed as the Doppler stage
    t_doppler = time.perf_counter() - t0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if algorithm == "rd" and not in_memory:
            with open_product(raw_path, "raw") as f, progress_bar(1, label="focusing") as bar:
                ds = f["echo"] if channel == 0 else f["echo_channels"]

                def read(a, b):
                    return ds[a:b] if channel == 0 else ds[channel - 1, a:b]

                def on_block(i, n):
                    bar.length = n
                    bar.update(1)

                slc = SLC.placeholder(raw, shape)
                with slc_writer(output, slc, shape, inputs=_inputs(raw_path, doppler)) as out:
                    def sink(s, block):
                        out[s:s + block.shape[0]] = block

                    slc.update_from(focus_stream(raw, read, sink, model, make_knobs(**knobs), shape, on_block))
        else:
            slc = fn(raw, model, channel, **knobs)
            write_slc(output, slc, inputs=_inputs(raw_path, doppler))
    for w in caught:
        info(f"sarcli: warning: {w.message}", as_json)
    products = {"slc": str(output)}
    t0 = time.perf_counter()
    from sarcli.focus.quality import image_statistics
    from sarcli.io.slc import read_slc

    stats = _statistics(output, image_statistics)
    if geotiff or geotiff_slant or quicklook:
        full = read_slc(output)
        tags = {"source_product": output.name, "algorithm": algorithm, "doppler": how}
        if geotiff_slant:
            from sarcli.focus.geocode import write_slant_geotiff

            write_slant_geotiff(geotiff_slant, full, looks_az, looks_rg, tags)
            products["geotiff_slant"] = str(geotiff_slant)
        if geotiff:
            from sarcli.focus.geocode import write_map_geotiff

            used = write_map_geotiff(geotiff, full, looks_az, looks_rg, crs, spacing, tags)
            products["geotiff"] = str(geotiff)
            products["crs"] = used
        if quicklook:
            from sarcli.focus.quicklook import write_slc_quicklook

            write_slc_quicklook(quicklook, full, looks_az, looks_rg)
            products["quicklook"] = str(quicklook)
    t_products = time.perf_counter() - t0
    d = slc.doppler
    report = {
        "input": str(raw_path), "products": products, "algorithm": algorithm, "doppler_source": how,
        "shape": list(shape),
        "doppler_used": {
            "fdc_hz_min": float(np.min(d.fdc_hz)), "fdc_hz_max": float(np.max(d.fdc_hz)),
            "fdc_hz_mid": float(np.median(d.fdc_hz[:, d.fdc_hz.shape[1] // 2])),
            "fr_hz_per_s_min": float(np.min(d.fr_hz_per_s)), "fr_hz_per_s_max": float(np.max(d.fr_hz_per_s)),
            "fr_hz_per_s_mid": float(np.median(d.fr_hz_per_s[:, d.fr_hz_per_s.shape[1] // 2])),
            "effective_velocity_mps_mid": float(np.median(d.velocity_mps[:, d.velocity_mps.shape[1] // 2])),
        },
        "image_statistics": stats,
        "timings_s": _timings(t_doppler, slc.timings, t_products, time.perf_counter() - t_start),
        "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        "warnings": [str(w.message) for w in caught],
        "parameters": slc.parameters,
    }
    if as_json:
        emit_json(report)
    else:
        du = report["doppler_used"]
        info(f"focused {raw_path.name} -> {output} ({shape[0]} x {shape[1]}, {algorithm}) in "
             f"{report['timings_s']['total_s']:.2f} s; Doppler {how}: fdc {du['fdc_hz_mid']:.1f} Hz, "
             f"fr {du['fr_hz_per_s_mid']:.2f} Hz/s at mid-swath; peak RSS {report['peak_rss_bytes'] / 2**20:.0f} MiB")
        for k, v in products.items():
            if k not in ("slc", "crs"):
                info(f"wrote {v}")


def _check_output_options(looks_az: int, looks_rg: int, crs: str | None, spacing: float | None,
                          azimuth_bandwidth: float | None, range_band_fraction: float) -> None:
    """Refuse impossible option values before the Doppler estimate and the focus (one line each)."""
    import math

    if looks_az < 1 or looks_rg < 1:
        raise SarcliError(f"--looks-az and --looks-rg must be at least 1, got {looks_az} and {looks_rg}")
    if spacing is not None and not (math.isfinite(spacing) and spacing > 0):
        raise SarcliError(f"--pixel-spacing must be a positive number of metres, got {spacing}")
    if azimuth_bandwidth is not None and not (math.isfinite(azimuth_bandwidth) and azimuth_bandwidth > 0):
        raise SarcliError(f"--azimuth-bandwidth must be a positive number of Hz, got {azimuth_bandwidth}")
    if not (math.isfinite(range_band_fraction) and 0 < range_band_fraction <= 1):
        raise SarcliError(f"--range-band-fraction must be in (0, 1], got {range_band_fraction}")
    if crs is not None:
        from pyproj import CRS
        from pyproj.exceptions import CRSError

        try:
            CRS.from_user_input(crs)
        except CRSError:
            raise SarcliError(f"--crs {crs!r} is not a known coordinate reference system "
                              "(e.g. EPSG:32610)") from None


def _timings(t_doppler: float, stages: dict, t_products: float, t_total: float) -> dict:
    """Seconds per stage, every key ending in ``_s``: the focuser's own total becomes ``focus_s``
    and ``total_s`` is the whole command (reading, Doppler, focus, statistics and products)."""
    out = {"doppler_s": t_doppler}
    for k, v in stages.items():
        k = k if k.endswith("_s") else f"{k}_s"
        out["focus_s" if k == "total_s" else k] = v
    out.update({"statistics_and_products_s": t_products, "total_s": t_total})
    return out


def _parse_sets(items: list[str]) -> dict:
    """``["a=1", "b=hamming"]`` -> {"a": 1, "b": "hamming"} (JSON values where they parse)."""
    import json

    out = {}
    for it in items:
        key, eq, val = it.partition("=")
        if not eq or not key.strip():
            raise SarcliError(f"--set {it!r}: expected KEY=VALUE")
        try:
            out[key.strip()] = json.loads(val)
        except json.JSONDecodeError:
            out[key.strip()] = val
    return out


class _LazyDoppler:
    """Estimates the Doppler from the data on first use (an algorithm that ignores it costs nothing)."""

    def __init__(self, raw):
        self._raw = raw
        self._model = None

    def _get(self):
        if self._model is None:
            from sarcli.doppler.api import estimate_doppler

            self._model = estimate_doppler(self._raw)
        return self._model

    def fdc(self, range_m, azimuth_time_s):
        return self._get().fdc(range_m, azimuth_time_s)

    def fr(self, range_m, azimuth_time_s):
        return self._get().fr(range_m, azimuth_time_s)

    def __getattr__(self, name):
        return getattr(self._get(), name)


def _statistics(path: Path, fn) -> dict:
    """Image statistics over the fully focused lines, read in row blocks (bounded memory)."""
    from sarcli.io.h5common import open_product

    with open_product(path, "slc") as f:
        ds = f["image"]
        a = int(f.attrs.get("first_full_line", 0))
        b = int(f.attrs.get("last_full_line", ds.shape[0] - 1)) + 1
        if b <= a:
            a, b = 0, ds.shape[0]
        try:
            return fn(ds[c:min(b, c + 1024)] for c in range(a, b, 1024))
        except SarcliError:
            return {}


def _inputs(raw_path: Path, doppler: Path | None) -> tuple:
    return (raw_path,) + ((doppler,) if doppler is not None else ())


def register(app: typer.Typer) -> None:
    app.command("focus")(focus)
