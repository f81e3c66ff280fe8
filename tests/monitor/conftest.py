"""Shared pieces of the monitoring tests: scans of the landslide sample simulated at 10-minute
intervals (offline, without the instruments) and a small campaign processed from them."""

from __future__ import annotations

import dataclasses
import datetime as dt
import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SAMPLES

LANDSLIDE = SAMPLES / "gbsar_landslide.toml"
MONITOR = SAMPLES / "monitor.toml"


def simulate_scans(folder: Path, n: int, scene_path: Path = LANDSLIDE, interval_s: float = 600.0,
                   first: int = 0) -> list[dict]:
    """Scans ``first .. first+n-1`` of the scene at ``interval_s`` (the emulator's clock) as
    ``folder/scans/scan_NNNNN.h5`` (complete, measured-like: truth removed); returns each scan's truth."""
    from sarcli.gbsar.scene import load_scene, scene_at, scene_truth
    from sarcli.gbsar.simulate import simulate
    from sarcli.io.scan import write_scan

    (folder / "scans").mkdir(parents=True, exist_ok=True)
    sc = load_scene(scene_path)
    epoch = dt.datetime.fromisoformat(sc.epoch_utc.replace("Z", "+00:00"))
    truths = []
    for j in range(first, first + n):
        s = scene_at(sc, interval_s * j, j)
        scan = simulate(s)
        when = (epoch + dt.timedelta(seconds=interval_s * j)).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
        scan = dataclasses.replace(scan, epoch_utc=when, stop_time=np.zeros(scan.n_stops), status="complete",
                                   truth=None)
        write_scan(folder / "scans" / f"scan_{j + 1:05d}.h5", scan)
        truths.append(scene_truth(s))
    return truths


@pytest.fixture(scope="session")
def offline_campaign(tmp_path_factory) -> Path:
    """12 scans of the landslide sample rebuilt by ``gbsar series`` into a campaign folder (store,
    alarms.csv, index.html); ``truth.json`` beside it."""
    from sarcli.workflows import gbsar_series

    root = tmp_path_factory.mktemp("offline")
    truths = simulate_scans(root, 12)
    (root / "truth.json").write_text(json.dumps(truths))
    scans = tuple(sorted((root / "scans").glob("scan_*.h5")))
    gbsar_series.run(gbsar_series.Config(inputs=scans, config=MONITOR, out=root, jobs=1))
    return root


def snapshot(root: Path) -> dict:
    """Everything the store holds, comparable with ==: each epoch's record and maps, the state's arrays
    and bookkeeping, alarms.csv (provenance attributes such as creation times are left out)."""
    import h5py

    from sarcli.monitor.store import Store

    st = Store(root)
    out: dict = {"alarms": st.alarms.read_text()}
    for p in sorted(st.epochs.glob("scan_*.h5")):
        with h5py.File(p, "r") as f:
            out[p.name] = (f.attrs["record"], {k: _canon(f[k][()]) for k in f})
    with h5py.File(st.state_path, "r") as f:
        out["state"] = (f.attrs["meta"], {k: _canon(f[k][()]) for k in f if isinstance(f[k], h5py.Dataset)},
                        {k: _canon(f["static"][k][()]) for k in f["static"]}, f["static"].attrs["meta"])
    return out


def _canon(a):
    """An array as bytes with every NaN the same (NaN != NaN would make equal stores differ)."""
    a = np.asarray(a)
    if a.dtype.kind in "fc":
        a = np.where(np.isnan(a), np.nan, a)
    return (a.dtype.str, a.shape, a.tobytes())
