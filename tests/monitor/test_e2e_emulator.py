"""End to end against the emulated instruments (pty, ``--time-scale 0``): the real ``sarcli gbsar
monitor`` process on the landslide sample, compared with the emulator's truth file; the offline
rebuild; a campaign killed mid-scan and mid-update, restarted, equal to an uninterrupted one.

Bars (docs/monitoring.md, "Measured"): cumulative displacement at the watch points within 0.3 mm + 5 % of the truth;
stable points within 0.3 mm RMS after APS and visibly worse without (ratio >= 3 here); each alarm level of the
slide raised within one scan of the truth crossing its threshold (truth level: the highest level its
true velocity or acceleration reaches), never on the stable areas; the inverse-velocity failure time
within 10 % of the acceleration phase (t_f - t_a) once three quarters of the phase is seen.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sarcli.acquire.emulator import Emulator, scene_source
from sarcli.gbsar.scene import MotionLaw
from sarcli.monitor.config import LEVELS
from sarcli.workflows import gbsar_series
from tests.monitor.conftest import LANDSLIDE, MONITOR, snapshot

SARCLI = os.path.join(os.path.dirname(sys.executable), "sarcli")
START = "2026-05-01T06:00:00Z"
SLIDE = MotionLaw("failure", 0.3, 1.0, 7.05)  # samples/gbsar_landslide.toml, zone "slide"
KEYS = ("scan", "time_utc", "n_points", "aps_residual_mm", "max_velocity_mm_per_h", "alarm_level", "displacement_mm")


def start_emulator(truth: Path | None = None, on_sweep=None) -> Emulator:
    src = scene_source(str(LANDSLIDE), 2.0, 600.0, None if truth is None else str(truth))
    return Emulator(src, time_scale=0.0, machine_zero_m=-0.5, grbl_settings={130: 1500.0}, on_sweep=on_sweep).start()


def monitor(emu: Emulator, out: Path, count: int, config: Path = MONITOR, hook: str | None = None
            ) -> subprocess.Popen:
    cmd = [SARCLI, "gbsar", "monitor", "--port", emu.vna_port, "--rail-port", emu.rail_port, "-c", str(config),
           "--every", "10m", "--time-scale", "0", "--start-utc", START, "--count", str(count), "--out", str(out),
           "--json"]
    if hook:
        cmd += ["--on-alarm", hook]
    # its own session: a kill reaches the hook it may be running too
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


def finish(p: subprocess.Popen, timeout: float = 300) -> list[dict]:
    out, err = p.communicate(timeout=timeout)
    assert p.returncode == 0, err[-3000:]
    return [json.loads(line) for line in out.splitlines()]


def truth_level(t_h: float, area) -> int:
    v = SLIDE.velocity_mm_per_h_at(t_h)
    h = 1e-4
    a = (SLIDE.velocity_mm_per_h_at(t_h + h) - SLIDE.velocity_mm_per_h_at(t_h - h)) / (2 * h)
    return max(sum(v >= x for x in area["v"]), sum(a >= x for x in area["a"]))


@pytest.mark.slow  # 43 scans through the pty instruments: ~12 s of CPU, 20-40 s on a loaded machine
def test_landslide_campaign_meets_the_bars(tmp_path):
    truth_file, out = tmp_path / "truth.jsonl", tmp_path / "campaign"
    emu = start_emulator(truth_file)
    try:
        recs = finish(monitor(emu, out, 43))
    finally:
        emu.stop()
    truth = [json.loads(x) for x in truth_file.read_text().splitlines()]
    assert len(recs) == len(truth) == 43 and all(r["status"] == "accepted" for r in recs)
    assert all(set(KEYS) <= set(r) for r in recs)
    # displacement at the watch points (the corner reflectors: same names in the scene)
    worst = 0.0
    for r, t in zip(recs, truth, strict=True):
        assert r["time_utc"] == t["time_utc"]
        for name, got in r["displacement_mm"].items():
            want = t["groups"][name]["los_displacement_mm"]
            worst = max(worst, abs(got - want) / (0.3 + 0.05 * abs(want)))
    assert worst <= 1.0, f"watch-point error {worst:.2f} of the allowed 0.3 mm + 5 %"
    # stable points after APS, and without
    res = [r["aps_residual_mm"] for r in recs[1:]]
    raw = [r["raw_stable_rms_mm"] for r in recs[10:]]
    assert max(res) <= 0.3 and sum(raw) / len(raw) >= 3 * sum(res[9:]) / len(res[9:])
    # alarms: within one scan of the truth crossing, never on the stable areas
    area = {"v": (2.0, 4.0, 8.0), "a": (4.0, 16.0, 64.0)}  # samples/monitor.toml, area "slide"
    t_h = [r["time_h"] for r in recs]
    got = [LEVELS.index(r["areas"]["slide"]["level"]) for r in recs]
    want = [truth_level(t, area) for t in t_h]
    for level in (1, 2, 3):
        k_want = next(k for k, w in enumerate(want) if w >= level)
        k_got = next(k for k, g in enumerate(got) if g >= level)
        assert abs(k_got - k_want) <= 1, (level, k_got + 1, k_want + 1)
    assert all(r["areas"][a]["level"] == "none" for r in recs for a in ("stable-low", "stable-high"))
    # the inverse-velocity forecast once three quarters of the acceleration phase is seen
    ta, tf = SLIDE.onset_h, SLIDE.failure_h
    late = [r for r in recs if r["time_h"] >= ta + 0.75 * (tf - ta)]
    assert len(late) >= 5
    for r in late:
        fc = r["areas"]["slide"]["forecast"]
        assert fc is not None and abs(fc["failure_h"] - tf) <= 0.1 * (tf - ta), (r["scan"], fc)
    # the offline rebuild gives the same store
    gbsar_series.run(gbsar_series.Config(inputs=(out,), out=tmp_path / "rebuilt", jobs=2))
    assert snapshot(tmp_path / "rebuilt") == snapshot(out)
    assert 'id="latest-scan">43<' in (out / "index.html").read_text()
    # docs/monitoring.md's offline form (the scans by a glob, with the configuration) and its alarms.csv line
    from tests.conftest import REPO, run_cli

    r = run_cli("gbsar", "series", *sorted((out / "scans").glob("*.h5")), "-c", MONITOR, "--out",
                tmp_path / "offline", "--jobs", "2")
    assert r.exit_code == 0, r.stderr
    alarms = (out / "alarms.csv").read_text()
    assert (tmp_path / "offline" / "alarms.csv").read_text() == alarms
    assert alarms.splitlines()[1] in (REPO / "docs" / "monitoring.md").read_text()


def _kill_config(tmp_path: Path) -> Path:
    """The sample with thresholds low enough for the slide and the creep to raise an alarm at scan 3."""
    text = MONITOR.read_text().replace("velocity_mm_per_h = [2.0, 4.0, 8.0]", "velocity_mm_per_h = [0.15, 5.0, 9.0]")
    p = tmp_path / "monitor.toml"
    p.write_text(text)
    return p


@pytest.mark.slow  # three campaigns of 8 scans through the pty instruments, and restarts
def test_killed_mid_scan_and_mid_update_then_restarted(tmp_path):
    cfg = _kill_config(tmp_path)
    n = 8
    # the uninterrupted campaign
    emu = start_emulator()
    try:
        finish(monitor(emu, tmp_path / "ref", n, cfg, hook="true"))
    finally:
        emu.stop()
    ref = snapshot(tmp_path / "ref")
    assert "raised" in ref["alarms"]
    # killed in the middle of scan 5 (its 11th sweep), then restarted
    holder: list[subprocess.Popen] = []

    def kill_at(sweep: int) -> None:
        if sweep == 4 * 21 + 11 and holder:
            os.killpg(holder[0].pid, signal.SIGKILL)

    emu = start_emulator(on_sweep=kill_at)
    out = tmp_path / "mid_scan"
    try:
        p = monitor(emu, out, n, cfg)
        holder.append(p)
        p.communicate(timeout=300)
        assert p.returncode == -signal.SIGKILL
        holder.clear()
        assert (out / "scans" / "scan_00005.h5").exists()
        finish(monitor(emu, out, n, cfg))
    finally:
        emu.stop()
    assert snapshot(out) == ref
    # killed while the alarm hook of scan 3 runs: its epoch file and alarm lines are written, the state not
    emu = start_emulator()
    out, marker = tmp_path / "mid_update", tmp_path / "hook-started"
    try:
        p = monitor(emu, out, n, cfg, hook=f"touch {marker}; sleep 60")
        deadline = time.monotonic() + 300
        while not marker.exists() and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert marker.exists()
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate(timeout=60)
        assert (out / "store" / "epochs" / "scan_00003.h5").exists()
        assert "raised" in (out / "alarms.csv").read_text()  # written past the last commit
        recs = finish(monitor(emu, out, n, cfg, hook="true"))
    finally:
        emu.stop()
    assert [r["scan"] for r in recs] == list(range(3, n + 1))  # it picked up where it stopped
    assert snapshot(out) == ref
