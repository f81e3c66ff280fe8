"""Acquisition messages people act on: the resume hint is a real, complete command; frequency limits
read in engineering units; the repeat example survives --help formatting."""

from __future__ import annotations

import json
import shlex

from sarcli.acquire.config import format_frequency

from .conftest import scan_args


def test_alarm_hint_is_the_full_resume_command(cli, emulator, config_path, tmp_path):
    emu = emulator(faults="alarm@3:9")
    out = tmp_path / "f.h5"
    r = cli(*scan_args(emu, config_path, "-o", out, "--ifbw", "3000"))
    assert r.exit_code == 3
    line = r.stderr.strip().splitlines()[-1]
    assert "..." not in line and "continue with: sarcli gbsar scan " in line
    cmd = shlex.split(line.split("continue with: ", 1)[1])
    assert cmd[:3] == ["sarcli", "gbsar", "scan"] and cmd[-2:] == ["--resume", str(out)]
    assert "-o" not in cmd and "--output" not in cmd and cmd[cmd.index("--ifbw") + 1] == "3000.0"
    # the printed command, run as printed, continues the scan to the end
    r = cli(*cmd[1:], "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["resumed_from"] == 2 and s["status"] == "complete"


def test_frequency_limits_in_engineering_units(cli, config_path):
    r = cli("gbsar", "scan", "-c", config_path, "--dry-run", "--start", "10kHz", "--stop", "7GHz")
    assert r.exit_code != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "10 kHz-7 GHz" in lines[0] and "30 kHz-6 GHz" in lines[0], lines
    assert [format_frequency(f) for f in (30e3, 6e9, 5.2e9, 150e6, 12.5)] == [
        "30 kHz", "6 GHz", "5.2 GHz", "150 MHz", "12.5 Hz"]


def test_repeat_help_example_is_not_mangled(cli):
    out = cli("gbsar", "repeat", "--help").stdout
    assert "\\       -c" not in out
    lines = out.splitlines()
    i = next(k for k, ln in enumerate(lines) if "sarcli gbsar repeat --every 30m" in ln)
    assert lines[i].rstrip().endswith("--rail-port /dev/ttyACM0 \\")
    assert lines[i + 1].strip() == "-c samples/scan.toml -o 'series/scan_{index:02d}_{utc}.h5'"
