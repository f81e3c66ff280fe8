"""``sarcli gbsar simulate|plan|focus|interfere|coherence|polarimetry``: GB-SAR processing commands.

Heavy modules are imported inside the commands so that this module always imports cleanly.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import typer

from sarcli.cli.common import emit_json, info, progress, require_output_folders
from sarcli.cli.gbsar_app import attach, gbsar_app
from sarcli.errors import SarcliError
from sarcli.model.constants import C_LIGHT


@gbsar_app.command("simulate")
def simulate_cmd(
    scene: Path = typer.Argument(..., help="Scene TOML (see samples/gbsar_*.toml)."),
    output: Path = typer.Option(..., "-o", "--output", help="Output scan product (.h5)."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Simulate a stop-and-go VNA rail scan of a scene: S21 per polarization, stop and frequency.

    Only the effects listed under [effects.*] in the scene are computed.

    Examples:

      sarcli gbsar simulate samples/gbsar_indoor.toml -o indoor.h5

      sarcli gbsar simulate samples/gbsar_outdoor.toml -o t1.h5 --json
    """
    from sarcli.gbsar.scene import load_scene
    from sarcli.gbsar.simulate import simulate
    from sarcli.gbsar.system import system_from_scene
    from sarcli.io.scan import write_scan

    sc = load_scene(scene)
    s = simulate(sc, progress=lambda it: progress(it, total=sc.positions_m.size, label="stops"))
    write_scan(output, s, parameters={"scene": scene.name}, inputs=[scene])
    sysp = system_from_scene(sc)
    r = np.linalg.norm(sc.scatterers.position - np.array([0.0, 0.0, sc.height_m]), axis=1)
    wrapped = int(np.sum(r > sysp.r_max_m)) if np.isfinite(sysp.r_max_m) else 0
    summary = {"output": str(output), "n_pol": len(sc.polarizations), "n_stops": s.n_stops,
               "n_freq": int(s.frequency.size), "n_scatterers": int(r.size), "effects": sorted(sc.effects),
               "r_max_m": sysp.r_max_m, "n_beyond_r_max": wrapped}
    if wrapped:
        info(f"warning: {wrapped} scatterer(s) beyond R_max = {sysp.r_max_m:.2f} m fold back into the image")
    if json_out:
        emit_json(summary)
    else:
        info(f"wrote {output}: {s.n_stops} stops x {s.frequency.size} frequencies x "
             f"{len(sc.polarizations)} polarizations, {r.size} scatterers, effects: "
             f"{', '.join(sorted(sc.effects)) or 'none'}")


def _scan_or_scene_system(path: Path, max_range: float | None, criterion_deg: float):
    """Table 1 of a scene TOML or a scan product."""
    import math

    from sarcli.gbsar.system import build_system

    if path.suffix.lower() == ".toml":
        from sarcli.gbsar.scene import load_scene

        sc = load_scene(path)
        f, x, lx = sc.frequencies(), sc.positions_m, sc.antenna.length_azimuth_m
        max_range = max_range if max_range is not None else sc.processing.get("max_range_m")
    else:
        from sarcli.io.scan import read_scan

        s = read_scan(path)
        f, x, lx = s.frequency, s.rail_position, s.antenna.length_azimuth_m
    return build_system(f, x, lx, max_range, math.radians(criterion_deg))


