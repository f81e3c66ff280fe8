"""Helpers shared by all commands: one-line errors, JSON output, progress bars, typer factory, running a
workflow from a command's options, and what reaches the terminal (``--verbose``, ``--quiet``,
``--log-file``).

Streams: a command's result goes to stdout (``sarcli info f.h5 | less``, ``--json``); status lines,
warnings (``sarcli: warning: ...``), diagnostics and errors (``sarcli: error: ...``) go to stderr.
Diagnostics are the ``logging`` records of sarcli's modules (``logging.getLogger(__name__)``): hidden by
default, ``-v`` shows INFO, ``-vv`` DEBUG. ``--quiet`` hides status lines and progress bars (warnings and
errors stay). ``--log-file PATH`` appends everything (DEBUG diagnostics, status lines, warnings, the
error) with timestamps, whatever the terminal shows.

Nothing here imports numpy, h5py or scipy: ``sarcli --help`` stays fast.
"""

from __future__ import annotations

import json
import logging
import os
import re
import sys
import warnings
from collections.abc import Iterable, Iterator, Mapping
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any, TypeVar

import typer
from typer.core import TyperGroup

from orbit.errors import OrbitError
from sarcli.errors import ConfigError, InstrumentError, Interrupted, MissingFileError, ProductError, SarcliError

T = TypeVar("T")

#: loggers whose records are sarcli diagnostics (the ``orbit`` package is sarcli's geometry)
LOGGERS = ("sarcli", "orbit")
_LOG_FORMAT_TERMINAL = "sarcli: %(levelname_lower)s: %(name)s: %(message)s"
_LOG_FORMAT_FILE = "%(asctime)s %(levelname)s %(name)s: %(message)s"
_log = logging.getLogger("sarcli.cli")


class _Terminal:
    """What the current invocation shows (set by the root command's options)."""

    quiet = False
    log_file: logging.Handler | None = None


EXIT_USAGE, EXIT_DATA, EXIT_INSTRUMENT, EXIT_INTERRUPT = 2, 1, 3, 130


def exit_code_for(error: BaseException) -> int:
    """The exit status of an error: 130 interrupted, 3 instrument, 1 bad data, 2 usage or configuration
    (a missing input file is a usage mistake: 2)."""
    if isinstance(error, Interrupted | KeyboardInterrupt):
        return EXIT_INTERRUPT
    if isinstance(error, InstrumentError):
        return EXIT_INSTRUMENT
    if isinstance(error, MissingFileError | FileNotFoundError):
        return EXIT_USAGE
    if isinstance(error, ProductError | OrbitError | OSError):
        return EXIT_DATA
    return EXIT_USAGE


def fail(message: str, exit_code: int = EXIT_USAGE) -> typer.Exit:
    """Print ``sarcli: error: message`` on stderr and return the Exit to raise."""
    typer.echo(f"sarcli: error: {message}", err=True)
    _to_log_file(logging.ERROR, f"error (exit {exit_code}): {message}")
    return typer.Exit(exit_code)


#: Click's UsageError and the no-arguments-shows-help one (Typer 0.28 ships its own Click: found through
#: Typer's BadParameter, a UsageError)
_UsageError = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "UsageError")
_NoArgsIsHelp = getattr(sys.modules[_UsageError.__module__], "NoArgsIsHelpError", ())


def _usage_fail(e: Any) -> typer.Exit:
    """Click's own usage error (unknown option or command, missing value, bad choice) as one line naming the
    command and its help, exit 2, instead of Click's usage text."""
    where = e.ctx.command_path if e.ctx is not None else "sarcli"
    text = " ".join(e.format_message().split())
    return fail(f"{where}: {text} (see '{where} -h')", EXIT_USAGE)


