"""The ``sarcli`` entry point: a command group that imports a command's module only when it runs.

:data:`COMMANDS` names every top-level command, the modules of :mod:`sarcli.cli.commands` that
register it (each defines ``register(app)``) and the first paragraph of its help, which ``sarcli
--help`` lists without importing any command module: ``sarcli --help`` and ``sarcli focus`` import
only what they use. Adding a command group is one module plus one line here (a test checks that the
table and the modules agree).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

import typer
import typer.main
from typer.core import TyperCommand

from sarcli.cli.common import SarcliGroup, make_typer, terminal

#: command -> (modules of sarcli.cli.commands that register it, the first paragraph of its help), in the
#: order of ``sarcli --help`` (commands, then command groups)
COMMANDS: dict[str, tuple[tuple[str, ...], str]] = {
    "batch": (("batch",), "Process a folder of scenes: raw -> Doppler -> SLC + GeoTIFF + quicklook, as one "
                          "task graph."),
    "calibrate": (("calibrate",), "Derive the absolute calibration constant K from corner reflectors and write "
                  "it into the SLC."),
    "design": (("design",), "Derive resolutions, PRF window, Doppler samples and swath, and check each "
                            "constraint."),
    "doppler": (("doppler",), "Estimate the Doppler centroid (baseband CDE + ambiguity) and the Doppler rate."),
    "export": (("export",), "Write a focused image in an interchange format; sarcli's own SLC stays the "
                            "working format."),
    "focus": (("focus",), "Focus a stripmap raw product into a single-look complex image."),
    "info": (("info",), "Describe a product, a GeoTIFF or a raw input; nothing is written."),
    "ingest": (("ingest",), "Ingest raw data: the sensor reader is found by sniffing the input (or named with "
                            "--format)."),
    "quality": (("quality",), "Measure point targets: IRW, PSLR and ISLR in range and azimuth, and the peak "
                              "position error."),
    "run": (("run",), "Run workflows from a file: each top-level table is a step, its keys the step's options."),
    "simulate": (("simulate",), "Simulate the raw echoes of a stripmap scene; only the effects the scene lists "
                                "are computed."),
    "ati": (("ati",), "SAR along-track interferometry: detect, estimate, compensate ground movers."),
    "gbsar": (("gbsar_acquisition", "gbsar_monitoring", "gbsar_processing"),
              "Ground-based SAR: simulate, import, plan, focus, interfere, coherence; acquire with a VNA and a rail; "
              "monitor a slope."),
    "optical": (("optical",), "Emulated acousto-optic / CCD real-time processor [KimAODCCD]."),
    "orbit": (("orbit_cmd",), "Orbit state vectors: summary, Hermite interpolation, accuracy/cost tables."),
}


_LOADED: dict[str, tuple[typer.Typer, Any]] = {}


def load_command(name: str) -> Any:
    """The command (or command group) ``name`` of :data:`COMMANDS`, its modules imported on first use.
    (The Typer app it was registered on is kept alive: ``gbsar_app.attach`` remembers apps by id.)"""
    if name not in _LOADED:
        sub = make_typer()
        for module in COMMANDS[name][0]:
            importlib.import_module(f"sarcli.cli.commands.{module}").register(sub)
        _LOADED[name] = (sub, typer.main.get_group(sub).commands[name])
    return _LOADED[name][1]


class LazyGroup(SarcliGroup):
    """The root group: lists :data:`COMMANDS` from the table, imports a command when it is asked for."""

    def list_commands(self, ctx: typer.Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: typer.Context, cmd_name: str) -> Any:
        if cmd_name not in self.commands and cmd_name in COMMANDS:
            self.commands[cmd_name] = load_command(cmd_name)
        return self.commands.get(cmd_name)

    def format_commands(self, ctx: typer.Context, formatter: Any) -> None:
        width = formatter.width - 6 - max(len(n) for n in COMMANDS)
        rows = [(n, TyperCommand(n, help=text).get_short_help_str(width)) for n, (_, text) in COMMANDS.items()]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


app = make_typer(
    cls=LazyGroup,
    help=(
        "sarcli: SAR processing from raw echoes and GB-SAR scans to products.\n\n"
        "Examples:\n\n"
        "  sarcli simulate samples/rs1_point.toml -o raw.h5\n\n"
        "  sarcli info raw.h5 --json\n\n"
        "  sarcli -v --log-file run.log run steps.toml\n\n"
        "Run 'sarcli COMMAND --help' (or -h) for a command's options and examples. Exit status: 0 done, 1 bad "
        "data, 2 usage or configuration, 3 instrument fault, 130 interrupted (docs/cli.md)."
    ),
    add_completion=True,  # --install-completion / --show-completion (bash, zsh, fish, PowerShell)
    context_settings={"help_option_names": ["-h", "--help"]},  # inherited by every command
)


def _print_version(value: bool) -> None:
    if value:
        from sarcli import versions  # GDAL and PROJ: asked only here

        typer.echo(versions.version_text())
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    version: bool = typer.Option(False, "--version", is_eager=True, callback=_print_version,
                                 help="Print the versions of sarcli, numpy, numba, GDAL, PROJ, ... and exit."),
    verbose: int = typer.Option(0, "--verbose", "-v", count=True,
                                help="Show diagnostics on stderr: -v progress of each step, -vv debugging detail."),
    quiet: bool = typer.Option(False, "--quiet", "-q",
                               help="Hide status lines and progress bars (results, warnings and errors stay)."),
    log_file: Path = typer.Option(None, "--log-file", dir_okay=False, metavar="PATH",
                                  help="Append every diagnostic (DEBUG), status line, warning and error, "
                                       "with times, to this file."),
) -> None:
    """sarcli command line."""
    ctx.with_resource(terminal(verbose, quiet, log_file))


def main() -> None:
    """Console-script entry point."""
    app()
