"""``sarcli optical``: the emulated AOD/CCD processor of [KimAODCCD] against the digital RD image."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import info, make_typer, print_report, run_workflow

optical_app = make_typer(help="Emulated acousto-optic / CCD real-time processor [KimAODCCD].")


@optical_app.command("compare")
def compare_cmd(
    raw_path: Path = typer.Argument(..., metavar="RAW", help="Simulated airborne raw product (HDF5) with truth."),
    json_out: bool = typer.Option(False, "--json", help="Print the report as JSON."),
    plot: Path | None = typer.Option(None, "--plot", help="Write the comparison figure (PNG)."),
    reference_offset_hz: float | None = typer.Option(
        None, help="Reference-beam offset dnu = nu2 - nu1 (Hz); default the rule dnu = B of [KimAODCCD]."),
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
    report = run_workflow("optical_compare", {"raw": raw_path, "plot": plot, "reference_offset_hz": reference_offset_hz,
                                              "magnification": magnification, "adc_bits": adc_bits,
                                              "centre_range_m": centre_range_m, "quick": quick},
                          flags={"raw": "RAW"}, progress_disabled=json_out)
    if plot is not None:
        info(f"wrote {plot}", quiet=json_out)
    print_report(report, json_out)


def register(app: typer.Typer) -> None:
    app.add_typer(optical_app, name="optical")
