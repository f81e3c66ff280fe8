"""--device: parsing, the environment default, one-line refusals, and no GPU import on the CPU path."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from sarcli.errors import ConfigError
from sarcli.focus.bp_product import BpOptions
from sarcli.focus.rda import RdOptions
from sarcli.gpu.device import default_device, options_with_device, parse_device, require_cuda

REPO = Path(__file__).resolve().parents[2]


def _no_gpu(monkeypatch):
    """This process as on a machine without CuPy: the simulator off, ``import cupy`` failing."""
    monkeypatch.delenv("NUMBA_ENABLE_CUDASIM", raising=False)
    monkeypatch.setitem(sys.modules, "cupy", None)  # a None entry makes the import raise ImportError


@pytest.mark.parametrize("text,expected", [("cpu", "cpu"), (" CUDA ", "cuda"), ("Cpu", "cpu")])
def test_parse_device(text, expected):
    assert parse_device(text) == expected


def test_unknown_device_is_one_line():
    with pytest.raises(ConfigError, match="unknown device 'gpu0': use cpu or cuda"):
        parse_device("gpu0")


def test_default_comes_from_the_environment(monkeypatch):
    monkeypatch.delenv("SARCLI_DEVICE", raising=False)
    assert default_device() == "cpu"
    monkeypatch.setenv("SARCLI_DEVICE", "cuda")
    assert default_device() == "cuda"


def test_cuda_without_cupy_says_what_is_missing(monkeypatch):
    _no_gpu(monkeypatch)
    with pytest.raises(ConfigError, match=r"needs CuPy, which is not installed: install the GPU extra"):
        require_cuda()
    with pytest.raises(ConfigError, match="needs CuPy"):
        RdOptions(device="cuda")
    with pytest.raises(ConfigError, match="needs CuPy"):
        BpOptions(device="cuda")


def test_simulator_is_cuda_with_numpy(monkeypatch):
    import numpy as np

    monkeypatch.setenv("NUMBA_ENABLE_CUDASIM", "1")
    dev = require_cuda()
    assert dev.simulator and dev.xp is np
    assert RdOptions(device="CUDA").device == "cuda"


def test_focuser_without_a_device_option_refuses_cuda_only():
    from dataclasses import dataclass

    @dataclass(frozen=True)
    class NoDevice:
        x: int = 1

    assert options_with_device(NoDevice, {"x": 2}, "cpu") == {"x": 2}
    assert options_with_device(NoDevice, {"x": 2}, None) == {"x": 2}
    assert options_with_device(RdOptions, {}, "cuda") == {"device": "cuda"}
    with pytest.raises(ConfigError, match="this focuser has no CUDA path"):
        options_with_device(NoDevice, {}, "cuda")


def test_cli_device_cuda_without_a_gpu_is_exit_2_one_line(cli, tmp_path, monkeypatch):
    _no_gpu(monkeypatch)
    raw = tmp_path / "raw.h5"
    assert cli("simulate", REPO / "samples" / "rs1_point.toml", "-o", raw).exit_code == 0
    r = cli("focus", raw, "-o", tmp_path / "slc.h5", "--device", "cuda")
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sarcli: error:") and "CuPy" in lines[0]
    assert not (tmp_path / "slc.h5").exists()
    monkeypatch.setenv("SARCLI_DEVICE", "tpu")
    r = cli("focus", raw, "-o", tmp_path / "slc.h5")
    assert r.exit_code == 2 and "--device must be cpu or cuda" in r.stderr
    r = cli("gbsar", "focus", raw, "-o", tmp_path / "img.h5", "--device", "cuda")
    assert r.exit_code == 2 and r.stderr.count("\n") == 1


def test_cpu_focus_imports_no_gpu_package(tmp_path):
    """The CPU path of focus never imports CuPy, numba.cuda or the GPU kernels (subprocess: a clean import state;
    sarcli.gpu.device, which imports neither, parses the option)."""
    code = (
        "import sys, json\n"
        "from sarcli.cli.app import app\n"
        f"raw, slc = {str(tmp_path / 'raw.h5')!r}, {str(tmp_path / 'slc.h5')!r}\n"
        "for args in (['simulate', 'samples/rs1_point.toml', '-o', raw],\n"
        "             ['focus', raw, '-o', slc, '--device', 'cpu']):\n"
        "    try:\n"
        "        app(args)\n"
        "    except SystemExit as e:\n"
        "        assert not e.code, e.code\n"
        "gpu = ('cupy', 'numba.cuda', 'sarcli.gpu.bp_cuda', 'sarcli.gpu.rd_xp')\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.startswith(gpu))))\n")
    env = {**os.environ, "PYTHONPATH": str(REPO), "SARCLI_NO_PROGRESS": "1"}
    env.pop("NUMBA_ENABLE_CUDASIM", None)
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == []
