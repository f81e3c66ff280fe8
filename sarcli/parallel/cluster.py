"""Where the work runs: a Dask client on a local cluster or on a running scheduler; every task's thread budget.

- A :class:`ClusterSpec` says where: ``scheduler`` (an address ``tcp://host:8786``: workers started
  elsewhere with ``dask worker tcp://host:8786``) or a ``LocalCluster`` of ``workers`` processes with
  ``threads_per_worker`` threads each (default: one process per usable core, one thread each).
  :func:`cluster_spec` builds it from command-line options; ``SARCLI_SCHEDULER`` names the scheduler
  when ``--scheduler`` is not given (for ``sarcli batch``; explicit ``--workers`` wins over it).
- Thread budget: a host runs ``T`` Dask threads in all (the sum of its workers' threads, from the
  scheduler) and has ``C`` usable cores; each task may use ``max(1, C // T)`` threads for its numba
  kernels and FFTs (:func:`sarcli.threads.limited`). Today's single-process default -- scipy
  ``workers=-1`` and numba's parallel kernels, every core in every process -- would run W x C threads
  on C cores.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlparse

from sarcli.errors import ConfigError
from sarcli.threads import limited, usable_cores

log = logging.getLogger(__name__)

SCHEDULER_ENV = "SARCLI_SCHEDULER"
#: configuration fields that say where the work runs, not what it computes (products do not store them)
EXECUTION_FIELDS = ("workers", "threads_per_worker", "scheduler")
_ADDRESS = re.compile(r"^(tcp|tls)://[A-Za-z0-9_.\-\[\]:]+:\d+$")
#: seconds to wait for a scheduler that does not answer
CONNECT_TIMEOUT_S = 20


@dataclass(frozen=True)
class ClusterSpec:
    """scheduler: address of a running scheduler (``tcp://host:port``) or None for a LocalCluster of
    ``workers`` processes (None: usable cores // threads_per_worker) x ``threads_per_worker`` threads."""

    scheduler: str | None = None
    workers: int | None = None
    threads_per_worker: int = 1

    def __post_init__(self) -> None:
        if self.scheduler is not None and not _ADDRESS.match(self.scheduler):
            raise ConfigError(f"--scheduler {self.scheduler!r} is not a Dask scheduler address (tcp://host:port, "
                              "e.g. tcp://10.0.0.5:8786)")
        if self.scheduler is not None and self.workers is not None:
            raise ConfigError("--workers sizes a local cluster: with --scheduler the workers are those started "
                              "for that scheduler (dask worker ADDRESS)")
        if self.workers is not None and self.workers < 1:
            raise ConfigError(f"--workers must be at least 1, got {self.workers}")
        if self.threads_per_worker < 1:
            raise ConfigError(f"--threads-per-worker must be at least 1, got {self.threads_per_worker}")

    def describe(self) -> str:
        if self.scheduler is not None:
            return f"scheduler {self.scheduler}"
        return f"local cluster of {self.n_local_workers()} process(es) x {self.threads_per_worker} thread(s)"

    def n_local_workers(self) -> int:
        return self.workers or max(1, usable_cores() // self.threads_per_worker)


def cluster_spec(scheduler: str | None, workers: int | None, threads_per_worker: int | None,
                 use_env: bool = True) -> ClusterSpec:
    """The cluster the options ask for: ``scheduler``, else ``$SARCLI_SCHEDULER`` (when ``use_env`` and
    no ``workers`` were given), else a LocalCluster."""
    env = os.environ.get(SCHEDULER_ENV, "").strip()
    if scheduler is None and workers is None and use_env and env:
        scheduler = env
    return ClusterSpec(scheduler=scheduler, workers=workers,
                       threads_per_worker=1 if threads_per_worker is None else threads_per_worker)


@contextlib.contextmanager
def connect(spec: ClusterSpec) -> Iterator[Any]:
    """A ``distributed.Client`` for ``spec``, closed (and a local cluster shut down) on exit."""
    from distributed import Client, LocalCluster

    if spec.scheduler is None:
        n = spec.n_local_workers()
        log.info("starting a local Dask cluster: %d process(es) x %d thread(s)", n, spec.threads_per_worker)
        with LocalCluster(n_workers=n, threads_per_worker=spec.threads_per_worker, processes=True,
                          dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
                Client(cluster, set_as_default=False) as client:
            yield client
        return
    try:
        client = Client(spec.scheduler, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError) as e:
        raise ConfigError(f"cannot reach the Dask scheduler at {spec.scheduler} ({e.__class__.__name__}): start "
                          "it with 'dask scheduler' and its workers with 'dask worker ADDRESS'") from None
    with client:
        if not host_threads(client):
            log.warning("the scheduler at %s has no workers yet: tasks wait for one", spec.scheduler)
        yield client


def host_threads(client: Any) -> dict[str, int]:
    """Dask threads per host (the sum over the workers on it), from the scheduler."""
    out: dict[str, int] = {}
    for addr, w in client.scheduler_info(n_workers=-1)["workers"].items():
        host = w.get("host") or urlparse(addr).hostname or addr
        out[host] = out.get(host, 0) + int(w.get("nthreads", 1))
    return out


def task_budget(threads_by_host: Mapping[str, int]) -> int | None:
    """The thread budget of a task running on this worker (module docstring); None outside a worker."""
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):
        return None
    host = urlparse(worker.address).hostname or ""
    total = threads_by_host.get(host) or worker.nthreads
    return max(1, usable_cores() // max(1, total))


@contextlib.contextmanager
def task_threads(threads_by_host: Mapping[str, int]) -> Iterator[int | None]:
    """Run the block within this task's thread budget (nothing changes outside a Dask worker)."""
    n = task_budget(threads_by_host)
    if n is None:
        yield None
        return
    with limited(n):
        yield n
