"""``sarcli optical``: the emulated AOD/CCD processor of seed 004 against the digital RD image."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, make_typer, progress_bar

optical_app = make_typer(help="Emulated acousto-optic / CCD real-time processor (seed 004).")


@optical_app.command("compare")
def compare_cmd(
    raw_path: Path = typer.Argument(..., metavar="RAW", help="Simulated airborne raw product (HDF5) with truth."),
    json_out: bool = typer.Option(False, "--json", help="Print the report as JSON."),
    plot: Path | None = typer.Option(None, "--plot", help="Write the comparison figure (PNG)."),
    reference_offset_hz: float | None = typer.Option(
        None, help="Reference-beam offset dnu = nu2 - nu1 (Hz); default the seed's rule dnu = B."),
    magnification: str = typer.Option("carrier", help="carrier (pixels sample the carrier) or fit_aod."),
    adc_bits: int = typer.Option(8, help="Read-out converter bits (the 'adc' limitation)."),
    centre_range_m: float | None = typer.Option(None, help="Slant range at the CCD's centre column (m)."),
    quick: bool = typer.Option(False, "--quick", help="Skip the one-limitation-at-a-time images."),
) -> None:
    """Measure the optical processor (ideal, each device limitation alone, all with and without bias
    removal) against the digital Range-Doppler image of the same point-target scene.

    Examples:

      sarcli simulate samples/aod_ccd_scene.toml -o aod.h5

      sarcli optical compare aod.h5 --plot optical.png

      sarcli optical compare aod.h5 --reference-offset-hz 2e7 --json
    """
    from sarcli.io.raw import read_raw
    from sarcli.optical.compare import cases, compare
    from sarcli.optical.devices import CCD, OpticalSettings
    from sarcli.optical.plot import comparison_png

    settings = OpticalSettings(ccd=CCD(adc_bits=adc_bits), reference_offset_hz=reference_offset_hz,
                               magnification=magnification)  # checked before reading anything
    raw = read_raw(raw_path)
    with progress_bar(len(cases(not quick)) + 1, label="images", disable=json_out) as bar:
        report = compare(raw, settings, centre_range_m=centre_range_m, single_limitations=not quick,
                         keep_images=plot is not None, on_step=lambda _label: bar.update(1))
    images = report.pop("images", None)
    if plot is not None:
        comparison_png(plot, images, title=f"{raw_path.name}: digital RD vs emulated AOD/CCD processor")
        info(f"wrote {plot}", quiet=json_out)
    if json_out:
        emit_json(report)
        return
    p, d = report["predictions"], report["design"]
    typer.echo(f"design: dnu = {d['reference_offset_hz'] / 1e6:.2f} MHz, pixel = {d['pixel_delay_s'] * 1e9:.2f} ns "
               f"(magnification {d['magnification']:.3f}), swath {d['swath_slant_m']:.0f} m, "
               f"{d['rows_integrated']} rows integrated")
    typer.echo(f"predicted: range IRW {p['irw_range_m']:.2f} m, azimuth IRW (CCD rows) {p['irw_azimuth_ccd_m']:.2f} m, "
               f"light-pulse gain {p['light_pulse_gain']:.3f}, pixel gain {p['ccd_pixels_gain']:.3f}")
    typer.echo(f"{'image':40s} {'s':>6s} {'dR m':>6s} {'dAz m':>6s} {'IRW r':>6s} {'IRW az':>6s} "
               f"{'PSLR r':>7s} {'PSLR az':>7s} {'DR dB':>6s} {'peak':>8s}")
    for r in report["rows"]:
        typer.echo(f"{r['processor']:40s} {r['seconds']:6.2f} {r['range_error_m']:6.2f} {r['azimuth_error_m']:6.2f} "
                   f"{r['irw_range_m']:6.2f} {r['irw_azimuth_m']:6.2f} {r['pslr_range_db']:7.1f} "
                   f"{r['pslr_azimuth_db']:7.1f} {r['dynamic_range_db']:6.1f} {r['peak_amplitude']:8.1f}")


def register(app: typer.Typer) -> None:
    app.add_typer(optical_app, name="optical")
