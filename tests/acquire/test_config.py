"""Bad configurations give one clear error line before anything moves; --dry-run touches nothing."""

from __future__ import annotations

import json

import pytest

from sarcli.io.scan import read_scan
from tests.acquire.conftest import scan_args


def one_error(r, code=2):
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == code, r.stderr
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: "), r.stderr
    return lines[0]


def nothing_moved(emu):
    return not any(x.startswith(("G0", "G1", "$H")) for x in emu.grbl.log)


@pytest.mark.parametrize("flags, words", [
    (["--start", "7GHz", "--stop", "7.2GHz"], "outside the 8753ES range"),
    (["--start", "10kHz"], "outside the 8753ES range"),
    (["--start", "5.5GHz", "--stop", "5.4GHz"], "start >= stop"),
    (["--points", "300"], "points = 300 is not allowed"),
    (["--ifbw", "500"], "IF bandwidth 500 Hz is not allowed"),
    (["--power", "20"], "power 20 dBm"),
    (["--count", "100"], "beyond the limits"),
    (["--rail-start", "-0.6"], "beyond the limits"),
    (["--pol", "VV,XX"], "polarizations"),
    (["--pol", "VV,HH", "--switch", "none"], "need a switch"),
    (["--start", "five"], "cannot read frequency"),
    (["--data-format", "FORM9"], "data_format"),
])
def test_bad_settings_refused_before_connecting(cli, emulator, config_path, tmp_path, flags, words):
    emu = emulator()
    r = cli(*scan_args(emu, config_path, "-o", tmp_path / "x.h5", *flags))
    assert words in one_error(r)
    assert emu.grbl.log == [] and emu.vna.log == []  # the ports were not even opened
    assert not (tmp_path / "x.h5").exists()


def test_wrong_port(cli, emulator, config_path, tmp_path):
    emu = emulator()
    r = cli("gbsar", "scan", "--port", "/dev/does-not-exist", "--rail-port", emu.rail_port, "-c", config_path,
            "-o", tmp_path / "x.h5")
    assert "cannot open the VNA port /dev/does-not-exist" in one_error(r, 3)
    assert nothing_moved(emu) and not (tmp_path / "x.h5").exists()


def test_swapped_ports_are_identified(cli, emulator, config_path, tmp_path):
    emu = emulator()
    r = cli("gbsar", "scan", "--port", emu.rail_port, "--rail-port", emu.vna_port, "-c", config_path,
            "-o", tmp_path / "x.h5")
    assert "expected a Prologix GPIB-USB controller" in one_error(r, 3)
    assert nothing_moved(emu) and not (tmp_path / "x.h5").exists()


def test_vna_model_mismatch(cli, emulator, config_path, tmp_path):
    config_path.write_text(config_path.read_text().replace('[vna]\n', '[vna]\nmodel = "8720ES"\n'))
    emu = emulator()
    r = cli(*scan_args(emu, config_path, "-o", tmp_path / "x.h5"))
    assert "identifies as 'HEWLETT PACKARD,8753ES" in one_error(r, 3)
    assert nothing_moved(emu)


def test_travel_beyond_grbl_max_travel(cli, emulator, config_path, tmp_path):
    emu = emulator(grbl_settings={130: 500.0})  # the rail is 0.5 m long; the plan needs 1 m
    r = cli(*scan_args(emu, config_path, "-o", tmp_path / "x.h5"))
    assert "beyond the limits 0..0.5 m" in one_error(r)
    assert nothing_moved(emu) and not (tmp_path / "x.h5").exists()


def test_unknown_key_and_section(cli, config_path, tmp_path):
    config_path.write_text(config_path.read_text() + "\n[vna2]\nx = 1\n")
    line = one_error(cli("gbsar", "scan", "-c", config_path, "--dry-run"))
    assert f"{config_path}: unknown option(s) vna2; known: antenna, polarization, rail, site, vna" in line
    config_path.write_text("[vna]\npoints_typo = 3\n")
    line = one_error(cli("gbsar", "scan", "-c", config_path, "--dry-run"))
    assert f"{config_path} [vna]: unknown option(s) points_typo; known: " in line
    config_path.write_text("[rail]\ncount = 2.5\n")
    line = one_error(cli("gbsar", "scan", "-c", config_path, "--dry-run"))
    assert f"{config_path} [rail].count: expected an integer, got 2.5" in line
    config_path.write_text("[vna\n")
    assert "not valid TOML" in one_error(cli("gbsar", "scan", "-c", config_path, "--dry-run"))


def test_output_exists_and_resume_mismatch(cli, emulator, config_path, tmp_path):
    emu = emulator(faults="vna-unplug@5")
    out = tmp_path / "s.h5"
    r = cli(*scan_args(emu, config_path, "-o", out))
    assert r.exit_code == 3 and read_scan(out).n_stops == 2
    emu2 = emulator()
    assert "exists; continue it with --resume" in one_error(cli(*scan_args(emu2, config_path, "-o", out)))
    msg = one_error(cli(*scan_args(emu2, config_path, "--resume", out, "--points", "401")))
    assert "cannot resume" in msg and "points" in msg
    msg = one_error(cli(*scan_args(emu2, config_path, "--resume", out, "--step", "0.04")))
    assert "rail_step_m" in msg
    assert nothing_moved(emu2)
    assert read_scan(out).n_stops == 2  # untouched


def test_dry_run_estimate(cli, config_path):
    r = cli("gbsar", "scan", "-c", config_path, "--dry-run", "--json")
    assert r.exit_code == 0, r.stderr
    plan = json.loads(r.stdout)
    # independent arithmetic: sweep = N (1/IFBW + 0.6 ms); FORM2 moves 8 B/point at 50 kB/s;
    # a 50 mm step at 500 mm/min and 10 mm/s^2 is a trapezoid: d/v + v/a
    sweep = 201 * (1 / 1000 + 6e-4)
    transfer = 201 * 8 / 50e3
    move = 50 / (500 / 60) + (500 / 60) / 10
    assert plan["sweep_s"] == pytest.approx(sweep) and plan["move_s"] == pytest.approx(move)
    assert plan["duration_s"] == pytest.approx(21 * (2 * (sweep + transfer) + move))
    assert plan["rail_m"] == [-0.5, 0.5] and plan["n_sweeps"] == 42
