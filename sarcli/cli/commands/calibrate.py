"""``sarcli calibrate``: absolute radiometric calibration of an SLC from corner reflectors.

Parses the options into :class:`sarcli.workflows.calibrate.Config`, runs the workflow, prints the report.
"""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, report


def calibrate(
    slc_path: Path = typer.Argument(..., help="SLC product (from 'sarcli focus')."),
    corner_reflectors: Path = typer.Option(..., "--corner-reflectors", help="Surveyed corner reflectors (NISAR or "
                                           "UAVSAR CSV); those in service for radiometry are used."),
    output: Path = typer.Option(None, "-o", "--output", help="Calibrated SLC to write (default: rewrite the input "
                                "atomically)."),
    search: int = typer.Option(8, "--search", help="Peak search around each predicted position, pixels."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON report on stdout."),
) -> None:
    """Derive the absolute calibration constant K from corner reflectors and write it into the SLC.

    Each reflector's RCS is measured by integrated energy and compared with the theoretical RCS of a
    triangular trihedral of its side along the radar's line of sight; K is scaled by the mean ratio
    and the product's beta0/sigma0/gamma0 look-up tables with it.

    Examples:

      sarcli calibrate slc.h5 --corner-reflectors CR.csv

      sarcli calibrate slc.h5 --corner-reflectors CR.csv -o slc_cal.h5 --json
    """
    from sarcli.workflows.calibrate import Config, run

    rep = run(Config(slc=slc_path, reflectors=corner_reflectors, output=output, search_px=search))
    if as_json:
        emit_json(rep.to_dict())
        return
    for line in rep.lines():
        report(line)


def register(app: typer.Typer) -> None:
    app.command("calibrate")(calibrate)
