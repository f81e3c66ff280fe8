"""``sarcli gbsar simulate|import|plan|focus|interfere|coherence|polarimetry``: GB-SAR processing commands.

Each command parses its options into the ``Config`` of its workflow (``sarcli.workflows.gbsar_*``,
imported inside the command so that ``--help`` stays fast), runs it and prints the report.
"""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.gbsar_app import attach, gbsar_app, run_workflow
from sarcli.errors import ConfigError

_WINDOW_HELP = "rect (or none) | hamming[:a] | hann | kaiser[:beta], as stripmap focus"


def _numbers(flag: str, text: str | None) -> tuple[float, ...] | None:
    """``"a,b,c"`` -> (a, b, c); one-line error for anything but numbers."""
    if text is None:
        return None
    try:
        return tuple(float(t) for t in text.split(","))
    except ValueError:
        raise ConfigError(f"{flag} takes comma-separated numbers, e.g. -50,50,0.1,-50,50,0.1; got {text!r}") from None


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
    from sarcli.workflows import gbsar_simulate as wf

    run_workflow(wf, wf.Config(scene=scene, output=output), json_out)


@gbsar_app.command("import")
def import_cmd(
    files: list[Path] = typer.Argument(..., help="Sweep files of one format (.mat, .npz, .npy, .csv, .s1p, .s2p); "
                                       "several are concatenated along the positions."),
    output: Path = typer.Option(..., "-o", "--output", help="Output scan product (.h5)."),
    data: str = typer.Option(None, "--data", help="Samples: a complex variable or RE,IM (dotted paths into MATLAB "
                             "structs, e.g. data.fp); CSV: column(s); Touchstone: S11|S21|S12|S22 "
                             "[default: usual names (fp, s21, data, ...); S21 for .s2p]."),
    frequency: str = typer.Option(None, "--frequency", help="Frequencies (Hz) [default: freq, frequency, f, ...]."),
    position: str = typer.Option(None, "--position", help="Antenna positions (m): one variable (n rail positions, or "
                                 "n x 3) or X,Y,Z; Touchstone: START:STEP or a comma list, one per file "
                                 "[default: position, pos, ..., or x,y,z]."),
    reference_range: str = typer.Option(None, "--reference-range", help="Range (m) each sweep's phase is referenced "
                                        "to, per sweep or one value [default: r0, R0, reference_range if present]."),
    layout: str = typer.Option("auto", "--layout", metavar="[auto|frequency-position|position-frequency]",
                               help="auto | frequency-position | position-frequency (needed when "
                               "the matrix is square)."),
    pol: str = typer.Option(None, "--pol", help="Polarization VV|VH|HV|HH [default: from the file names, else VV]."),
    height: float = typer.Option(0.0, "--height", help="Antenna height (m) of 1-D rail positions."),
    antenna_length: float = typer.Option(None, "--antenna-length", help="Antenna length L_x (m) for the rail "
                                         "focusers' beam footprint [default: 0.25]."),
    epoch: str = typer.Option("2000-01-01T00:00:00Z", "--epoch", help="Scan epoch (ISO-8601 UTC)."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Import frequency sweeps (one per antenna position) into a scan product for `gbsar focus`.

    A sample matrix is frequency x position or position x frequency: the layout is taken from the
    lengths of the frequency and position vectors (the report says which). Positions are 1-D rail
    positions or a 3-D track; a reference range per sweep (de-ramped, motion-compensated phase
    histories) makes S21 ~ exp(-j*4*pi*f*(R - r_ref)/c). Focus 3-D or referenced scans with
    `gbsar focus --algorithm bp --grid ...`.

    Examples:

      sarcli gbsar import ../shared/data/gotcha_pass1_hh/data_3dsar_pass1_az00?_HH.mat -o gotcha.h5

      sarcli gbsar import sweeps.npz --data S --frequency f --position x --height 1.2 -o rail.h5

      sarcli gbsar import stop_*.s2p --position 0:0.01 -o lab.h5
    """
    from sarcli.workflows import gbsar_import as wf

    cfg = wf.Config(inputs=tuple(files), output=output, data=data, frequency=frequency, position=position,
                    reference_range=reference_range, layout=layout, pol=pol, height_m=height,
                    antenna_length_m=antenna_length, epoch_utc=epoch)
    run_workflow(wf, cfg, json_out)


@gbsar_app.command("plan")
def plan_cmd(
    source: Path = typer.Argument(..., help="Scene TOML or scan product (.h5)."),
    max_range: float = typer.Option(None, "--max-range", help="Image range Rc (m) for RD's N_xfft [default: "
                                    "the scene's processing.max_range_m, else R_max]."),
    criterion_deg: float = typer.Option(45.0, "--criterion-deg", help="DF phase-error criterion (deg), eq. 12."),
    json_out: bool = typer.Option(False, "--json", help="Print the table as JSON on stdout."),
) -> None:
    """Print the derived system table ([LeeGBSAR-II-2007, Table 1]), the DF minimum range and resolution by region.

    Examples:

      sarcli gbsar plan samples/gbsar_outdoor.toml

      sarcli gbsar plan scan.h5 --json
    """
    from sarcli.workflows import gbsar_plan as wf

    run_workflow(wf, wf.Config(source=source, max_range_m=max_range, criterion_deg=criterion_deg), json_out,
                 text=typer.echo)


@gbsar_app.command("focus")
def focus_cmd(
    scan: Path = typer.Argument(..., help="Scan product (.h5)."),
    output: Path = typer.Option(..., "-o", "--output", help="Output image product (.h5)."),
    algorithm: str = typer.Option("auto", "--algorithm", metavar="[auto|df|rd|bp|ffbp]",
                                  help="auto | df | rd | bp | ffbp (fast factorized backprojection)."),
    pol: list[str] = typer.Option(None, "--pol", help="Polarization(s) to focus [default: all]."),
    max_range: float = typer.Option(None, "--max-range", help="Largest image range R0 (m) [default: R_max]."),
    min_range: float = typer.Option(0.0, "--min-range", help="Smallest image range R0 (m)."),
    pixel_x: float = typer.Option(None, "--pixel-x", help="Azimuth pixel (m), a multiple of the rail step "
                                  "[default: about half the range pixel]."),
    width: float = typer.Option(None, "--width", help="Azimuth width of the image (m) [default: beam "
                                "footprint at the top range plus the rail, at most DF's width]."),
    criterion_deg: float = typer.Option(45.0, "--criterion-deg", help="DF phase-error criterion (deg) for auto."),
    near: str = typer.Option("bp", "--near", metavar="[bp|rd]", help="auto's near-range algorithm: bp | rd."),
    n_xfft: int = typer.Option(None, "--n-xfft", help="Azimuth FFT size for DF/RD [default: the paper's rule]."),
    rd_reference: str = typer.Option("sinc", "--rd-reference", metavar="[sinc|rect]",
                                     help="RD reference weighting: sinc (real "
                                     "antenna) | rect (the paper's ideal beam)."),
    range_window: str = typer.Option("hamming", "--range-window", help=f"Taper over the frequencies: {_WINDOW_HELP}."),
    azimuth_window: str = typer.Option("hamming", "--azimuth-window",
                                       help=f"Taper over the rail stops: {_WINDOW_HELP}."),
    geotiff: Path = typer.Option(None, "--geotiff", help="Amplitude (dB) GeoTIFF in UTM of the first polarization."),
    enu_geotiff: Path = typer.Option(None, "--enu-geotiff", help="Amplitude (dB) GeoTIFF in local ENU."),
    map_pixel: float = typer.Option(None, "--map-pixel", help="Map pixel (m) of the GeoTIFFs [default: range pixel]."),
    ground_height: float = typer.Option(0.0, "--ground-height", help="Surface height z (m) for geocoding."),
    quicklook: Path = typer.Option(None, "--quicklook", help="Quicklook PNG of the slant-plane amplitude."),
    grid: str = typer.Option(None, "--grid", help="x0,x1,dx,y0,y1,dy[,z] (m): backproject onto this horizontal "
                             "grid of the scan's frame (z default 0) instead of the rail's slant plane."),
    permittivity: float = typer.Option(1.0, "--permittivity", help="Relative permittivity of the medium: waves "
                                       "travel at c/sqrt(EPS), image ranges are distances in it (e.g. depth)."),
    device: str = typer.Option("cpu", "--device", metavar="[cpu|cuda]", envvar="SARCLI_DEVICE",
                               help="Where backprojection runs (bp, auto's bp ranges, --grid, ffbp): cpu or cuda "
                               "(a GPU and the gpu extra; DF and RD stay on the CPU)."),
    double: bool = typer.Option(False, "--double", help="--grid backprojection with the float64 kernel (the "
                                "reference; default: float32 phasor recurrence, within 4e-5 of it)."),
    json_out: bool = typer.Option(False, "--json", help="Print the focusing report as JSON on stdout."),
) -> None:
    """Focus a scan: range compression, then DF, RD, BP or auto (DF beyond the eq. 12 limit, BP/RD nearer).

    The image lies in the slant plane of the rail (range R0 from the rail line, azimuth x along it);
    its phase at a scatterer is -4*pi*R0/lambda for every algorithm. A scan measured with the rail
    moving backwards focuses to the same image; an output that is the input is refused.
    With --grid, BP focuses onto a horizontal grid of the scan's frame (a rail: x along it, y across,
    z up; an imported 3-D track: the data's own frame, for GOTCHA centred on the scene), from any
    antenna track and reference ranges; a scatterer then focuses to its complex amplitude.

    Examples:

      sarcli gbsar focus scan.h5 -o image.h5 --geotiff image.tif --quicklook image.png

      sarcli gbsar focus scan.h5 --algorithm rd --max-range 15 -o near.h5 --json

      sarcli gbsar focus scan.h5 -o kaiser.h5 --range-window kaiser:2.5 --azimuth-window hann

      sarcli gbsar focus gotcha.h5 --algorithm bp --grid -50,50,0.1,-50,50,0.1 -o cars.h5 --quicklook cars.png

      sarcli gbsar focus gpr.h5 --algorithm bp --permittivity 6 --max-range 2 -o depth.h5

      sarcli gbsar focus gotcha.h5 --algorithm bp --grid -50,50,0.1,-50,50,0.1 -o cars.h5 --device cuda
    """
    from sarcli.workflows import gbsar_focus as wf

    cfg = wf.Config(scan=scan, output=output, algorithm=algorithm, pols=tuple(pol or ()), max_range_m=max_range,
                    min_range_m=min_range, pixel_x_m=pixel_x, width_m=width, criterion_deg=criterion_deg, near=near,
                    n_xfft=n_xfft, rd_reference=rd_reference, range_window=range_window,
                    azimuth_window=azimuth_window, geotiff=geotiff, enu_geotiff=enu_geotiff, map_pixel_m=map_pixel,
                    ground_height_m=ground_height, quicklook=quicklook, grid_m=_numbers("--grid", grid),
                    permittivity=permittivity, bp_precision="double" if double else "single",
                    device=(device or "cpu").strip().lower())
    run_workflow(wf, cfg, json_out)


@gbsar_app.command("interfere")
def interfere_cmd(
    reference: Path = typer.Argument(..., help="Reference image (or scan) A."),
    secondary: Path = typer.Argument(..., help="Secondary image (or scan) B; the interferogram is B * conj(A)."),
    output: Path = typer.Option(..., "-o", "--output", help="Output interferogram product (.h5)."),
    mode: str = typer.Option("dinsar", "--mode", metavar="[dinsar|crosstrack|deltaf|combined]",
                             help="dinsar | crosstrack | deltaf | combined."),
    pol: str = typer.Option(None, "--pol", help="Polarization [default: the first of A]."),
    window: int = typer.Option(5, "--window", help="Coherence boxcar window (pixels)."),
    ground_height: float = typer.Option(0.0, "--ground-height", help="Reference surface height z (m) of the model."),
    geotiff: Path = typer.Option(None, "--geotiff", help="UTM GeoTIFF of the residual phase (rad)."),
    png: Path = typer.Option(None, "--png", help="PNG of the residual phase: hue = phase, brightness = coherence."),
    value_png: Path = typer.Option(None, "--value-png", help="PNG of the converted value (mm or m), unwrapped."),
    value_geotiff: Path = typer.Option(None, "--value-geotiff", help="UTM GeoTIFF of the converted value."),
    coherence_png: Path = typer.Option(None, "--coherence-png", help="PNG of the coherence (0..1)."),
    coherence_geotiff: Path = typer.Option(None, "--coherence-geotiff", help="UTM GeoTIFF of the coherence."),
    min_coherence: float = typer.Option(0.5, "--min-coherence", help="The converted value (product, --value-png, "
                                        "--value-geotiff) is NaN where the coherence is below this (0 keeps all)."),
    map_pixel: float = typer.Option(None, "--map-pixel", help="GeoTIFF pixel (m) [default: range pixel]."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Interferogram of two GB-SAR images: phase, coherence, model phase removed, converted value.

    dinsar -> LOS displacement (mm); crosstrack / combined -> height (m); deltaf -> range offset (m),
    from the residual phase unwrapped spatially (SNAPHU, coherence-weighted; docs/gbsar.md).
    Scans given instead of images are focused with --algorithm auto first. Pixels outside the beam
    footprint (no image support) are NaN (blank in PNGs, nodata in GeoTIFFs); the converted value is
    also NaN where the coherence is below --min-coherence.

    Examples:

      sarcli gbsar interfere t2.h5 t3.h5 --mode crosstrack -o xt.h5 --png xt.png --value-png height.png

      sarcli gbsar interfere t1.h5 t2.h5 --mode dinsar -o dinsar.h5 --value-geotiff los.tif --json

      sarcli gbsar interfere t1.h5 t2.h5 -o dinsar.h5 --png phase.png --coherence-png coherence.png
    """
    from sarcli.workflows import gbsar_interfere as wf

    cfg = wf.Config(reference=reference, secondary=secondary, output=output, mode=mode, pol=pol, window=window,
                    ground_height_m=ground_height, min_coherence=min_coherence, geotiff=geotiff, png=png,
                    value_png=value_png, value_geotiff=value_geotiff, coherence_png=coherence_png,
                    coherence_geotiff=coherence_geotiff, map_pixel_m=map_pixel)
    run_workflow(wf, cfg, json_out)


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
    workers: int = typer.Option(None, "--workers", help="Run the pixel-block tasks on a local Dask cluster of "
                                "this many processes."),
    scheduler: str = typer.Option(None, "--scheduler", metavar="ADDRESS", help="Run them on this Dask scheduler "
                                  "(tcp://host:8786)."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Temporal coherence |sum z|/sum|z|, persistent-scatterer selection and PS phase/displacement series.

    The images are read block by block (bounded memory, however many there are), as a task graph
    over pixel blocks (here, or on a Dask cluster with --workers / --scheduler: the same result).

    Examples:

      sarcli gbsar coherence p1.h5 p2.h5 p3.h5 p4.h5 --threshold 0.99 -o ps.h5 --csv ps.csv --plot ps.png

      sarcli gbsar coherence scans/*.h5 -o ps.h5 --workers 2
    """
    from sarcli.workflows import gbsar_coherence as wf

    cfg = wf.Config(images=tuple(images), output=output, threshold=threshold, dynamic_range_db=dynamic_range_db,
                    pol=pol, csv=csv, plot=plot, workers=workers, scheduler=scheduler)
    run_workflow(wf, cfg, json_out)


@gbsar_app.command("polarimetry")
def polarimetry_cmd(
    image: Path = typer.Argument(..., help="Image (or scan) with HH and VV."),
    geotiff: Path = typer.Option(None, "--geotiff", help="UTM GeoTIFF of (HH-VV)/(HH+VV)."),
    png: Path = typer.Option(None, "--png", help="PNG of (HH-VV)/(HH+VV) in the slant plane."),
    window: int = typer.Option(3, "--window", help="Boxcar window (pixels) for the powers."),
    map_pixel: float = typer.Option(None, "--map-pixel", help="GeoTIFF pixel (m) [default: range pixel]."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Polarimetric normalized difference (|HH|^2-|VV|^2)/(|HH|^2+|VV|^2) image ([LeeGBSAR-I-2007, §3.1, Fig. 4d]).

    Examples:

      sarcli gbsar polarimetry image.h5 --png nd.png --geotiff nd.tif
    """
    from sarcli.workflows import gbsar_polarimetry as wf

    cfg = wf.Config(image=image, geotiff=geotiff, png=png, window=window, map_pixel_m=map_pixel)
    run_workflow(wf, cfg, json_out)


def register(app: typer.Typer) -> None:
    attach(app)
