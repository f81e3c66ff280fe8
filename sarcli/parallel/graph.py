"""A graph of named tasks run on a Dask cluster, or in this process one after the other.

A :class:`Task` is ``fn(*args)``, with the results of the tasks it depends on appended to ``args``.
:func:`run_tasks` submits the whole graph at once (``client.submit`` with the upstream futures as
arguments: the scheduler runs every task as soon as its inputs exist, anywhere) and returns an
:class:`Outcome` per task:

- ``done``: the task's value;
- ``failed``: a :class:`~sarcli.errors.SarcliError` (a bad input, a refused configuration: one line)
  is final and not retried -- it would fail again; any other exception (a crash, a lost file
  system, a worker running out of memory) is retried ``retries`` times (Dask's ``retries``), and a
  worker that dies mid-task has its tasks rerun elsewhere by the scheduler;
- ``skipped``: a task it depends on did not succeed; it never ran.

One failure never stops the other tasks. Progress: ``progress("tasks", done, total)`` as tasks finish.
The warnings a task raises are kept in its outcome (one line each), not printed by the worker.
Without a client the same tasks run in order in this process (same functions, same results).
"""

from __future__ import annotations

import logging
import threading
import time
import uuid
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from sarcli.errors import SarcliError
from sarcli.workflows.base import Progress, no_progress

Status = Literal["done", "failed", "skipped"]


@dataclass(frozen=True)
class Task:
    """``fn(*args, *results of deps)``; ``key`` unique in its graph; ``label``: the kind of task (Dask groups
    tasks by it in its reports: ``focus``, ``doppler``)."""

    key: str
    fn: Callable[..., Any]
    args: tuple = ()
    deps: tuple[str, ...] = ()
    label: str = ""


@dataclass
class Outcome:
    """What became of one task (module docstring). ``seconds``: its run time (last attempt)."""

    key: str
    status: Status
    value: Any = None
    error: str = ""
    seconds: float = 0.0
    worker: str = ""
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class _Result:
    """What a task returns to the graph: its value, or the one-line failure that must not be retried."""

    status: Status
    value: Any = None
    error: str = ""
    seconds: float = 0.0
    worker: str = ""
    warnings: tuple[str, ...] = ()

    def outcome(self, key: str) -> Outcome:
        return Outcome(key, self.status, self.value, self.error, self.seconds, self.worker, self.warnings)


def one_line(e: BaseException) -> str:
    """An exception as one line: sarcli's own messages as they are, others with their type."""
    msg = " ".join(str(e).split())
    if isinstance(e, SarcliError):
        return msg
    return f"{e.__class__.__name__}: {msg}" if msg else e.__class__.__name__


def _worker_address() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return ""


def _run(fn: Callable[..., Any], threads_by_host: Mapping[str, int], n_args: int, keys: tuple[str, ...],
         *args: Any) -> _Result:
    """Run one task: skipped when an upstream task did not succeed; a SarcliError becomes a failed
    result (final); other exceptions propagate (Dask retries them)."""
    from orbit.errors import OrbitError
    from sarcli.parallel.cluster import task_threads

    own, upstream = args[:n_args], args[n_args:]
    for key, up in zip(keys, upstream, strict=True):
        if up.status != "done":
            return _Result("skipped", error=f"{key} {up.status}")
    if _worker_address():
        _quiet_logging()
    t0 = time.perf_counter()
    _install_warning_sink()
    caught: list[warnings.WarningMessage] = []
    _sink.caught = caught
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always")
            try:
                with task_threads(threads_by_host):
                    value = fn(*own, *(up.value for up in upstream))
            except (SarcliError, OrbitError) as e:
                return _Result("failed", error=one_line(e), seconds=time.perf_counter() - t0,
                               worker=_worker_address(), warnings=_lines(caught))
    finally:
        _sink.caught = None
    return _Result("done", value, seconds=time.perf_counter() - t0, worker=_worker_address(), warnings=_lines(caught))


#: the warnings of the task running on this thread (None: not in a task)
_sink = threading.local()
_sink_lock = threading.Lock()