@gbsar_app.command("plan")
def plan_cmd(
    source: Path = typer.Argument(..., help="Scene TOML or scan product (.h5)."),
    max_range: float = typer.Option(None, "--max-range", help="Image range Rc (m) for RD's N_xfft [default: "
                                    "the scene's processing.max_range_m, else R_max]."),
    criterion_deg: float = typer.Option(45.0, "--criterion-deg", help="DF phase-error criterion (deg), eq. 12."),
    json_out: bool = typer.Option(False, "--json", help="Print the table as JSON on stdout."),
) -> None:
    """Print the derived system table (seed 000 Table 1), the DF minimum range and resolution by region.

    Examples:

      sarcli gbsar plan samples/gbsar_outdoor.toml

      sarcli gbsar plan scan.h5 --json
    """
    from sarcli.gbsar.system import azimuth_resolution

    _check_criterion(criterion_deg)
    sysp = _scan_or_scene_system(source, max_range, criterion_deg)
    d = sysp.as_dict()
    top = sysp.r_max_m if sysp.r_max_m < float("inf") else 1000.0
    probes = sorted({r for r in (1, 2, 5, 10, 20, 50, 100, 200, 400, 600) if r <= top} | {round(top, 3)})
    regions = []
    for r0 in probes:
        for xc in (0.0, sysp.rail_length_m / 2 + sysp.wavelength_m * r0 / (2 * sysp.antenna_length_azimuth_m) / 2):
            reg, rd = azimuth_resolution(r0, xc, sysp.rail_length_m, sysp.wavelength_m, sysp.antenna_length_azimuth_m)
            _, df = azimuth_resolution(r0, xc, sysp.rail_length_m, sysp.wavelength_m,
                                       sysp.antenna_length_azimuth_m, "df")
            regions.append({"r0_m": r0, "xc_m": xc, "region": reg, "rd_resolution_m": rd, "df_resolution_m": df})
    d["resolution_by_region"] = regions
    if json_out:
        emit_json(d)
        return
    mb = 1024 * 1024
    lines = [
        f"centre frequency f_c       {sysp.center_frequency_hz / 1e9:.4g} GHz (lambda {sysp.wavelength_m:.4f} m)",
        f"bandwidth B_R, N_R         {sysp.bandwidth_hz / 1e6:.4g} MHz, {sysp.n_r}",
        f"range resolution dR        {_fmt(sysp.range_resolution_m)} m",
        f"frequency step df          {_fmt(sysp.frequency_step_hz)} Hz",
        f"R_max = c/(4 df)           {_fmt(sysp.r_max_m)} m",
        f"N_Rfft, range pixel        {sysp.n_rfft}, {_fmt(sysp.range_pixel_m)} m (Table 1 formula "
        f"{_fmt(sysp.range_pixel_paper_m)} m)",
        f"rail X, dx, N_x            {sysp.rail_length_m:.4g} m, {_fmt(sysp.rail_step_m)} m, {sysp.n_x}"
        + ("" if sysp.rail_uniform else " (NON-UNIFORM steps: BP only)"),
        f"N_xfft DF / RD             {sysp.n_xfft_df} / {sysp.n_xfft_rd} (RD for Rc = {sysp.image_max_range_m:.4g} m)",
        f"DF azimuth pixel, width    {_fmt(sysp.df_azimuth_pixel_per_rc)} Rc, {_fmt(sysp.df_azimuth_width_per_rc)} Rc",
        f"RD azimuth pixel, width    {_fmt(sysp.rd_azimuth_pixel_m)} m, {_fmt(sysp.rd_azimuth_width_m)} m",
        f"u_R                        {sysp.doppler_rate_coefficient:.4g}/R0 1/m^2",
        f"memory DF / RD             {sysp.memory_df_bytes / mb:.3g} MB / "
        f"{(sysp.memory_rd_bytes or 0) / mb:.4g} MB (raw {sysp.raw_bytes / mb:.3g} MB)",
        f"DF minimum range (eq. 12)  {sysp.df_min_range_m:.4g} m at criterion {criterion_deg:g} deg",
        "resolution by region (R0, xc -> region, RD, DF):",
    ]
    lines += [f"  {g['r0_m']:>8.4g} m {g['xc_m']:>8.3g} m  {g['region']:>3}  {g['rd_resolution_m']:.3g} m  "
              f"{g['df_resolution_m']:.3g} m" for g in regions]
    typer.echo("\n".join(lines))


def _fmt(v) -> str:
    return "n/a" if v is None else f"{v:.4g}"


MIN_RANGE_BINS = 4  # an image shallower than this many range bins is a mistake, not a product


