"""The numba.cuda backprojection kernels under numba's CUDA simulator (no GPU needed), against the plain-numpy
references, within the float32 bound derived in sarcli.gpu.bp_cuda; and ``gbsar focus --device cuda`` end to
end. The simulator must be on before numba is imported, so these run in their own processes."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from tests.gpu.cli_pair import REPO, gbsar_cpu_and_cuda, sim_env


@pytest.fixture(scope="module")
def checks() -> dict:
    out = subprocess.run([sys.executable, str(REPO / "tests" / "gpu" / "sim_checks.py")], cwd=REPO, env=sim_env(),
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
    from sarcli.gpu.bp_cuda import float32_bound

    s, cpu, gpu, largest = gbsar_cpu_and_cuda(tmp_path, "bp", "-1,1,0.1,3,6,0.15", 600)
    assert np.max(np.abs(cpu - gpu)) <= float32_bound(s.n_stops, largest)
