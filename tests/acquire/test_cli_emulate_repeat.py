"""``sarcli gbsar emulate`` as its own process (JSON port line, runs until interrupted) and
``sarcli gbsar repeat`` (each scan its own product)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from sarcli.gbsar.scene import load_scene
from sarcli.gbsar.simulate import simulate_stop
from sarcli.io.scan import read_scan
from tests.acquire.conftest import HEIGHT_M


@pytest.mark.slow  # a second Python process with the simulator: ~5-8 s on a loaded machine
def test_emulate_process_serves_a_scan(cli, scene_path, config_path, tmp_path):
    sarcli = os.path.join(os.path.dirname(sys.executable), "sarcli")
    p = subprocess.Popen([sarcli, "gbsar", "emulate", "--json", "--scene", str(scene_path), "--switch", "grbl",
                          "--time-scale", "0", "--machine-zero", "-0.5", "--max-travel-mm", "1500",
                          "--faults", "garble@2"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        ports = json.loads(p.stdout.readline())
        assert set(ports) == {"vna_port", "rail_port"}
        out = tmp_path / "e.h5"
        r = cli("gbsar", "scan", "--port", ports["vna_port"], "--rail-port", ports["rail_port"], "-c", config_path,
                "-o", out, "--count", "3")
        assert r.exit_code == 0, r.stderr
    finally:
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=20)
    assert p.returncode == 0 and "faults fired: garble@2" in err
    s = read_scan(out)
    sc = load_scene(scene_path)  # the emulator's height defaults to the scene's rail height
    ref = np.stack([simulate_stop(sc, x, HEIGHT_M, s.frequency, s.polarizations) for x in s.rail_position], 1)
    np.testing.assert_allclose(s.s21, ref, rtol=0, atol=2e-6 * np.abs(ref).max())


def test_repeat_writes_one_product_per_scan(cli, emulator, config_path, tmp_path):
    emu = emulator()
    pattern = str(tmp_path / "series" / "scan_{index:02d}.h5")
    r = cli("gbsar", "repeat", "--every", "0s", "--count", "2", "--port", emu.vna_port, "--rail-port",
            emu.rail_port, "-c", config_path, "-o", pattern, "--json")
    assert r.exit_code == 0, r.stderr
    summaries = json.loads(r.stdout)
    assert [s["status"] for s in summaries] == ["complete", "complete"]
    a, b = (read_scan(tmp_path / "series" / f"scan_{i:02d}.h5") for i in (1, 2))
    np.testing.assert_array_equal(a.s21, b.s21)  # a static scene: the two acquisitions agree exactly
    assert a.epoch_utc < b.epoch_utc


def test_repeat_keeps_going_after_a_failed_scan(cli, emulator, config_path, tmp_path):
    emu = emulator(faults="vna-unplug@3")  # the first scan loses the VNA; so do the next ones
    r = cli("gbsar", "repeat", "--every", "0", "--count", "2", "--port", emu.vna_port, "--rail-port",
            emu.rail_port, "-c", config_path, "-o", str(tmp_path / "s_{index}.h5"))
    assert r.exit_code != 0 and "2 of 2 scans did not complete" in r.stderr
    assert read_scan(tmp_path / "s_1.h5").n_stops == 1


def test_repeat_needs_a_varying_name(cli, config_path, tmp_path):
    r = cli("gbsar", "repeat", "--every", "30m", "--count", "9", "--port", "x", "--rail-port", "y", "-c",
            config_path, "-o", str(tmp_path / "same.h5"))
    assert r.exit_code == 2 and "{index}" in r.stderr
    r = cli("gbsar", "repeat", "--every", "half an hour", "--count", "9", "--port", "x", "--rail-port", "y",
            "-c", config_path, "-o", str(tmp_path / "s{index}.h5"))
    assert r.exit_code == 2 and "cannot read duration" in r.stderr