def _check_criterion(criterion_deg: float) -> None:
    """The eq. 12 phase-error criterion must lie in (0, 180] degrees."""
    if not (math.isfinite(criterion_deg) and 0 < criterion_deg <= 180):
        raise SarcliError(f"--criterion-deg must be in (0, 180] degrees, got {criterion_deg:g}")


def _check_range_interval(scan, min_range: float, max_range: float | None) -> None:
    """Refuse a range interval that holds fewer than MIN_RANGE_BINS range bins, before any focusing.

    The bin is the range-compression sample spacing ``c / (2 N df)``, ``N = 2^ceil(log2 N_f)``
    (N_Rfft of Table 1); ranges stop at R_max = c / (4 df).
    """
    from sarcli.gbsar.rangecomp import check_sweep
    from sarcli.gbsar.system import next_pow2

    if not (math.isfinite(min_range) and min_range >= 0):
        raise SarcliError(f"--min-range must be a finite range >= 0 m, got {min_range:g}")
    if max_range is not None and not (math.isfinite(max_range) and max_range > 0):
        raise SarcliError(f"--max-range must be a positive range in metres, got {max_range:g}")
    df = check_sweep(scan.frequency)
    dr = C_LIGHT / (2 * next_pow2(scan.frequency.size) * df)
    r_max = C_LIGHT / (4 * df)
    if min_range > r_max - MIN_RANGE_BINS * dr:
        raise SarcliError(f"--min-range {min_range:g} m leaves fewer than {MIN_RANGE_BINS} range bins below the "
                          f"unambiguous range R_max = {r_max:.4g} m of this sweep")
    top = r_max if max_range is None else min(max_range, r_max)
    if top - min_range < MIN_RANGE_BINS * dr:
        raise SarcliError(f"the range interval {min_range:g}-{top:g} m holds fewer than {MIN_RANGE_BINS} range bins "
                          f"of {dr:.3g} m (R_max {C_LIGHT / (4 * df):.4g} m): give --max-range at least "
                          f"{min_range + MIN_RANGE_BINS * dr:.3g} m and --min-range below it")


