"""The RD block written against an array namespace (sarcli.gpu.rd_xp) with xp = numpy: the code the GPU runs,
compared with the numba CPU path on plain-numpy point targets (tests/focus/synth.py).

The bound is :func:`sarcli.gpu.rd_xp.difference_bound` (derived there: the CPU kernel's span interpolation of
position and phase, and float32 round-off of FFTs and sums in another order)."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.focus.interp import table_for
from sarcli.focus.quality import point_target_metrics
from sarcli.focus.rangecomp import apply_range_filter_2d_numpy
from sarcli.focus.rcmc import rcmc_azimuth_numpy
from sarcli.focus.rda import focus_rd
from sarcli.focus.windows import window_table
from sarcli.gpu import rd_xp
from sarcli.model.doppler import GeometricDoppler
from tests.focus.synth import C, beam_offset, scene, sin_squint

PRF, FS = 1500.0, 24e6
DR = C / (2 * FS)
R0 = 850e3 + 384.3 * DR


@pytest.fixture
def simulator(monkeypatch):
    """``cuda`` = numba's simulator: the array namespace is numpy (sarcli.gpu.device)."""
    monkeypatch.setenv("NUMBA_ENABLE_CUDASIM", "1")


def _scene(fdc):
    eta0 = 0.34 + 0.37 / PRF - beam_offset(R0, fdc)
    raw = scene([(R0, eta0, 1.0), (R0 + 90 * DR, eta0 + 0.05, 0.5)], fdc=fdc, n_lines=768, n_samples=640)
    return raw, GeometricDoppler(7000.0, sin_squint(fdc), 0.0566)


@pytest.mark.parametrize("fdc,kw", [
    (0.0, {}),
    (-3.4 * PRF, {"block_lines": 512}),  # a centroid of several PRFs, several blocks
    (-3.4 * PRF, {"precision": "double", "rcmc": "linear"}),
    (200.0, {"rcmc": "nearest", "rcmc_oversample": 1, "src": False}),
])
def test_gpu_block_equals_cpu_within_the_derived_bound(simulator, fdc, kw):
    raw, dop = _scene(fdc)
    cpu = focus_rd(raw, dop, **kw)
    gpu = focus_rd(raw, dop, device="cuda", **kw)
    assert gpu.image.dtype == cpu.image.dtype == np.complex64
    peak = float(np.abs(cpu.image).max())
    plan_taps = {"nearest": 1, "linear": 2}.get(kw.get("rcmc", "sinc8"), 8)
    n_fft_az, n_fft_r = cpu.parameters["azimuth_fft_length"], cpu.parameters["range_fft_length"]
    bound = rd_xp.difference_bound(n_fft_az, n_fft_r, plan_taps, kw.get("precision", "single"))
    assert np.max(np.abs(gpu.image - cpu.image)) <= bound * peak
    # point targets: position, IRW, PSLR identical to the stated digits
    row, col = np.unravel_index(int(np.argmax(np.abs(cpu.image))), cpu.image.shape)
    m_cpu = point_target_metrics(cpu.image, row, col)
    m_gpu = point_target_metrics(gpu.image, row, col)
    for key in ("irw_range_px", "irw_azimuth_px"):
        assert round(m_cpu[key], 3) == round(m_gpu[key], 3)
    for key in ("pslr_range_db", "pslr_azimuth_db"):
        assert round(m_cpu[key], 2) == round(m_gpu[key], 2)
    assert abs(m_cpu["row"] - m_gpu["row"]) < 1e-3 and abs(m_cpu["col"] - m_gpu["col"]) < 1e-3

def test_tile_size_does_not_change_the_image(simulator, monkeypatch):
    raw, dop = _scene(-3.4 * PRF)
    slc = focus_rd(raw, dop, device="cuda")
    monkeypatch.setattr(rd_xp, "ROWS", 7)
    b = focus_rd(raw, dop, device="cuda").image
    # rows are independent, so a tile changes only how the FFT library batches rows (SIMD lanes): the
    # round-off of the range IFFT, eps32 log2(L) relative, and of the azimuth IFFT that sums it, log2(N)
    n = slc.parameters["azimuth_fft_length"] * slc.parameters["range_fft_length"] * 2
    peak = float(np.abs(slc.image).max())
    assert np.max(np.abs(slc.image - b)) <= 2 * np.log2(n) * np.finfo(np.float32).eps * peak


def test_range_filter_rows_is_the_numpy_reference():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((12, 40)) + 1j * rng.standard_normal((12, 40))
    h = np.exp(1j * rng.uniform(0, 6, 40))
    f = np.fft.fftfreq(40, 1 / 30e6)
    ik = rng.uniform(0, 1e-14, 12)
    for n_out in (40, 41, 80):
        np.testing.assert_allclose(rd_xp.range_filter_rows(np, x, h, f, ik, n_out),
                                   apply_range_filter_2d_numpy(x, h, f, ik, n_out), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("interp", ["nearest", "linear", "sinc8", "sinc16"])
def test_rcmc_rows_match_the_exact_reference(interp):
    """Against exact weights: only the tables differ (window 4097 points, sinc 2048 phases: the same 2e-3 of
    the CPU kernel's test, tests/focus/test_kernels.py)."""
    rng = np.random.default_rng(5)
    na, nr = 64, 96
    s = rng.standard_normal((na, nr)) + 1j * rng.standard_normal((na, nr))
    prf, dr = 1500.0, 6.0
    f_bin = np.fft.fftfreq(na, 1 / prf)
    r0 = 850e3 + np.arange(nr) * dr
    v = np.linspace(7000, 7000.8, nr)
    fdc = np.linspace(-5100, -5095, nr)
    dt = np.linspace(-2e-6, 2e-6, nr)
    ph0 = np.linspace(0, 0.05, nr)
    kind, table = table_for(interp)
    out = rd_xp.rcmc_azimuth_rows(np, s, f_bin, r0[0], dr, r0, v, fdc, dt, ph0, 0.0566, prf, 1200.0,
                                  window_table("hamming"), kind, table, 3)
    ref = rcmc_azimuth_numpy(s, f_bin, r0[0], dr, r0, v, fdc, dt, ph0, 0.0566, prf, 1200.0, "hamming", interp, 3)
    assert np.max(np.abs(out - ref)) < 2e-3 * np.max(np.abs(ref))
