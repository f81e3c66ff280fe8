"""The ``sarcli gbsar`` sub-app, shared by the processing and the acquisition command modules.

Each of them adds its commands to :data:`gbsar_app` and calls :func:`attach` from its ``register``;
the sub-app is added to the main app once. :func:`run_workflow` is how a command runs its workflow:
progress bars on a terminal, each warning as one ``sarcli: warning:`` line, the report printed.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Callable, Iterator
from types import ModuleType
from typing import Any

import typer

from sarcli.cli.common import emit_json, info, make_typer, progress_sink

gbsar_app = make_typer(
    help="Ground-based SAR: simulate, import, plan, focus, interfere, coherence; acquire with a VNA and a rail; "
         "monitor a slope.",
)

_ATTACHED: set[int] = set()


def attach(app: typer.Typer) -> None:
    """Add ``gbsar`` to ``app`` (idempotent)."""
    if id(app) not in _ATTACHED:
        app.add_typer(gbsar_app, name="gbsar")
        _ATTACHED.add(id(app))


@contextlib.contextmanager
def warning_lines() -> Iterator[None]:
    """Warnings raised inside the block reach the user as one line each (also when the block fails)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield
        finally:
            for w in caught:
                info(f"sarcli: warning: {w.message}")


def run_workflow(workflow: ModuleType, config: Any, json_out: bool, text: Callable[[str], None] = info,
                 **extra: Any) -> Any:
    """``workflow.run(config, **extra)`` with progress and warning lines; print its report (``--json``:
    the JSON document on stdout, even for a run that ended early, e.g. an interrupted acquisition;
    then its ``raise_for_status()`` if it has one; then its lines through ``text``) and return it."""
    with warning_lines(), progress_sink() as sink:
        report = workflow.run(config, progress=sink, **extra)
    if json_out:
        emit_json(report.to_dict())
    check = getattr(report, "raise_for_status", None)
    if check is not None:
        check()
    if not json_out:
        for line in report.lines():
            text(line)
    return report