@gbsar_app.command("focus")
def focus_cmd(
    scan: Path = typer.Argument(..., help="Scan product (.h5)."),
    output: Path = typer.Option(..., "-o", "--output", help="Output image product (.h5)."),
    algorithm: str = typer.Option("auto", "--algorithm", help="auto | df | rd | bp."),
    pol: list[str] = typer.Option(None, "--pol", help="Polarization(s) to focus [default: all]."),
    max_range: float = typer.Option(None, "--max-range", help="Largest image range R0 (m) [default: R_max]."),
    min_range: float = typer.Option(0.0, "--min-range", help="Smallest image range R0 (m)."),
    pixel_x: float = typer.Option(None, "--pixel-x", help="Azimuth pixel (m), a multiple of the rail step "
                                  "[default: about half the range pixel]."),
    width: float = typer.Option(None, "--width", help="Azimuth width of the image (m) [default: beam "
                                "footprint at the top range plus the rail, at most DF's width]."),
    criterion_deg: float = typer.Option(45.0, "--criterion-deg", help="DF phase-error criterion (deg) for auto."),
    near: str = typer.Option("bp", "--near", help="auto's near-range algorithm: bp | rd."),
    n_xfft: int = typer.Option(None, "--n-xfft", help="Azimuth FFT size for DF/RD [default: the paper's rule]."),
    rd_reference: str = typer.Option("sinc", "--rd-reference", help="RD reference weighting: sinc (real "
                                     "antenna) | rect (the paper's ideal beam)."),
    range_window: str = typer.Option("hamming", "--range-window", help="hamming | hann | none."),
    azimuth_window: str = typer.Option("hamming", "--azimuth-window", help="hamming | hann | none."),
    geotiff: Path = typer.Option(None, "--geotiff", help="Amplitude (dB) GeoTIFF in UTM of the first polarization."),
    enu_geotiff: Path = typer.Option(None, "--enu-geotiff", help="Amplitude (dB) GeoTIFF in local ENU."),
    map_pixel: float = typer.Option(None, "--map-pixel", help="Map pixel (m) of the GeoTIFFs [default: range pixel]."),
    ground_height: float = typer.Option(0.0, "--ground-height", help="Surface height z (m) for geocoding."),
    quicklook: Path = typer.Option(None, "--quicklook", help="Quicklook PNG of the slant-plane amplitude."),
    json_out: bool = typer.Option(False, "--json", help="Print the focusing report as JSON on stdout."),
) -> None:
    """Focus a scan: range compression, then DF, RD, BP or auto (DF beyond the eq. 12 limit, BP/RD nearer).

    The image lies in the slant plane of the rail (range R0 from the rail line, azimuth x along it);
    its phase at a scatterer is -4*pi*R0/lambda for every algorithm.

    Examples:

      sarcli gbsar focus scan.h5 -o image.h5 --geotiff image.tif --quicklook image.png

      sarcli gbsar focus scan.h5 --algorithm rd --max-range 15 -o near.h5 --json
    """
    import math

    from sarcli.gbsar.focus import FocusOptions, image_from_scan
    from sarcli.io.gbsar_image import write_gbsar_image
    from sarcli.io.scan import read_scan

    _check_criterion(criterion_deg)
    if width is not None and not (math.isfinite(width) and width > 0):
        raise SarcliError(f"--width must be a positive azimuth extent in metres, got {width:g}")
    if n_xfft is not None and n_xfft < 1:
        raise SarcliError(f"--n-xfft must be a positive FFT size, got {n_xfft}")
    require_output_folders(output, geotiff, enu_geotiff, quicklook)
    s = read_scan(scan)
    _check_range_interval(s, min_range, max_range)
    opts = FocusOptions(algorithm=algorithm, range_window=range_window, azimuth_window=azimuth_window,
                        max_range_m=max_range, min_range_m=min_range, pixel_x_m=pixel_x, width_m=width,
                        criterion_rad=math.radians(criterion_deg), near=near, n_xfft=n_xfft,
                        rd_reference=rd_reference)
    pols = tuple(p.upper() for p in pol) if pol else None
    for p in pols or ():
        s.pol(p)
    img = image_from_scan(s, opts, pols=pols)
    f = img
    timings = img.report.pop("seconds")  # wall times stay out of the product (reproducible bytes)
    write_gbsar_image(output, img, parameters=vars(opts), inputs=[scan])
    img.report["seconds"] = timings
    _image_outputs(img, geotiff, enu_geotiff, map_pixel, ground_height, quicklook, f.report)
    if "df_below_limit" in f.report:
        b = f.report["df_below_limit"]
        info(f"warning: DF used from {b['from_m']:.2f} m, below its minimum range {b['limit_m']:.2f} m (eq. 12): "
             f"phase error up to {b['eq11_phase_error_rad']:.2f} rad, near-range targets defocus")
    if f.report["skipped_stops"]:
        info(f"warning: skipped {len(f.report['skipped_stops'])} flagged/NaN stop(s): {f.report['skipped_stops']}")
    if json_out:
        emit_json(f.report)
    else:
        used = ", ".join(f"{k} {a:.2f}-{b:.2f} m" for k, (a, b) in f.report["used"].items())
        info(f"wrote {output}: {img.image.shape[1]} x {img.image.shape[2]} pixels, {used} "
             f"(DF minimum range {f.report['df_min_range_m']:.2f} m)")


