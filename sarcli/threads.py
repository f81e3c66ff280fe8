"""The thread budget: how many threads one computation may use (a base module, usable from every layer).

Processing code that starts threads -- scipy.fft's ``workers``, the RD focuser's chunk pool, numba
``parallel=True`` kernels -- asks :func:`budget` (or :func:`fft_workers` for scipy's convention)
instead of taking every core. Outside :func:`limited` the budget is every core this process may run on
(its CPU affinity): a single ``sarcli`` command behaves as before. A Dask task runs inside
``limited(k)`` with its share of the worker's cores (``sarcli.parallel``), so that W workers x T
threads x k threads per task never exceeds the cores of the host: no oversubscription.

The limit is per thread of control (a context variable, and numba's own thread-local setting), so
tasks running side by side in one worker process each keep their own.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

_LIMIT: contextvars.ContextVar[int | None] = contextvars.ContextVar("sarcli_thread_budget", default=None)


def usable_cores() -> int:
    """Cores this process may run on (CPU affinity where the OS has it, else the core count)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def budget() -> int:
    """Threads the current computation may use (module docstring); at least 1."""
    n = _LIMIT.get()
    return usable_cores() if n is None else n


def fft_workers(workers: int) -> int:
    """scipy.fft's ``workers`` argument resolved against the budget: a negative value counts from the
    budget as scipy counts from the core count (-1: the whole budget, -2: all but one), a positive
    one is kept."""
    if workers >= 1:
        return workers
    if workers == 0:
        raise ValueError("workers must not be zero")
    return max(1, budget() + 1 + workers)


@contextlib.contextmanager
def limited(n: int) -> Iterator[int]:
    """Inside the block, in this thread: ``budget() == n`` and numba's parallel kernels launched from
    here use at most ``n`` threads (numba's setting is thread-local). Restored on exit."""
    if n < 1:
        raise ValueError(f"a thread budget must be at least 1, got {n}")
    token = _LIMIT.set(n)
    import numba

    before = numba.get_num_threads()
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    try:
        yield n
    finally:
        numba.set_num_threads(before)
        _LIMIT.reset(token)


def one_thread_each(fn: Callable[[Any], Any], jobs: Sequence[Any]) -> list[Any]:
    """``[fn(job) for job in jobs]``, the jobs side by side on the budget's threads, each under
    ``limited(1)`` (its FFTs and kernels single-threaded, so the single-threaded numpy arithmetic between
    them runs on every core too); in order. For jobs whose result does not depend on the thread count."""
    n = min(budget(), len(jobs))
    if n <= 1:
        return [fn(job) for job in jobs]
    from concurrent.futures import ThreadPoolExecutor

    def one(job: Any) -> Any:
        with limited(1):
            return fn(job)

    with ThreadPoolExecutor(n) as pool:
        return list(pool.map(one, jobs))
