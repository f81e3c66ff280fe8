"""Who made a product and how: passed by the caller of a workflow, never read from ``sys.argv``.

A workflow's ``run(config, provenance)`` enters :func:`using` for its duration; the product writers
(:func:`sarcli.io.h5common.atomic_h5`) read :func:`current`. A context variable keeps concurrent
runs in one process (threads, Dask tasks) apart.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator
from dataclasses import dataclass


@dataclass(frozen=True)
class Provenance:
    """command_line: what the user ran (``sarcli focus raw.h5 -o slc.h5``), or a description of the
    caller (``python: sarcli.workflows.focus.run``, ``dask batch task 17``)."""

    command_line: str = "python API"


_CURRENT: contextvars.ContextVar[Provenance] = contextvars.ContextVar("sarcli_provenance", default=Provenance())  # noqa: B039 (frozen)


def current() -> Provenance:
    """The provenance of the workflow running in this context."""
    return _CURRENT.get()


@contextlib.contextmanager
def using(provenance: Provenance | None) -> Iterator[Provenance]:
    """Make ``provenance`` current inside the block (``None`` keeps the current one)."""
    if provenance is None:
        yield current()
        return
    token = _CURRENT.set(provenance)
    try:
        yield provenance
    finally:
        _CURRENT.reset(token)
