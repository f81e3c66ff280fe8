"""FFBP's numba.cuda stages under numba's CUDA simulator (no GPU needed) against the CPU FFBP, within the bound
derived in sarcli.gpu.ffbp_cuda; the refusals of ``--device cuda`` with ffbp are gone (``gbsar focus
--algorithm ffbp --device cuda`` end to end). The simulator must be on before numba is imported, so these run
in their own processes."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from tests.gpu.cli_pair import REPO, gbsar_cpu_and_cuda, sim_env


@pytest.fixture(scope="module")
def checks() -> dict:
    out = subprocess.run([sys.executable, str(REPO / "tests" / "gpu" / "ffbp_sim_checks.py")], cwd=REPO,
                         env=sim_env(), capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout)


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["grid", "stripmap"])
def test_ffbp_on_the_simulated_device_equals_the_cpu(checks, scene):
    r = checks[scene]
    assert r["stages"] >= 2  # the merge kernel runs, twice
    assert r["peak"] > 1.0  # a focused target, not zeros
    assert r["max_error"] <= r["bound"], r
    assert r["wsum_error"] == 0.0  # the weights used are the same pulses' (no rounding enters them)


@pytest.mark.slow
def test_the_stripmap_ffbp_focuser_accepts_cuda(checks):
    assert checks["stripmap_options_device"] == "cuda"


def test_the_bound_follows_its_derivation():
    """ffbp_bound = (S + 1) eps32 Lambda^(S+1) W + (8 k R + 64 + N) eps64 Lambda^(S+1) W, with Lambda the
    kernels' Lebesgue constants: linear interpolation's is exactly 1, so for two-tap kernels the bound is
    (S + 1) eps32 W + (8 k R + 64 + N) eps64 W."""
    from sarcli.focus.ffbp import FfbpKnobs
    from sarcli.gpu.ffbp_cuda import ffbp_bound, lebesgue

    assert lebesgue(2, 2.0) == pytest.approx(1.0, abs=1e-12)
    assert lebesgue(6, 2.0) > 1.0  # a windowed sinc has negative lobes
    lines = np.array([[3.0, -4.0j], [1.0, 0.5]])
    w = np.array([0.5, -2.0])  # W = 0.5 * 4 + 2 * 1 = 4
    got = ffbp_bound(FfbpKnobs(order=2, range_order=2), 2, 2.0, lines, w, 100.0, 10.0)
    eps32, eps64 = np.finfo(np.float32).eps, np.finfo(np.float64).eps
    assert got == pytest.approx(3 * eps32 * 4 + (8 * 100 * 10 + 64 + 2) * eps64 * 4, rel=1e-12)


@pytest.mark.slow
def test_gbsar_focus_ffbp_on_the_simulated_device_equals_the_cpu(tmp_path):
    """``sarcli gbsar focus --algorithm ffbp --grid ... --device cuda`` (simulator) vs ``--device cpu``: no
    refusal any more, and the same pixels (the image is the FFBP sum over the weight total, and the two
    paths share their arithmetic: module docstring of sarcli.gpu.ffbp_cuda; its bound, divided by the weight
    sum, with W = sum_i w_i max|P_i| <= the largest profile sample times the weight sum; k from the band's
    top frequency 5.6 GHz < c / 0.05 m, ranges and coordinates below 100 m, at most log_4(stops) merges)."""
    from sarcli.focus.ffbp import FfbpKnobs
    from sarcli.gpu.ffbp_cuda import ffbp_bound

    s, cpu, gpu, largest = gbsar_cpu_and_cuda(tmp_path, "ffbp", "-0.5,0.5,0.25,4.5,5.5,0.25", 900)
    stages = int(np.ceil(np.log(s.n_stops) / np.log(4)))  # at most log_base(stops) merges
    n = s.n_stops
    bound = ffbp_bound(FfbpKnobs(aperture_split=64), stages, 2.0, np.full((n, 1), largest), np.full(n, 1.0 / n),
                       4 * np.pi / 0.05, 100.0)
    assert np.max(np.abs(cpu - gpu)) <= bound