def _image_outputs(img, geotiff, enu_geotiff, map_pixel, ground_height, quicklook, report) -> None:
    """GeoTIFFs (UTM / ENU) and the quicklook of the first polarization's amplitude in dB."""
    from sarcli.gbsar.geocode import resample_to_map
    from sarcli.io.images import amplitude_db, write_geotiff, write_quicklook

    db = amplitude_db(img.image[0], floor_db=-200.0)
    pixel = map_pixel or float(img.range_m[1] - img.range_m[0]) if img.range_m.size > 1 else 1.0
    for path, frame in ((geotiff, "utm"), (enu_geotiff, "enu")):
        if path is None:
            continue
        raster, transform, crs, ginfo = resample_to_map(db, img.range_m, img.azimuth_m, img.site, img.rail_height_m,
                                                        img.rail_centre_m, pixel, frame, ground_height)
        report[f"{frame}_geotiff"] = {"path": str(path), "crs": crs, "shape": list(raster.shape), **ginfo}
        write_geotiff(path, raster, crs, transform=transform, band_description=f"{img.polarizations[0]} amplitude (dB)",
                      tags={"algorithm": img.algorithm, "epoch_utc": img.epoch_utc, "units": "dB"})
    if quicklook is not None:
        write_quicklook(quicklook, img.image[0], title=f"GB-SAR {img.polarizations[0]} ({img.algorithm})",
                        extent=[img.azimuth_m[0], img.azimuth_m[-1], img.range_m[-1], img.range_m[0]],
                        xlabel="azimuth x (m)", ylabel="range R0 (m)", aspect="auto")


def _load_image(path: Path, like=None):
    """A focused image product, or a scan focused on the fly with ``auto`` on the grid of the image
    ``like`` (default grid without one: it depends on the wavelength, so a delta-f pair needs ``like``)."""
    from sarcli.io.h5common import attr_str, open_product

    with open_product(path, ("gbsar_image", "gbsar_scan")) as f:
        kind = attr_str(f, "product_type")
    if kind == "gbsar_image":
        from sarcli.io.gbsar_image import read_gbsar_image

        return read_gbsar_image(path)
    from sarcli.gbsar.focus import Grid, image_from_scan
    from sarcli.io.scan import read_scan

    grid = Grid(ranges=like.range_m, azimuths=like.azimuth_m) if like is not None else None
    return image_from_scan(read_scan(path), grid=grid)


def _map_outputs(raster, img, geotiff: Path | None, png: Path | None, title: str, label: str, cmap: str,
                 vmin: float, vmax: float, map_pixel: float | None) -> dict:
    """UTM GeoTIFF (nearest resampling) and slant-plane PNG of a real-valued raster on ``img``'s grid."""
    from sarcli.gbsar.geocode import resample_to_map
    from sarcli.io.images import write_geotiff, write_quicklook

    out = {}
    if geotiff is not None:
        pixel = map_pixel or float(img.range_m[1] - img.range_m[0])
        m, transform, crs, ginfo = resample_to_map(raster, img.range_m, img.azimuth_m, img.site, img.rail_height_m,
                                                   img.rail_centre_m, pixel, "utm")
        write_geotiff(geotiff, m, crs, transform=transform, band_description=label)
        out["geotiff"] = {"path": str(geotiff), "crs": crs, **ginfo}
    if png is not None:
        write_quicklook(png, raster, title=title, cmap=cmap, is_db=True, vmin=vmin, vmax=vmax,
                        extent=[img.azimuth_m[0], img.azimuth_m[-1], img.range_m[-1], img.range_m[0]],
                        xlabel="azimuth x (m)", ylabel="range R0 (m)", colorbar_label=label)
        out["png"] = str(png)
    return out


