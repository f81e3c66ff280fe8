"""A real multi-process Dask cluster on 127.0.0.1: ``dask scheduler`` and two ``dask worker`` processes started
here (free ports, no dashboards), ``sarcli batch --scheduler`` on three small scenes; one worker is killed
(SIGKILL, by this test) while the batch runs: the batch still completes and every product equals the
serial batch's. The processes are always torn down (fixture finalizer)."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

#: longer than its synthetic aperture, so that the GeoTIFFs hold fully focused lines
SCENE = Path(__file__).parents[1] / "focus" / "scenes" / "batch_long.toml"
BIN = Path(sys.executable).parent


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_for_workers(address: str, n: int, timeout: float = 60.0) -> dict[str, str]:
    """{worker name: address} once ``n`` workers are connected."""
    from distributed import Client

    with Client(address, timeout=timeout, set_as_default=False) as client:
        client.wait_for_workers(n, timeout=timeout)
        return {w["name"]: a for a, w in client.scheduler_info(n_workers=-1)["workers"].items()}


@pytest.fixture
def cluster(tmp_path):
    """(scheduler address, [worker processes]); everything killed at the end, whatever happened."""
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, SARCLI_NO_PROGRESS="1")
    logs = tmp_path / "dask-logs"
    logs.mkdir()
    procs: list[subprocess.Popen] = []

    def start(name: str, args: list[str]) -> subprocess.Popen:
        p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=open(logs / f"{name}.log", "w"), env=env,
                             start_new_session=True)
        procs.append(p)
        return p

    try:
        start("scheduler", [str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                            "--no-dashboard"])
        workers = [start(f"worker{k}", [str(BIN / "dask"), "worker", address, "--host", "127.0.0.1", "--nthreads",
                                        "1", "--no-nanny", "--no-dashboard", "--name", f"w{k}"]) for k in range(2)]
        names = _wait_for_workers(address, 2)
        yield address, workers, names
    finally:
        for p in procs:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=30)


def _same_products(a: Path, b: Path, name: str) -> None:
    import rasterio

    with h5py.File(a / f"{name}.slc.h5") as fa, h5py.File(b / f"{name}.slc.h5") as fb:
        np.testing.assert_array_equal(fa["image"][()], fb["image"][()])
        np.testing.assert_array_equal(fa["azimuth_time"][()], fb["azimuth_time"][()])
    with h5py.File(a / f"{name}.doppler.h5") as fa, h5py.File(b / f"{name}.doppler.h5") as fb:
        def arrays(f):
            out = {}
            f.visititems(lambda k, v: out.__setitem__(k, v[()]) if isinstance(v, h5py.Dataset) else None)
            return out
        da, db = arrays(fa), arrays(fb)
        assert da.keys() == db.keys()
        for k in da:
            np.testing.assert_array_equal(da[k], db[k], err_msg=k)
    with rasterio.open(a / f"{name}.tif") as ra, rasterio.open(b / f"{name}.tif") as rb:
        np.testing.assert_array_equal(ra.read(), rb.read())
    assert (a / f"{name}.png").read_bytes() == (b / f"{name}.png").read_bytes()


@pytest.mark.slow
def test_batch_on_a_cluster_survives_a_killed_worker(cluster, tmp_path):
    from tests.conftest import run_cli

    address, workers, names = cluster
    inp = tmp_path / "in"
    inp.mkdir()
    assert run_cli("simulate", SCENE, "-o", inp / "a.h5").exit_code == 0
    shutil.copy(inp / "a.h5", inp / "b.h5")
    assert run_cli("simulate", SCENE, "--format", "ceos", "-o", inp / "c").exit_code == 0
    serial = tmp_path / "serial"
    assert run_cli("batch", inp, "-o", serial, "--workers", "0").exit_code == 0
    out = tmp_path / "out"
    env = dict(os.environ, SARCLI_NO_PROGRESS="1")
    t0 = time.monotonic()
    report = tmp_path / "dask-report.html"
    batch = subprocess.Popen([str(BIN / "sarcli"), "batch", str(inp), "-o", str(out), "--scheduler", address, "--json",
                              "--report", str(report)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=env)
    try:
        # kill a worker once the first product exists: the graph (7 tasks) is still running
        while not (out.is_dir() and any(p.suffix == ".h5" and not p.name.startswith(".") for p in out.iterdir())):
            assert batch.poll() is None, batch.stderr.read()
            assert time.monotonic() - t0 < 120, "no product after 120 s"
            time.sleep(0.05)
        workers[1].send_signal(signal.SIGKILL)
        workers[1].wait(timeout=30)
        stdout, stderr = batch.communicate(timeout=300)
    finally:
        if batch.poll() is None:
            batch.kill()
    assert batch.returncode == 0, stderr
    rep = json.loads(stdout)
    assert rep["counts"] == {"done": 7, "failed": 0, "skipped": 0, "up_to_date": 0}
    assert rep["where"] == f"scheduler {address}" and rep["performance_report"] == str(report)
    assert "Dask Performance Report" in report.read_text()
    done_by = {s["worker"] for n in "abc" for s in json.loads((out / f"{n}.json").read_text())["steps"]}
    assert names["w0"] in done_by and done_by <= set(names.values())  # the survivor finished the graph
    for n in "abc":
        _same_products(serial, out, n)
