"""Run tasks on a Dask client or here, through one interface, so a graph is written once.

``submit(fn, *args, label=...)`` returns a future; futures may be passed to later ``submit`` calls as
arguments (their results are handed to ``fn``: on a cluster the scheduler runs the task where and
when its inputs are ready); ``as_completed(futures)`` yields them as they finish. :class:`Here` runs
each task at once in this process (the same functions, the same results, no Dask imported);
:class:`OnCluster` submits to a ``distributed.Client``. An exception in a task is raised by
``result()``.
"""

from __future__ import annotations

import contextlib
import uuid
from collections.abc import Callable, Iterable, Iterator
from typing import Any


class _Done:
    """A task that already ran here."""

    def __init__(self, value: Any):
        self.value = value

    def result(self) -> Any:
        return self.value

    def release(self) -> None:
        self.value = None


class Here:
    """Every task runs when submitted, in this process, one after the other."""

    def submit(self, fn: Callable[..., Any], *args: Any, label: str = "task") -> _Done:
        return _Done(fn(*(a.result() if isinstance(a, _Done) else a for a in args)))

    def as_completed(self, futures: Iterable[_Done]) -> Iterator[_Done]:
        yield from futures


class OnCluster:
    """Tasks on a Dask cluster (``client``: a ``distributed.Client``); ``label`` groups them in Dask's reports."""

    def __init__(self, client: Any):
        self.client = client

    def submit(self, fn: Callable[..., Any], *args: Any, label: str = "task") -> Any:
        return self.client.submit(fn, *args, pure=False, key=f"{label}-{uuid.uuid4().hex}")

    def as_completed(self, futures: Iterable[Any]) -> Iterator[Any]:
        from distributed import as_completed

        return iter(as_completed(list(futures), loop=self.client.loop))


@contextlib.contextmanager
def executor(spec: Any) -> Iterator[Here | OnCluster]:
    """:class:`Here` for ``spec`` None, else :class:`OnCluster` on a client for the
    :class:`~sarcli.parallel.cluster.ClusterSpec` (closed on exit)."""
    if spec is None:
        yield Here()
        return
    from sarcli.parallel.cluster import connect

    with connect(spec) as client:
        yield OnCluster(client)
