"""``sarcli quality``: point-target quality of an SLC (IRW, PSLR, ISLR, position error).

Parses the options into :class:`sarcli.workflows.quality.Config`, runs the workflow, prints the report.
"""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, report
from sarcli.errors import ConfigError


def _parse_at(values: list[str]) -> tuple[tuple[float, float], ...]:
    out = []
    for v in values:
        try:
            a, b = (float(x) for x in v.split(","))
        except ValueError:
            raise ConfigError(f"--at {v!r}: expected TIME_S,RANGE_M (zero-Doppler time, slant range)") from None
        out.append((a, b))
    return tuple(out)


def quality(
    slc_path: Path = typer.Argument(..., help="SLC product (from 'sarcli focus')."),
    at: list[str] = typer.Option(None, "--at", help="Target at TIME_S,RANGE_M (zero-Doppler time s after the "
                                 "epoch, slant range m); repeatable. Default: the simulated truth targets."),
    corner_reflectors: Path = typer.Option(None, "--corner-reflectors", help="Surveyed corner reflectors (NISAR or "
                                           "UAVSAR CSV): offsets from the orbit's prediction and the IRF of each."),
    plots: Path = typer.Option(None, "--plots", help="With --corner-reflectors: a folder for one IRF PNG per "
                               "reflector (created if missing)."),
    plot: Path = typer.Option(None, "--plot", help="PNG of the point targets' impulse responses: range and "
                              "azimuth cuts and 2-D contours, one row per target."),
    frequency: str = typer.Option(None, "--frequency", help="NISAR RSLC layer: frequency A or B (default: first)."),
    polarization: str = typer.Option(None, "--polarization", help="NISAR RSLC layer: HH, HV, ... (default HH)."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object per target (a list) on stdout."),
) -> None:
    """Measure point targets: IRW, PSLR and ISLR in range and azimuth, and the peak position error.

    PSLR/ISLR use the main lobe between the first minima and sidelobes out to 20 main-lobe
    half-widths; IRW is the -3 dB width (metres: slant range, ground azimuth). With simulated truth
    (or --at) the position error is the distance between the interpolated peak and the truth. The
    image may be a sarcli SLC or a NISAR RSLC (sarcli's or ISCE3's). With --corner-reflectors, each
    surveyed reflector inside the image is predicted from the orbit (zero-Doppler solve, plate motion
    applied) and measured: range/azimuth offsets (m), IRW, PSLR, ISLR, the theoretical IRWs, and the
    corrections to add before reading an offset as a geometry error (docs/nisar.md).

    Examples:

      sarcli quality slc.h5

      sarcli quality slc.h5 --json

      sarcli quality slc.h5 --plot irf.png

      sarcli quality slc.h5 --at -3.758,993644.5 --at -3.9485,992646.0

      sarcli quality rslc.h5 --corner-reflectors CR.csv --plots cr_plots --json
    """
    if corner_reflectors is not None:
        if plot is not None:
            raise ConfigError("--plot draws point targets; with --corner-reflectors use --plots FOLDER")
        if at:
            raise ConfigError("--at and --corner-reflectors are two ways to name the targets: give one")
        from sarcli.workflows import corner_reflectors as crw

        cr = crw.run(crw.Config(slc=slc_path, reflectors=corner_reflectors, plots=plots, frequency=frequency,
                                polarization=polarization))
        if as_json:
            emit_json(cr.records())
        else:
            for line in cr.lines():
                report(line)
        return
    if plots is not None:
        raise ConfigError("--plots goes with --corner-reflectors")
    from sarcli.workflows.quality import Config, run

    rep = run(Config(slc=slc_path, at=_parse_at(at or []), frequency=frequency, polarization=polarization,
                     plot=plot))
    if as_json:
        emit_json(rep.to_dict()["targets"])
        return
    for line in rep.lines():
        report(line)


def register(app: typer.Typer) -> None:
    app.command("quality")(quality)