@gbsar_app.command("interfere")
def interfere_cmd(
    reference: Path = typer.Argument(..., help="Reference image (or scan) A."),
    secondary: Path = typer.Argument(..., help="Secondary image (or scan) B; the interferogram is B * conj(A)."),
    output: Path = typer.Option(..., "-o", "--output", help="Output interferogram product (.h5)."),
    mode: str = typer.Option("dinsar", "--mode", help="dinsar | crosstrack | deltaf | combined."),
    pol: str = typer.Option(None, "--pol", help="Polarization [default: the first of A]."),
    window: int = typer.Option(5, "--window", help="Coherence boxcar window (pixels)."),
    ground_height: float = typer.Option(0.0, "--ground-height", help="Reference surface height z (m) of the model."),
    geotiff: Path = typer.Option(None, "--geotiff", help="UTM GeoTIFF of the residual phase (rad)."),
    png: Path = typer.Option(None, "--png", help="PNG of the residual phase (cyclic colour map)."),
    value_png: Path = typer.Option(None, "--value-png", help="PNG of the converted value (mm or m)."),
    value_geotiff: Path = typer.Option(None, "--value-geotiff", help="UTM GeoTIFF of the converted value."),
    min_coherence: float = typer.Option(0.5, "--min-coherence", help="The converted value (product, --value-png, "
                                        "--value-geotiff) is NaN where the coherence is below this (0 keeps all)."),
    map_pixel: float = typer.Option(None, "--map-pixel", help="GeoTIFF pixel (m) [default: range pixel]."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Interferogram of two GB-SAR images: phase, coherence, model phase removed, converted value.

    dinsar -> LOS displacement (mm); crosstrack / combined -> height (m); deltaf -> range offset (m).
    Scans given instead of images are focused with --algorithm auto first. Pixels outside the beam
    footprint (no image support) are NaN (blank in PNGs, nodata in GeoTIFFs); the converted value is
    also NaN where the coherence is below --min-coherence.

    Examples:

      sarcli gbsar interfere t2.h5 t3.h5 --mode crosstrack -o xt.h5 --png xt.png --value-png height.png

      sarcli gbsar interfere t1.h5 t2.h5 --mode dinsar -o dinsar.h5 --value-geotiff los.tif --json
    """
    from sarcli.gbsar.interferometry import interfere

    a = _load_image(reference)
    b = _load_image(secondary, like=a)
    pol = (pol or a.polarizations[0]).upper()
    ifg = interfere(a, b, mode, pol, window, ground_height, min_coherence)
    attrs = {"mode": mode, "pol": pol, "coherence_window": window, "ground_height_m": ground_height,
             "min_coherence": min_coherence,
             "rail_height_a_m": a.rail_height_m, "rail_height_b_m": b.rail_height_m,
             "center_frequency_a_hz": a.center_frequency_hz, "center_frequency_b_hz": b.center_frequency_hz,
             "epoch_utc": a.epoch_utc}
    from sarcli.io.interferogram import write_interferogram

    write_interferogram(output, ifg, a.range_m, a.azimuth_m, attrs, parameters=attrs, inputs=[reference, secondary])
    n_valid = int(np.count_nonzero(np.isfinite(ifg.value)))
    summary = {"output": str(output), **attrs, "value": ifg.value_name, "unit": ifg.value_unit, "rate": ifg.rate,
               "mean_coherence": float(np.nanmean(ifg.coherence)) if ifg.support.any() else None,
               "supported_pixels": int(np.count_nonzero(ifg.support)), "valid_value_pixels": n_valid}
    summary.update(_map_outputs(ifg.residual, a, geotiff, png, f"{mode} residual phase ({pol})", "phase (rad)",
                                "twilight", -np.pi, np.pi, map_pixel))
    if value_png is not None or value_geotiff is not None:
        v = ifg.value[np.isfinite(ifg.value)]
        lo, hi = (np.percentile(v, [2, 98]) if v.size else (0.0, 1.0))
        title = f"{mode} {ifg.value_name} (coherence >= {min_coherence:g})"
        summary["value_outputs"] = _map_outputs(ifg.value, a, value_geotiff, value_png, title,
                                                f"{ifg.value_name} ({ifg.value_unit})", "viridis", float(lo),
                                                float(hi), map_pixel)
    if not n_valid:
        info(f"warning: no pixel has both images' support and coherence >= {min_coherence:g}: the value is all NaN")
    if json_out:
        emit_json(summary)
    else:
        info(f"wrote {output}: {mode}, mean coherence {summary['mean_coherence'] or 0:.3f} over "
             f"{summary['supported_pixels']} supported pixels, value {ifg.value_name} ({ifg.value_unit}) on "
             f"{n_valid} with coherence >= {min_coherence:g}")


@gbsar_app.command("coherence")
def coherence_cmd(
    images: list[Path] = typer.Argument(..., help="Two or more images (or scans) of the same geometry, in time order."),
    output: Path = typer.Option(..., "-o", "--output", help="Output PS product (.h5)."),
    threshold: float = typer.Option(0.9, "--threshold", help="Temporal coherence threshold for PS."),
    dynamic_range_db: float = typer.Option(40.0, "--dynamic-range-db",
                                           help="PS amplitude floor below the brightest pixel (dB)."),
    pol: str = typer.Option(None, "--pol", help="Polarization [default: the first of the first image]."),
    csv: Path = typer.Option(None, "--csv", help="CSV of the PS time series."),
    plot: Path = typer.Option(None, "--plot", help="PNG: coherence map and PS displacement series."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Temporal coherence |sum z|/sum|z|, persistent-scatterer selection and PS phase/displacement series.

    Examples:

      sarcli gbsar coherence p1.h5 p2.h5 p3.h5 p4.h5 --threshold 0.99 -o ps.h5 --csv ps.csv --plot ps.png
    """
    from sarcli.errors import SarcliError
    from sarcli.gbsar.interferometry import support
    from sarcli.gbsar.timeseries import check_series, ps_series, select_ps, temporal_coherence
    from sarcli.io.interferogram import write_ps

    if len(images) < 2:
        raise SarcliError("coherence needs at least 2 images")
    imgs = [_load_image(images[0])]
    imgs += [_load_image(p, like=imgs[0]) for p in images[1:]]
    pol = (pol or imgs[0].polarizations[0]).upper()
    check_series(imgs, pol, [str(p) for p in images])
    stack = np.stack([im.pol(pol) for im in imgs])
    ok = np.logical_and.reduce([support(im, pol) for im in imgs])
    gamma = np.where(ok, temporal_coherence(stack), np.nan).astype(np.float32)  # NaN outside the footprint
    rows, cols = select_ps(gamma, np.mean(np.abs(stack), axis=0), threshold, dynamic_range_db)
    phase, disp = ps_series(stack, rows, cols, imgs[0].wavelength_m)
    t = np.array([_seconds_between(imgs[0].epoch_utc, im.epoch_utc) + im.scan_time_s for im in imgs])
    by_index = bool(np.any(np.diff(t) <= 0))
    if by_index:
        info("warning: the scan times (epoch + mean stop time) are equal or out of order: time_s is kept, "
             "but the PS plot uses the scan index as its time axis")
    attrs = {"pol": pol, "threshold": threshold, "dynamic_range_db": dynamic_range_db, "epoch_utc": imgs[0].epoch_utc}
    write_ps(output, gamma, t, rows, cols, imgs[0].range_m, imgs[0].azimuth_m, phase, disp, attrs,
             parameters=attrs, inputs=images)
    if csv is not None:
        _write_ps_csv(csv, imgs[0], rows, cols, gamma, phase, disp)
    if plot is not None:
        _ps_plot(plot, imgs[0], gamma, rows, cols, np.arange(t.size) if by_index else t / 60.0,
                 "scan index" if by_index else "time (min)", disp)
    summary = {"output": str(output), "n_images": len(imgs), "n_ps": int(rows.size), "threshold": threshold,
               "max_abs_phase_change_deg": float(np.degrees(np.max(np.abs(phase)))) if rows.size else None,
               "time_s": t, "plot_time_axis": "scan_index" if by_index else "time"}
    if json_out:
        emit_json(summary)
    else:
        info(f"wrote {output}: {rows.size} PS of {int(ok.sum())} supported pixels (gamma >= {threshold})")


def _seconds_between(a: str, b: str) -> float:
    from datetime import datetime

    from sarcli.errors import SarcliError

    try:
        ta, tb = (datetime.fromisoformat(x.replace("Z", "+00:00")) for x in (a, b))
    except ValueError:
        raise SarcliError(f"unreadable epoch_utc '{a}' or '{b}'") from None
    return (tb - ta).total_seconds()


def _write_ps_csv(path: Path, img, rows, cols, gamma, phase, disp) -> None:
    """One line per PS: position, coherence, phase (deg) and LOS displacement (mm) per scan; atomic."""
    import csv as _csv

    from sarcli.io.images import atomic_path

    n = phase.shape[1] if phase.ndim == 2 else 0
    with atomic_path(path, ".csv") as tmp, open(tmp, "w", newline="") as fh:
        w = _csv.writer(fh)
        w.writerow(["ps", "azimuth_m", "range_m", "coherence"] + [f"phase_deg_{i}" for i in range(n)]
                   + [f"displacement_mm_{i}" for i in range(n)])
        for k, (r, c) in enumerate(zip(rows, cols, strict=True)):
            w.writerow([k, f"{img.azimuth_m[c]:.3f}", f"{img.range_m[r]:.3f}", f"{gamma[r, c]:.5f}"]
                       + [f"{v:.3f}" for v in np.degrees(phase[k])] + [f"{v:.4f}" for v in disp[k]])


def _ps_plot(path: Path, img, gamma, rows, cols, t_axis, t_label: str, disp) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 5), dpi=100)
    im = a1.imshow(gamma, vmin=0, vmax=1, cmap="viridis", aspect="auto", interpolation="nearest",
                   extent=[img.azimuth_m[0], img.azimuth_m[-1], img.range_m[-1], img.range_m[0]])
    a1.plot(img.azimuth_m[cols], img.range_m[rows], "r.", ms=3, label="PS")
    a1.set(xlabel="azimuth x (m)", ylabel="range R0 (m)", title="temporal coherence")
    fig.colorbar(im, ax=a1)
    for k in range(min(rows.size, 20)):
        a2.plot(t_axis, disp[k], ".-")
    a2.set(xlabel=t_label, ylabel="LOS displacement (mm)", title=f"{rows.size} PS (first 20 shown)")
    fig.tight_layout()
    from sarcli.io.images import atomic_path

    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


