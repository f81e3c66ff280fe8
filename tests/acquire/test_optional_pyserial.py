"""pyserial is the ``acquire`` extra: without it the acquisition commands that talk to instruments
refuse in one line naming the install command (nothing created), while planning (--dry-run), the
emulator and all processing work."""

from __future__ import annotations

import subprocess
import sys

import pytest

import sarcli.acquire.port as port_module
from tests.acquire.conftest import scan_args


@pytest.fixture
def no_pyserial(monkeypatch):
    monkeypatch.setattr(port_module, "serial", None)


def _one_line(r, code: int) -> str:
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == code and len(lines) == 1 and lines[0].startswith("sarcli: error: "), r.stderr
    return lines[0]


def test_scan_and_repeat_need_pyserial(cli, emulator, config_path, tmp_path, no_pyserial):
    emu = emulator()
    out = tmp_path / "s.h5"
    line = _one_line(cli(*scan_args(emu, config_path, "-o", out)), 2)
    assert "pip install 'sarcli[acquire]'" in line and not out.exists()
    assert emu.vna.log == [] and emu.grbl.log == []
    r = cli("gbsar", "repeat", "--every", "0", "--count", "1", "--port", emu.vna_port, "--rail-port",
            emu.rail_port, "-c", config_path, "-o", str(tmp_path / "r_{index}.h5"))
    assert "pip install 'sarcli[acquire]'" in _one_line(r, 2) and not list(tmp_path.glob("r_*"))


def test_dry_run_needs_no_pyserial(cli, config_path, no_pyserial):
    r = cli("gbsar", "scan", "-c", config_path, "--dry-run", "--json")
    assert r.exit_code == 0, r.stderr


def test_processing_and_the_emulator_import_without_pyserial():
    """A fresh interpreter where ``import serial`` fails: the CLI, the processing workflows and the
    emulator import (the emulator speaks through os.openpty, not pyserial)."""
    code = ("import sys; sys.modules['serial'] = None\n"
            "import sarcli.cli.app, sarcli.workflows.gbsar_focus, sarcli.workflows.gbsar_emulate\n"
            "import sarcli.workflows.gbsar_scan, sarcli.workflows.gbsar_repeat\n"
            "import sarcli.acquire.port as p; assert p.serial is None\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
