"""The campaign store: the sign of the displacement against the simulator, crash safety of the commit
(a crash before the state's rename leaves the previous state, recovery removes what was written past
it), the rebuild's equality, and a state whose size does not grow with the number of scans."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from sarcli.monitor import store as store_mod
from sarcli.monitor.campaign import Campaign
from sarcli.monitor.config import load_monitor_config
from sarcli.monitor.store import Store
from tests.monitor.conftest import MONITOR, simulate_scans, snapshot


def test_displacement_sign_and_scale_against_the_simulator(offline_campaign):
    """d = -lam/(4 pi) (phi_k - phi_1): a target moving *away* (range growing) reads positive, in mm."""
    truth = json.loads((offline_campaign / "truth.json").read_text())
    rec, maps = Store(offline_campaign).read_epoch(12)
    for name in ("CR-creep", "CR-slide", "CR-low"):
        want = truth[11]["groups"][name]["los_displacement_mm"]
        assert rec["displacement_mm"][name] == pytest.approx(want, abs=0.3 + 0.05 * abs(want))
    assert truth[11]["groups"]["CR-slide"]["los_displacement_mm"] > 0.5  # it did move away, by > 0.5 mm


def test_rebuild_gives_the_same_store(offline_campaign, tmp_path):
    from sarcli.workflows import gbsar_series

    scans = tuple(sorted((offline_campaign / "scans").glob("scan_*.h5")))
    gbsar_series.run(gbsar_series.Config(inputs=scans, config=MONITOR, out=tmp_path, jobs=2, checkpoint_every=5))
    assert snapshot(tmp_path) == snapshot(offline_campaign)


def test_crash_before_the_commit_leaves_the_previous_state(offline_campaign, tmp_path, monkeypatch):
    root = tmp_path / "c"
    shutil.copytree(offline_campaign, root)
    before = snapshot(root)
    cfg = load_monitor_config(MONITOR)
    simulate_scans(root, 1, first=12)  # scan 13
    camp = Campaign(root, cfg)
    camp.open()

    def power_cut(*a, **k):
        raise KeyboardInterrupt  # the process dies between writing the epoch file and the state's rename

    monkeypatch.setattr(store_mod.os, "replace", _replace_but_not_state(power_cut))
    with pytest.raises(KeyboardInterrupt):
        camp.process_file(13, root / "scans" / "scan_00013.h5")
    monkeypatch.undo()
    assert (root / "store" / "epochs" / "scan_00013.h5").exists()  # written past the commit
    assert any(p.name.endswith(".part") for p in (root / "store").iterdir())  # a half-written state
    again = Campaign(root, cfg)
    removed = again.open()
    assert "epochs/scan_00013.h5" in removed and snapshot(root) == before
    assert again.next_index == 13
    again.process_file(13, root / "scans" / "scan_00013.h5")
    assert again.state.last_scan == 13


def _replace_but_not_state(fail):
    real = store_mod.os.replace

    def replace(src, dst):
        if Path(dst).name == "state.h5":
            fail()
        return real(src, dst)
    return replace


def test_recovery_truncates_alarm_lines_past_the_commit(offline_campaign, tmp_path):
    root = tmp_path / "c"
    shutil.copytree(offline_campaign, root)
    before = snapshot(root)
    with open(root / "alarms.csv", "a") as fh:
        fh.write("2026-05-01T09:00:00Z,13,slide,raised,alarm,none,velocity,9,8,9,,\n")
    Campaign(root, load_monitor_config(MONITOR)).open()
    assert snapshot(root) == before


def test_state_size_does_not_grow_with_the_scans(offline_campaign, tmp_path):
    """The state after 6 and after 12 scans has the same maps (what makes an update's cost flat); the
    page's time series are bounded by CHART_CAPACITY (older points thinned)."""
    from sarcli.monitor.engine import CHART_CAPACITY, Chart
    from sarcli.workflows import gbsar_series

    scans = sorted((offline_campaign / "scans").glob("scan_*.h5"))
    gbsar_series.run(gbsar_series.Config(inputs=tuple(scans[:6]), config=MONITOR, out=tmp_path, jobs=1))
    six = snapshot(tmp_path)["state"][1]
    twelve = snapshot(offline_campaign)["state"][1]
    maps = [k for k in six if not k.startswith("chart")]
    assert {k: six[k][:2] for k in maps} == {k: twelve[k][:2] for k in maps}  # dtypes and shapes
    ch = Chart(["x"])
    for i in range(5000):
        ch.append(float(i), {"x": 2.0 * i})
    assert ch.t.size < CHART_CAPACITY and ch.t[0] == 0 and ch.t[-1] == 4999
    assert np.all(np.diff(ch.t) > 0) and np.array_equal(ch.series("x"), 2 * ch.t)
    assert np.all(np.diff(ch.t)[-CHART_CAPACITY // 4:] == 1)  # the recent scans kept whole


def test_series_refuses_bad_inputs(cli, tmp_path, offline_campaign):
    r = cli("gbsar", "series", str(tmp_path))
    assert r.exit_code == 2 and "scan_NNNNN.h5" in r.stderr
    r = cli("gbsar", "series", str(offline_campaign / "scans" / "scan_00001.h5"))
    assert r.exit_code == 2 and "--out" in r.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text('[[areas]]\nname = "a"\npolygon = [[0, 0], [1, 0]]\n')
    r = cli("gbsar", "series", str(offline_campaign / "scans" / "scan_00001.h5"), "-c", str(bad), "--out",
            str(tmp_path / "o"))
    assert r.exit_code == 2 and "at least 3 vertices" in r.stderr
    assert not np.any([p.name == "o" for p in tmp_path.iterdir()])
