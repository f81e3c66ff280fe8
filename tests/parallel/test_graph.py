"""The task graph: a one-line sarcli error fails its task once (no retry) and skips what depends on it; an
unexpected error is retried once; the other tasks run; warnings are kept; the same outcomes here and on
a Dask cluster (in-process, threads)."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from sarcli.errors import ProductError
from sarcli.parallel.graph import Task, run_tasks


def _count(path: Path) -> int:
    n = int(path.read_text()) + 1 if path.exists() else 1
    path.write_text(str(n))
    return n


def add(a, b, *up):
    return a + b + sum(up)


def bad_input(counter: Path, *up):
    _count(counter)
    raise ProductError("scene.h5: not a raw product")


def flaky(counter: Path, *up):
    if _count(counter) == 1:
        raise OSError("the file system went away")
    warnings.warn("second try worked", stacklevel=1)
    return 7


def always_crashes(counter: Path, *up):
    _count(counter)
    raise RuntimeError("boom")


def _graph(tmp: Path) -> list[Task]:
    return [Task("a", add, (1, 2)), Task("b", add, (10, 0), ("a",)),
            Task("bad", bad_input, (tmp / "bad",)), Task("after-bad", add, (0, 0), ("bad",)),
            Task("flaky", flaky, (tmp / "flaky",)), Task("after-flaky", add, (1, 0), ("flaky",)),
            Task("crash", always_crashes, (tmp / "crash",)), Task("after-crash", add, (0, 0), ("crash",))]


def _check(out, tmp: Path) -> None:
    assert out["a"].value == 3 and out["b"].value == 13  # upstream result appended to the arguments
    assert out["bad"].status == "failed" and out["bad"].error == "scene.h5: not a raw product"
    assert (tmp / "bad").read_text() == "1"  # not retried: it would fail again
    assert out["after-bad"].status == "skipped" and out["after-bad"].error == "bad failed"
    assert out["flaky"].status == "done" and out["flaky"].value == 7 and (tmp / "flaky").read_text() == "2"
    assert out["flaky"].warnings == ("second try worked",)
    assert out["after-flaky"].value == 8
    assert out["crash"].status == "failed" and out["crash"].error == "RuntimeError: boom"
    assert (tmp / "crash").read_text() == "2"  # one retry
    assert out["after-crash"].status == "skipped"


def test_graph_here(tmp_path):
    seen = []
    out = run_tasks(_graph(tmp_path), progress=lambda label, done, total: seen.append((label, done, total)))
    _check(out, tmp_path)
    assert seen[-1] == ("tasks", 8, 8)


def thread_budget(*up):
    import numba

    from sarcli.threads import budget

    return budget(), numba.get_num_threads()


def test_graph_on_a_dask_cluster(tmp_path):
    """Same outcomes; each task's thread budget is its share of the host: cores // (2 workers x 1 thread)."""
    from distributed import Client, LocalCluster

    from sarcli.threads import usable_cores

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
                      dashboard_address=None) as cluster, Client(cluster, set_as_default=False) as client:
        out = run_tasks([*_graph(tmp_path), Task("budget", thread_budget)], client)
    _check(out, tmp_path)
    share = max(1, usable_cores() // 2)
    assert out["budget"].value == (share, share)


def test_a_graph_in_the_wrong_order_is_refused():
    with pytest.raises(ValueError, match="not earlier"):
        run_tasks([Task("b", add, (1, 1), ("a",)), Task("a", add, (1, 1))])
