"""``sarcli design``: the SAR design calculator (relations of [KimAODCCD, §2.4]) with a verdict per constraint."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import print_report, run_workflow


def design(
    source: Path = typer.Argument(..., help="Design TOML ([design] table), a stripmap or GB-SAR scene TOML, "
                                            "a raw product or a GB-SAR scan (.h5)."),
    json_out: bool = typer.Option(False, "--json", help="Print the full report as JSON."),
) -> None:
    """Derive resolutions, PRF window, Doppler samples and swath, and check each constraint.

    Examples:

      sarcli design samples/aod_ccd_example.toml

      sarcli design samples/design_radarsat1.toml --json

      sarcli design samples/gbsar_outdoor.toml

      sarcli design raw.h5

    Exit status 0 also when a constraint is violated: violations are reported, not errors.
    """
    print_report(run_workflow("design", {"source": source}, flags={"source": "SOURCE"}), json_out)


def register(app: typer.Typer) -> None:
    app.command("design")(design)