@gbsar_app.command("polarimetry")
def polarimetry_cmd(
    image: Path = typer.Argument(..., help="Image (or scan) with HH and VV."),
    geotiff: Path = typer.Option(None, "--geotiff", help="UTM GeoTIFF of (HH-VV)/(HH+VV)."),
    png: Path = typer.Option(None, "--png", help="PNG of (HH-VV)/(HH+VV) in the slant plane."),
    window: int = typer.Option(3, "--window", help="Boxcar window (pixels) for the powers."),
    map_pixel: float = typer.Option(None, "--map-pixel", help="GeoTIFF pixel (m) [default: range pixel]."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Polarimetric normalized difference (|HH|^2-|VV|^2)/(|HH|^2+|VV|^2) image (seed 003).

    Examples:

      sarcli gbsar polarimetry image.h5 --png nd.png --geotiff nd.tif
    """
    from sarcli.gbsar.interferometry import support
    from sarcli.gbsar.polarimetry import normalized_difference

    img = _load_image(image)
    nd = normalized_difference(img.pol("HH"), img.pol("VV"), window)
    nd[~(support(img, "HH") & support(img, "VV"))] = np.nan  # blank outside the beam footprint
    summary = {"mean": float(np.nanmean(nd)), "fraction_hh_dominant": float(np.nanmean(nd > 0))}
    summary.update(_map_outputs(nd, img, geotiff, png, "(HH-VV)/(HH+VV)", "normalized difference", "RdBu_r",
                                -1.0, 1.0, map_pixel))
    if json_out:
        emit_json(summary)
    else:
        info(f"normalized difference: mean {summary['mean']:.3f}")


def register(app: typer.Typer) -> None:
    attach(app)
