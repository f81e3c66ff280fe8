"""``sarcli run STEPS.toml``: run the workflows named by a TOML file's tables, in order."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import print_report, run_workflow


def run(
    steps: Path = typer.Argument(..., help="Steps file (TOML): one table per step, [simulate], [ingest], [info], ..."),
    as_json: bool = typer.Option(False, "--json", help="Print every step's report as one JSON object."),
) -> None:
    """Run workflows from a file: each top-level table is a step, its keys the step's options.

    The table names are workflow names (sarcli run --help lists them in the docs: simulate, ingest, info,
    orbit_info, orbit_interpolate, orbit_accuracy, ati_detect, ati_estimate, ati_compensate,
    ati_montecarlo, optical_compare, design, and doppler, focus, ... where installed). Every step is
    checked before the first runs; paths are relative to the current folder.

    Example steps.toml:

      [simulate]
      scene = "samples/rs1_point.toml"
      output = "demo/raw.h5"

      [info]
      sources = ["demo/raw.h5"]

    Examples:

      sarcli run steps.toml

      sarcli -v --log-file run.log run steps.toml --json
    """
    print_report(run_workflow("run", {"steps": steps}, flags={"steps": "STEPS"}), as_json)


def register(app: typer.Typer) -> None:
    app.command("run")(run)
