"""The ``sarcli`` entry point: discovers command modules in :mod:`sarcli.cli.commands`.

Each module there defines ``register(app)`` and adds its commands or sub-apps. Adding a command
group touches nothing else.
"""

from __future__ import annotations

import importlib
import pkgutil
import warnings

import typer

from sarcli import __version__
from sarcli.cli import commands
from sarcli.cli.common import make_typer

app = make_typer(
    help=(
        "sarcli: SAR processing from raw echoes and GB-SAR scans to products.\n\n"
        "Examples:\n\n"
        "  sarcli simulate samples/rs1_point.toml -o raw.h5\n\n"
        "  sarcli info raw.h5 --json\n\n"
        "Run 'sarcli COMMAND --help' for a command's options and examples."
    ),
)


def _print_version(value: bool) -> None:
    if value:
        typer.echo(__version__)
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", is_eager=True, callback=_print_version,
                                 help="Print the version and exit."),
) -> None:
    """sarcli command line."""


def _register_all() -> None:
    for mod in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{commands.__name__}.{mod.name}")
        module.register(app)


_register_all()


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings reach a person as one line, like errors: ``sarcli: warning: ...``."""
    import sys

    print(f"sarcli: warning: {message}", file=sys.stderr if file is None else file)


def main() -> None:
    """Console-script entry point."""
    warnings.showwarning = _one_line_warning
    app()