def _install_warning_sink() -> None:
    """Route each thread's warnings to its own task (``_sink.caught``). ``catch_warnings(record=True)`` swaps
    the process-wide ``warnings.showwarning``: tasks on two threads would restore each other's and lose or
    swap their warnings. This hook is installed once (again if someone replaced it since) and hands a
    warning raised outside any task to the function it replaced."""
    with _sink_lock:
        current = warnings.showwarning
        if getattr(current, "_sarcli_task_sink", False):
            return

        def show(message, category, filename, lineno, file=None, line=None):
            caught = getattr(_sink, "caught", None)
            if caught is None:
                current(message, category, filename, lineno, file, line)
            else:
                caught.append(warnings.WarningMessage(message, category, filename, lineno, file, line))

        show._sarcli_task_sink = True  # type: ignore[attr-defined]
        warnings.showwarning = show


def _quiet_logging() -> None:
    """On a worker, sarcli's log records go nowhere (Python's last-resort handler would print its warnings
    on the worker's stderr): what a person needs is in the task's outcome."""
    lg = logging.getLogger("sarcli")
    if not lg.handlers:
        lg.addHandler(logging.NullHandler())


def _lines(caught: list[warnings.WarningMessage]) -> tuple[str, ...]:
    return tuple(dict.fromkeys(" ".join(str(w.message).split()) for w in caught))


def _check(tasks: Sequence[Task]) -> None:
    seen: set[str] = set()
    for t in tasks:
        if t.key in seen:
            raise ValueError(f"task key {t.key!r} used twice")
        missing = [d for d in t.deps if d not in seen]
        if missing:
            raise ValueError(f"task {t.key!r} depends on {missing}, not earlier in the graph")
        seen.add(t.key)


def run_tasks(tasks: Sequence[Task], client: Any = None, progress: Progress | None = None,
              retries: int = 1) -> dict[str, Outcome]:
    """Run ``tasks`` (listed after the tasks they depend on); module docstring."""
    _check(tasks)
    progress = progress or no_progress
    if client is None:
        return _run_here(tasks, progress, retries)
    from distributed import as_completed

    from sarcli.parallel.cluster import host_threads

    threads = host_threads(client)
    futures: dict[str, Any] = {}
    for t in tasks:
        futures[t.key] = client.submit(_run, t.fn, threads, len(t.args), t.deps, *t.args,
                                       *(futures[d] for d in t.deps), key=f"{t.label or 'task'}-{uuid.uuid4().hex}",
                                       retries=retries,
                                       pure=False)
    done = 0
    try:
        for _ in as_completed(futures.values(), loop=client.loop):
            done += 1
            progress("tasks", done, len(tasks))
    except BaseException:
        client.cancel(list(futures.values()))
        raise
    out: dict[str, Outcome] = {}
    for t in tasks:
        f = futures[t.key]
        if f.status == "finished":
            out[t.key] = f.result().outcome(t.key)
            continue
        bad = [d for d in t.deps if out[d].status != "done"]
        if bad:
            out[t.key] = Outcome(t.key, "skipped", error=f"{bad[0]} {out[bad[0]].status}")
        else:
            out[t.key] = Outcome(t.key, "failed", error=one_line(f.exception()))
    return out


def _run_here(tasks: Sequence[Task], progress: Progress, retries: int) -> dict[str, Outcome]:
    results: dict[str, _Result] = {}
    for i, t in enumerate(tasks):
        for attempt in range(retries + 1):
            try:
                results[t.key] = _run(t.fn, {}, len(t.args), t.deps, *t.args, *(results[d] for d in t.deps))
                break
            except (KeyboardInterrupt, SystemExit):
                raise
            except Exception as e:  # noqa: BLE001 (the graph's contract: one task's failure is reported, not raised)
                if attempt == retries:
                    results[t.key] = _Result("failed", error=one_line(e))
        progress("tasks", i + 1, len(tasks))
    return {k: r.outcome(k) for k, r in results.items()}
