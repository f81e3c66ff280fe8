"""Injected faults: the scan either recovers (bounded retries) or stops cleanly; every stop completed
before the fault is in the file, the file opens, and --resume finishes with a result identical to an
uninterrupted scan. Ctrl-C is sent to a real ``sarcli`` process."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from sarcli.acquire.emulator import Emulator, scene_source
from sarcli.io.scan import read_scan
from tests.acquire.conftest import CONFIG, HEIGHT_M, MACHINE_ZERO_M, SCENE, scan_args
from tests.conftest import run_cli


def assert_same_scan(a, b):
    """Identical measurement (times and provenance aside)."""
    assert a.status == b.status == "complete"
    assert a.polarizations == b.polarizations
    for name in ("s21", "frequency", "rail_position", "rail_height", "stop_flags"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """The uninterrupted reference scan (no faults)."""
    d = tmp_path_factory.mktemp("clean")
    (d / "scene.toml").write_text(SCENE)
    (d / "scan.toml").write_text(CONFIG)
    with Emulator(scene_source(str(d / "scene.toml"), HEIGHT_M), switch="grbl", machine_zero_m=MACHINE_ZERO_M,
                  grbl_settings={130: 1500.0}) as emu:
        r = run_cli(*scan_args(emu, d / "scan.toml", "-o", d / "clean.h5"))
    assert r.exit_code == 0, r.stderr
    return read_scan(d / "clean.h5")


# event counts: sweeps and OUTPDATA answers are 2 per stop (HH, VV); moves 1 per stop
RECOVERABLE = [("vna-timeout@5", "FORM2"), ("garble@6", "FORM2"), ("truncate@7", "FORM2"),
               ("slow-sweep@4:0.3", "FORM2"), ("grbl-error@3", "FORM2"), ("stall@4", "FORM2"),
               ("status-garble@9", "FORM2"), ("lost-ok@4", "FORM2"),
               ("garble@2,truncate@3,vna-timeout@4,grbl-error@2", "FORM2"),
               ("garble@6", "FORM4"), ("truncate@7", "FORM4"), ("vna-timeout@3", "FORM4")]


@pytest.mark.parametrize("faults, fmt", RECOVERABLE)
def test_recovers(cli, emulator, config_path, tmp_path, clean, faults, fmt):
    emu = emulator(faults=faults)
    out = tmp_path / "f.h5"
    r = cli(*scan_args(emu, config_path, "-o", out, "--json", "--data-format", fmt))
    assert r.exit_code == 0, r.stderr
    assert sorted(emu.faults.fired) == sorted(f.split(":")[0] for f in faults.split(","))
    summary = json.loads(r.stdout)
    if faults.startswith("slow-sweep"):  # not a retry: OPC? is polled with repeated ++read eoi
        log = emu.vna.log
        sings = [i for i, m in enumerate(log) if m == b"OPC?;SING;\n"]
        between = log[sings[3] + 1:sings[4]]
        assert summary["retries"] == 0 and between.count(b"++read eoi") >= 2
    else:
        assert summary["retries"] >= 1
    s = read_scan(out)
    if fmt == "FORM2":
        assert_same_scan(s, clean)
    else:  # FORM4 carries more digits than FORM2's float32: same to complex64 rounding
        np.testing.assert_allclose(s.s21, clean.s21, rtol=0, atol=1e-6)


@pytest.mark.parametrize("faults, kept, same_emulator", [
    ("vna-unplug@9", 4, False),   # 9th sweep = stop 5, first polarization
    ("rail-unplug@5", 4, False),  # 5th move = to stop 5
    ("alarm@6:1", 5, True),       # hard limit on the 6th move; reset + unlock on resume
    ("alarm@3:9", 2, True),
])
def test_stops_cleanly_then_resume_is_identical(cli, emulator, config_path, tmp_path, clean, faults, kept,
                                                same_emulator):
    emu = emulator(faults=faults)
    out = tmp_path / "f.h5"
    r = cli(*scan_args(emu, config_path, "-o", out))
    assert r.exit_code == 3
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sarcli: error:") and f"--resume {out}" in lines[0]
    part = read_scan(out)
    assert part.status == "interrupted" and part.n_stops == kept
    np.testing.assert_array_equal(part.s21, clean.s21[:, :kept])
    if "alarm" in faults:
        assert "ALARM" in lines[0]
    emu2 = emu if same_emulator else emulator()
    r = cli(*scan_args(emu2, config_path, "--resume", out, "--json"))
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["resumed_from"] == kept
    assert_same_scan(read_scan(out), clean)


def test_sweep_deadline(cli, emulator, config_path, tmp_path):
    """A sweep that never completes within its deadline (OPC? silent) ends the scan cleanly."""
    emu = emulator(faults="slow-sweep@3:60")
    out = tmp_path / "f.h5"
    # SWET = 201 * (1/IFBW + 0.6 ms); deadline = 1.5 SWET + 4 OPC polls of 0.1 + 0.08 s ~ 0.9 s at 6 kHz
    r = cli(*scan_args(emu, config_path, "-o", out, "--ifbw", "6000"))
    assert r.exit_code == 3 and "OPC? never answered" in r.stderr
    assert read_scan(out).n_stops == 1


def test_ctrl_c_keeps_completed_stops_and_resume_is_identical(emulator, cli, config_path, tmp_path, clean):
    proc: dict = {}

    def on_sweep(n: int) -> None:
        if n == 7 and "p" in proc:
            proc["p"].send_signal(signal.SIGINT)

    # time scale 0.02: a 5 cm move takes ~0.12 s and a sweep ~6 ms, so the scan is still running
    # when the signal lands at the 7th sweep (stop 4)
    emu = emulator(time_scale=0.02, on_sweep=on_sweep)
    out = tmp_path / "c.h5"
    env = {**os.environ, "SARCLI_NO_PROGRESS": "1"}
    sarcli = os.path.join(os.path.dirname(sys.executable), "sarcli")
    p = subprocess.Popen([sarcli, *scan_args(emu, config_path, "-o", str(out))],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True)
    proc["p"] = p
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert err.strip().count("\n") == 0 and "interrupted" in err and "--resume" in err
    part = read_scan(out)
    assert part.status == "interrupted" and 3 <= part.n_stops < 21
    np.testing.assert_array_equal(part.s21, clean.s21[:, :part.n_stops])
    r = cli(*scan_args(emulator(), config_path, "--resume", out))
    assert r.exit_code == 0, r.stderr
    assert_same_scan(read_scan(out), clean)