class SarcliGroup(TyperGroup):
    """A command group that turns user errors into one line on stderr and a non-zero exit."""

    def make_context(self, info_name: str | None, args: list[str], parent: Any = None, **extra: Any) -> Any:
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except _NoArgsIsHelp:
            raise
        except _UsageError as e:  # the group's own options (``sarcli --bogus``)
            raise _usage_fail(e) from None

    def invoke(self, ctx: typer.Context) -> Any:
        from sarcli.io.provenance import Provenance, using

        try:
            with using(Provenance(command_line=command_line())):
                return super().invoke(ctx)
        except _NoArgsIsHelp:
            raise
        except _UsageError as e:  # a command's options, an unknown command
            raise _usage_fail(e) from None
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
    kwargs.setdefault("cls", SarcliGroup)
    return typer.Typer(**kwargs)


def emit_json(obj: Any) -> None:
    """Print one JSON document on stdout (numpy types converted, NaN -> null)."""
    from sarcli.io.h5common import to_jsonable  # numpy: only once there is a result to print

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
    """Human-readable progress/status line on stderr (stdout stays clean for --json); hidden by
    ``--quiet`` (and by ``quiet``), always in the ``--log-file``."""
    _to_log_file(logging.INFO, msg)
    if not (quiet or _Terminal.quiet):
        typer.echo(msg, err=True)


def _progress_enabled(disable: bool) -> bool:
    if disable or _Terminal.quiet or os.environ.get("SARCLI_NO_PROGRESS"):
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


@contextmanager
def progress_sink(disable: bool = False) -> Iterator[Any]:
    """A workflow's ``progress(label, done, total)`` drawn as one bar per label on stderr (a terminal
    only; nothing under ``--quiet`` or ``SARCLI_NO_PROGRESS``)."""
    if not _progress_enabled(disable):
        yield None
        return
    with ExitStack() as stack:
        bars: dict[str, Any] = {}

        def sink(label: str, done: int, total: int) -> None:
            bar = bars.get(label)
            if bar is None:
                bar = bars[label] = stack.enter_context(
                    typer.progressbar(length=max(total, 1), label=label, file=sys.stderr, show_eta=True))
            bar.update(max(0, done - bar.pos))

        yield sink


# ---------------------------------------------------------------------------------------------------------
# Running a workflow from a command's options


_FIELD = re.compile(r"^([a-z][a-z0-9_]*)(?=:| must | ')")


def name_options(message: str, flags: Mapping[str, str]) -> str:
    """A configuration message that starts with a field name (``max_gap must be ...``, ``route: 'x' is
    not one of ...``, ``route 'x': choose ...``) reworded to name the command-line option as typed
    (``--max-gap must be ...``); other messages (``output folder ... does not exist``) are kept."""
    m = _FIELD.match(message)
    if m and m.group(1) in flags:
        return flags[m.group(1)] + message[m.end():]
    return message


def run_workflow(step: str, options: Mapping[str, Any], flags: Mapping[str, str] | None = None,
                 progress_disabled: bool = False) -> Any:
    """Build workflow ``step``'s ``Config`` from a command's options (``None``: not given, the default
    applies), run it with a progress bar, return its report. Configuration messages name the options as
    typed: a field ``max_gap`` is ``--max-gap`` unless ``flags`` says otherwise (``{"raw": "RAW"}``).
    The provenance is the command line (set for the whole invocation by :class:`SarcliGroup`)."""
    import dataclasses

    from sarcli.config import from_mapping
    from sarcli.workflows import WORKFLOWS

    module = WORKFLOWS.get(step)
    names = {f.name: "--" + f.name.replace("_", "-") for f in dataclasses.fields(module.Config)}
    names.update(flags or {})
    try:
        config = from_mapping(module.Config, {k: v for k, v in options.items() if v is not None}, where="")
        _log.debug("workflow %s: %r", step, config)
        with progress_sink(progress_disabled) as sink:
            return module.run(config, progress=sink)
    except ConfigError as e:
        raise ConfigError(name_options(str(e), names)) from None


