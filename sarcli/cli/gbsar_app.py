"""The ``sarcli gbsar`` sub-app, shared by the processing and the acquisition command modules.

Each of them adds its commands to :data:`gbsar_app` and calls :func:`attach` from its ``register``;
the sub-app is added to the main app once.
"""

from __future__ import annotations

import typer

from sarcli.cli.common import make_typer

gbsar_app = make_typer(
    help="Ground-based SAR: simulate, plan, focus, interfere, coherence; acquire with a VNA and a rail.",
)

_ATTACHED: set[int] = set()


def attach(app: typer.Typer) -> None:
    """Add ``gbsar`` to ``app`` (idempotent)."""
    if id(app) not in _ATTACHED:
        app.add_typer(gbsar_app, name="gbsar")
        _ATTACHED.add(id(app))
