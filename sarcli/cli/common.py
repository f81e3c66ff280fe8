"""Helpers shared by all commands: one-line errors, JSON output, progress bars, typer factory."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

import typer
from typer.core import TyperGroup

from orbit.errors import OrbitError
from sarcli.errors import InstrumentError, Interrupted, ProductError, SarcliError
from sarcli.io.h5common import to_jsonable

T = TypeVar("T")


EXIT_USAGE, EXIT_DATA, EXIT_INSTRUMENT, EXIT_INTERRUPT = 2, 1, 3, 130


def exit_code_for(error: BaseException) -> int:
    """The exit status of an error: 130 interrupted, 3 instrument, 1 bad data, 2 usage or configuration."""
    if isinstance(error, Interrupted | KeyboardInterrupt):
        return EXIT_INTERRUPT
    if isinstance(error, InstrumentError):
        return EXIT_INSTRUMENT
    if isinstance(error, ProductError | OrbitError | OSError):
        return EXIT_DATA
    return EXIT_USAGE


def fail(message: str, exit_code: int = EXIT_USAGE) -> typer.Exit:
    """Print ``sarcli: error: message`` on stderr and return the Exit to raise."""
    typer.echo(f"sarcli: error: {message}", err=True)
    return typer.Exit(exit_code)


class SarcliGroup(TyperGroup):
    """A command group that turns user errors into one line on stderr and a non-zero exit."""

    def invoke(self, ctx: typer.Context) -> Any:
        from sarcli.io.provenance import Provenance, using

        try:
            with using(Provenance(command_line=command_line())):
                return super().invoke(ctx)
        except (SarcliError, OrbitError) as e:  # OrbitError: impossible geometry, bad state vectors
            raise fail(str(e), exit_code_for(e)) from None
        except (FileNotFoundError, PermissionError, IsADirectoryError) as e:
            name = getattr(e, "filename", None)
            raise fail(f"{name}: {e.strerror}" if name else str(e), exit_code_for(e)) from None
        except KeyboardInterrupt as e:
            raise fail("interrupted", exit_code_for(e)) from None


def command_line() -> str:
    """The command as the user typed it (program name without its folder), for the products' provenance."""
    from pathlib import Path

    argv = list(sys.argv)
    if argv:
        argv[0] = Path(argv[0]).name
    return " ".join(argv)


def make_typer(**kwargs: Any) -> typer.Typer:
    """A Typer app/sub-app with sarcli's error handling and conventions."""
    kwargs.setdefault("no_args_is_help", True)
    kwargs.setdefault("add_completion", False)
    kwargs.setdefault("pretty_exceptions_enable", False)
    kwargs.setdefault("rich_markup_mode", None)
    return typer.Typer(cls=SarcliGroup, **kwargs)


def emit_json(obj: Any) -> None:
    """Print one JSON document on stdout (numpy types converted, NaN -> null)."""
    sys.stdout.write(json.dumps(to_jsonable(obj), indent=2, sort_keys=False) + "\n")
    sys.stdout.flush()


def require_output_folders(*paths: Any) -> None:
    """Refuse (one line) an output whose folder does not exist, before any work is done (None: skipped)."""
    from pathlib import Path

    for p in paths:
        if p is not None and not Path(p).resolve().parent.is_dir():
            raise SarcliError(f"output folder {Path(p).resolve().parent} does not exist: create it first")


def report(msg: str) -> None:
    """A line of the command's result for people (stdout: `sarcli info f.h5 | less` works)."""
    typer.echo(msg)


def info(msg: str, quiet: bool = False) -> None:
    """Human-readable progress/status line on stderr (stdout stays clean for --json)."""
    if not quiet:
        typer.echo(msg, err=True)


def _progress_enabled(disable: bool) -> bool:
    if disable or os.environ.get("SARCLI_NO_PROGRESS"):
        return False
    return sys.stderr.isatty()


def progress(items: Iterable[T], total: int | None = None, label: str = "", disable: bool = False) -> Iterator[T]:
    """Iterate with a progress bar (ETA) on stderr when it is a terminal; silent otherwise."""
    if not _progress_enabled(disable):
        yield from items
        return
    with typer.progressbar(items, length=total, label=label, file=sys.stderr, show_eta=True,
                           show_percent=True) as bar:
        yield from bar


@contextmanager
def progress_bar(total: int, label: str = "", disable: bool = False) -> Iterator[Any]:
    """A manual progress bar: ``with progress_bar(n) as bar: bar.update(1)``; no-op when not a tty."""
    if not _progress_enabled(disable):
        class _Null:
            def update(self, n: int = 1) -> None:
                pass
        yield _Null()
        return
    with typer.progressbar(length=total, label=label, file=sys.stderr, show_eta=True) as bar:
        yield bar
