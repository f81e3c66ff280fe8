"""The numba.cuda backprojection kernels under numba's CUDA simulator (no GPU needed), against the plain-numpy
references, within the float32 bound derived in sarcli.gpu.bp_cuda; and ``gbsar focus --device cuda`` end to
end. The simulator must be on before numba is imported, so these run in their own processes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def _env() -> dict[str, str]:
    return {**os.environ, "NUMBA_ENABLE_CUDASIM": "1", "PYTHONPATH": str(REPO), "SARCLI_NO_PROGRESS": "1"}


@pytest.fixture(scope="module")
def checks() -> dict:
    out = subprocess.run([sys.executable, str(REPO / "tests" / "gpu" / "sim_checks.py")], cwd=REPO, env=_env(),
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout)


@pytest.mark.parametrize("kernel", ["stripmap", "rail", "grid"])
def test_kernel_within_the_float32_bound(checks, kernel):
    r = checks[kernel]
    assert r["peak"] > 1.0  # the inputs produce a real signal, not zeros
    assert r["worst_ratio"] <= 1.0, r


def test_grid_kernel_counts_the_same_weights(checks):
    assert checks["grid"]["used_error"] < 1e-12


@pytest.mark.slow
def test_gbsar_focus_on_the_simulated_device_equals_the_cpu(tmp_path):
    """``sarcli gbsar focus --algorithm bp --grid ... --device cuda`` (simulator) vs ``--device cpu``: the same
    pixels within the kernel's float32 bound: (n + 6) eps32 of sum_i w_i |P_i| / sum_i w_i (the image is
    normalised by the weights), which is at most the largest profile sample."""
    scan = tmp_path / "scan.h5"
    grid = "-1,1,0.1,3,6,0.15"
    steps = [["gbsar", "simulate", "samples/gbsar_indoor.toml", "-o", str(scan)],
             ["gbsar", "focus", str(scan), "--algorithm", "bp", "--grid", grid, "-o", str(tmp_path / "cpu.h5")],
             ["gbsar", "focus", str(scan), "--algorithm", "bp", "--grid", grid, "-o", str(tmp_path / "gpu.h5"),
              "--device", "cuda"]]
    code = ("import sys\nfrom sarcli.cli.app import app\n"
            "try:\n    app(sys.argv[1:])\nexcept SystemExit as e:\n    sys.exit(e.code)\n")
    for args in steps:
        out = subprocess.run([sys.executable, "-c", code, *args], cwd=REPO, env=_env(), capture_output=True,
                             text=True, timeout=600)
        assert out.returncode == 0, (args, out.stderr[-2000:])

    def image(name):
        with h5py.File(tmp_path / name) as f:
            key = "image" if "image" in f else next(k for k in f if isinstance(f[k], h5py.Dataset)
                                                    and np.iscomplexobj(f[k]))
            return np.asarray(f[key])

    from sarcli.gbsar.rangecomp import range_compress
    from sarcli.gpu.bp_cuda import float32_bound
    from sarcli.io.scan import read_scan

    s = read_scan(scan)
    largest = max(float(np.abs(range_compress(s, p, "hamming", 4, centred=True).data).max())
                  for p in s.polarizations)
    cpu, gpu = image("cpu.h5"), image("gpu.h5")
    assert cpu.shape == gpu.shape and np.abs(cpu).max() > 0
    assert np.max(np.abs(cpu - gpu)) <= float32_bound(s.n_stops, largest)
