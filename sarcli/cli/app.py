"""The ``sarcli`` entry point: discovers command modules in :mod:`sarcli.cli.commands`.

Each module there defines ``register(app)`` and adds its commands or sub-apps. Adding a command
group touches nothing else.
"""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

import typer

from sarcli.cli import commands
from sarcli.cli.common import make_typer, terminal

app = make_typer(
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


def _register_all() -> None:
    for mod in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{commands.__name__}.{mod.name}")
        module.register(app)


_register_all()


def main() -> None:
    """Console-script entry point."""
    app()
