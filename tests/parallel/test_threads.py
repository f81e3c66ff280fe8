"""The thread budget: every usable core by default, a task's share inside ``limited``, per thread of control;
scipy's ``workers`` convention counted from the budget; numba's thread count follows and is restored."""

from __future__ import annotations

import os
import threading

import numba
import pytest

from sarcli.threads import budget, fft_workers, limited, one_thread_each, usable_cores


def test_default_budget_is_every_usable_core():
    assert budget() == usable_cores() == len(os.sched_getaffinity(0))


def test_limited_sets_budget_and_numba_threads_and_restores_them():
    before = numba.get_num_threads()
    with limited(1):
        assert budget() == 1
        assert numba.get_num_threads() == 1
        assert fft_workers(-1) == 1 and fft_workers(-2) == 1 and fft_workers(3) == 3
    assert budget() == usable_cores()
    assert numba.get_num_threads() == before


def test_fft_workers_counts_negative_values_from_the_budget_like_scipy():
    n = usable_cores()
    assert fft_workers(-1) == n  # scipy: -1 = os.cpu_count()
    assert fft_workers(-2) == max(1, n - 1)
    with pytest.raises(ValueError):
        fft_workers(0)


def test_a_limit_belongs_to_its_thread():
    seen = {}

    def other():
        seen["budget"], seen["numba"] = budget(), numba.get_num_threads()

    with limited(1):
        t = threading.Thread(target=other)
        t.start()
        t.join()
    assert seen == {"budget": usable_cores(), "numba": min(usable_cores(), numba.config.NUMBA_NUM_THREADS)}


def test_a_budget_below_one_is_refused():
    with pytest.raises(ValueError):
        with limited(0):
            pass


def test_the_package_sets_a_per_user_numba_cache(tmp_path):
    """sarcli/__init__ sets NUMBA_CACHE_DIR when unset ($XDG_CACHE_HOME/sarcli/numba), keeps a given one."""
    import subprocess
    import sys

    code = "import sarcli, os; print(os.environ['NUMBA_CACHE_DIR'])"
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == str(tmp_path / "sarcli" / "numba")
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == str(tmp_path / "mine")


def test_one_thread_each_runs_the_jobs_side_by_side_in_order_with_a_budget_of_one():
    seen = []

    def job(k):
        seen.append(threading.current_thread().name)
        return k * k, budget(), numba.get_num_threads()

    with limited(3):  # a pool of 3 threads even on a smaller machine
        out = one_thread_each(job, list(range(7)))
    assert [o[0] for o in out] == [k * k for k in range(7)]  # in the jobs' order
    assert all(o[1] == 1 and o[2] == 1 for o in out)  # each job under limited(1)
    assert all(name != threading.main_thread().name for name in seen)
    with limited(1):  # a budget of one: in this thread, serially
        seen.clear()
        assert [o[0] for o in one_thread_each(job, [2, 3])] == [4, 9]
        assert seen == [threading.current_thread().name] * 2