def parse_option_values(items: Iterable[str], flag: str = "--option") -> dict[str, Any]:
    """``KEY=VALUE`` strings -> a mapping; VALUE is read as a TOML value when it is one (``true``, ``12``,
    ``1.5``, ``"text"``, ``[1, 2]``), else kept as text (``missing=repeat``)."""
    import tomllib

    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(f"{flag} {item!r}: expected KEY=VALUE")
        try:
            out[key] = tomllib.loads(f"v = {value.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            out[key] = value.strip()
    return out


def print_report(report: Any, as_json: bool) -> None:
    """A workflow report as the command's result: ``--json`` -> its ``to_dict()``, else its ``lines()``,
    on stdout."""
    if as_json:
        emit_json(report.to_dict())
        return
    for line in report.lines():
        typer.echo(line)


def print_status(report: Any) -> None:
    """A workflow report's ``lines()`` as status lines on stderr (hidden by ``--quiet``): for commands
    whose result is a file, or whose ``--json`` goes to stdout alongside."""
    for line in report.lines():
        info(line)


# ---------------------------------------------------------------------------------------------------------
# What reaches the terminal and the log file


class _LowerLevel(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        record.levelname_lower = record.levelname.lower()
        return super().format(record)


class _StderrHandler(logging.Handler):
    """Writes to the *current* ``sys.stderr`` (the test runner swaps it per invocation)."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            print(self.format(record), file=sys.stderr)
        except Exception:  # noqa: BLE001 (logging's own contract: never raise from a handler)
            self.handleError(record)


def _to_log_file(level: int, message: str) -> None:
    h = _Terminal.log_file
    if h is not None:
        h.handle(_log.makeRecord(_log.name, level, "(cli)", 0, message, None, None))


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings reach a person as one line, like errors: ``sarcli: warning: ...`` (and the log file)."""
    text = " ".join(str(message).split())
    _to_log_file(logging.WARNING, f"warning: {text} ({category.__name__}, {filename}:{lineno})")
    print(f"sarcli: warning: {text}", file=sys.stderr if file is None else file)


@contextmanager
def terminal(verbose: int = 0, quiet: bool = False, log_file: Path | None = None) -> Iterator[None]:
    """For one invocation: diagnostics at WARNING (default), INFO (``verbose`` 1) or DEBUG (2+) on
    stderr; ``quiet`` hides status lines and progress bars; ``log_file`` appends everything at DEBUG.
    Warnings are shown as one line each (once per place in the code). Undone on exit."""
    if verbose and quiet:
        raise ConfigError("--verbose and --quiet exclude each other")
    level = logging.DEBUG if verbose >= 2 else logging.INFO if verbose == 1 else logging.WARNING
    handlers: list[logging.Handler] = []
    stderr = _StderrHandler(level)
    stderr.setFormatter(_LowerLevel(_LOG_FORMAT_TERMINAL))
    handlers.append(stderr)
    file_handler = None
    if log_file is not None:
        try:
            file_handler = logging.FileHandler(log_file, mode="a", encoding="utf-8")
        except OSError as e:
            raise ConfigError(f"--log-file {log_file}: cannot open ({e.strerror})") from None
        file_handler.setLevel(logging.DEBUG)
        file_handler.setFormatter(logging.Formatter(_LOG_FORMAT_FILE))
        handlers.append(file_handler)
    saved = []
    for name in LOGGERS:
        lg = logging.getLogger(name)
        saved.append((lg, lg.level, lg.propagate))
        lg.setLevel(min(h.level for h in handlers))
        lg.propagate = False
        for h in handlers:
            lg.addHandler(h)
    _Terminal.quiet, _Terminal.log_file = quiet, file_handler
    _to_log_file(logging.INFO, f"command: {command_line()}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            warnings.showwarning = _one_line_warning
            yield
    finally:
        _Terminal.quiet, _Terminal.log_file = False, None
        for lg, lvl, prop in saved:
            for h in handlers:
                lg.removeHandler(h)
            lg.setLevel(lvl)
            lg.propagate = prop
        if file_handler is not None:
            file_handler.close()
