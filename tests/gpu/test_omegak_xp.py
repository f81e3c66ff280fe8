"""The omega-k block on the array namespace (sarcli.gpu.omegak_xp) with xp = numpy, against the numba CPU path,
within :func:`sarcli.gpu.omegak_xp.difference_bound` (full Stolt: the CPU kernel's phasor recurrences, 1e-6 rad;
monochromatic: RD's span interpolation; both plus float32 round-off); point-target metrics identical to the
stated digits; the unit pieces against the numba kernels."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.focus import omegak
from sarcli.focus.interp import table_for
from sarcli.focus.omegak import focus_omegak
from sarcli.focus.quality import point_target_metrics
from sarcli.focus.windows import window_table
from sarcli.gpu import omegak_xp
from sarcli.model.doppler import GeometricDoppler
from tests.focus.synth import C, beam_offset, scene, sin_squint

PRF, FS = 1500.0, 24e6
DR = C / (2 * FS)
R0 = 850e3 + 384.3 * DR


@pytest.mark.parametrize("fdc,kw", [
    (0.0, {}),
    (-3.4 * PRF, {"block_lines": 512}),  # a centroid of several PRFs, several blocks
    (-3.4 * PRF, {"precision": "double", "stolt_kernel": "linear"}),
    (150.0, {"stolt_kernel": "sinc8", "stolt_oversample": 1.5}),
    (-3.4 * PRF, {"stolt": "monochromatic"}),
    (150.0, {"stolt": "monochromatic", "rcmc": "linear", "precision": "double"}),
])
def test_gpu_omegak_block_equals_cpu_within_the_derived_bound(monkeypatch, fdc, kw):
    monkeypatch.setenv("NUMBA_ENABLE_CUDASIM", "1")  # cuda = the simulator: xp is numpy
    eta0 = 0.34 + 0.37 / PRF - beam_offset(R0, fdc)
    raw = scene([(R0, eta0, 1.0), (R0 + 80 * DR, eta0 + 0.04, 0.5)], fdc=fdc, n_lines=768, n_samples=640)
    dop = GeometricDoppler(7000.0, sin_squint(fdc), 0.0566)
    cpu = focus_omegak(raw, dop, **kw)
    gpu = focus_omegak(raw, dop, device="cuda", **kw)
    assert gpu.image.dtype == cpu.image.dtype == np.complex64
    peak = float(np.abs(cpu.image).max())
    stolt = kw.get("stolt", "full")
    kernel = kw.get("stolt_kernel", "sinc16") if stolt == "full" else kw.get("rcmc", "sinc8")
    taps = table_for(kernel)[1].shape[1]
    n_az, n_r = cpu.parameters["azimuth_fft_length"], cpu.parameters["range_fft_length"]
    bound = omegak_xp.difference_bound(n_az, n_r, taps, kw.get("precision", "single"), stolt)
    assert np.max(np.abs(gpu.image - cpu.image)) <= bound * peak
    row, col = np.unravel_index(int(np.argmax(np.abs(cpu.image))), cpu.image.shape)
    m_cpu, m_gpu = point_target_metrics(cpu.image, row, col), point_target_metrics(gpu.image, row, col)
    for key in ("irw_range_px", "irw_azimuth_px"):
        assert round(m_cpu[key], 3) == round(m_gpu[key], 3)
    for key in ("pslr_range_db", "pslr_azimuth_db"):
        assert round(m_cpu[key], 2) == round(m_gpu[key], 2)
    assert abs(m_cpu["row"] - m_gpu["row"]) < 1e-3 and abs(m_cpu["col"] - m_gpu["col"]) < 1e-3


@pytest.mark.parametrize("interp", ["linear", "sinc8", "sinc16"])
def test_stolt_rows_is_the_kernel(interp):
    """Same table and phase index on both: they differ by the kernel's recurrence (<= 1e-6 rad by its span
    rule) and float64 round-off of sums of |u| ~ 1 over L bins."""
    rng = np.random.default_rng(4)
    rows, n = 6, 512
    x = rng.standard_normal((rows, n)) + 1j * rng.standard_normal((rows, n))
    h = np.exp(1j * rng.uniform(0, 6, n))
    fs, f0, v = 24e6, 5.3e9, 7000.0
    f_tau = np.fft.fftfreq(n, 1 / fs)
    f_eta = -5100.0 + rng.uniform(-600, 600, rows)
    kind, table = table_for(interp)
    ref = np.empty((rows, n), np.complex128)
    omegak.stolt_rows(x, h, f_tau, f_eta, v, 851e3, 5.68e-3, f0, fs, kind, table, ref)
    out = omegak_xp.stolt_rows(np, x, h, f_tau, f_eta, v, 851e3, 5.68e-3, f0, fs, kind, table)
    scale = np.sum(np.abs(x), axis=1, keepdims=True) / n * table.shape[1]
    assert np.max(np.abs(out - ref) / scale) < 2e-6


def test_column_corrections_are_the_kernel():
    """With a velocity from -10 to +100 m/s of v_ref across the columns the differential shift runs from 3e-4
    to 0.4 sample, so
    both branches (envelope read and plain sample) run; the same tables: float64 round-off only."""
    rng = np.random.default_rng(6)
    rows, n, nr = 40, 300, 256
    z = rng.standard_normal((rows, n)) + 1j * rng.standard_normal((rows, n))
    prf, lam, f0, dr = 1500.0, 0.0566, 5.3e9, DR
    f_bin = np.fft.fftfreq(rows, 1 / prf)
    r0 = 850e3 + np.arange(nr) * dr
    v = 7000.0 + np.linspace(-10.0, 100.0, nr)  # crosses v_ref = 7000 m/s near column 23
    fdc = np.linspace(-5100.0, -5080.0, nr)
    dt = np.linspace(-2e-6, 2e-6, nr)
    ph0 = np.linspace(0.0, 0.05, nr)
    wtab, table = window_table("hamming"), table_for(omegak.DIFF_INTERPOLATOR)[1]
    ref = np.empty((rows, nr), np.complex128)
    args = (f_bin, r0, v, 7000.0, fdc, dt, ph0, lam, prf, 1200.0, wtab, 3, f0, dr, table)
    omegak.column_corrections(z, *args, ref)
    out = omegak_xp.column_corrections(np, z, *args, omegak.SHIFT_TOL_SAMPLES)
    delta = np.abs(r0 * (np.sqrt(1 - (lam * -5100 / 14000) ** 2) / np.sqrt(1 - (lam * -5100 / (2 * v)) ** 2) - 1)
                   / dr)
    assert delta.max() > 0.1 and delta.min() < omegak.SHIFT_TOL_SAMPLES  # both branches
    assert np.max(np.abs(out - ref)) < 1e-12 * 8 * np.max(np.abs(z))


def test_bulk_phase_rows_is_the_kernel():
    rng = np.random.default_rng(8)
    x = (rng.standard_normal((7, 200)) + 1j * rng.standard_normal((7, 200))).astype(np.complex64)
    f_tau = np.fft.fftfreq(200, 1 / 24e6)
    f_eta = -5100.0 + rng.uniform(-600, 600, 7)
    ref = x.copy()
    omegak.bulk_phase_rows(ref, f_tau, f_eta, 7000.0, 851e3, 5.3e9)
    out = omegak_xp.bulk_phase_rows(np, x, f_tau, f_eta, 7000.0, 851e3, 5.3e9)
    assert out.dtype == np.complex64
    assert np.max(np.abs(out - ref)) <= 2 * np.finfo(np.float32).eps * np.max(np.abs(x))


def test_tile_size_does_not_change_the_image(monkeypatch):
    monkeypatch.setenv("NUMBA_ENABLE_CUDASIM", "1")
    fdc = -3.4 * PRF
    eta0 = 0.34 + 0.37 / PRF - beam_offset(R0, fdc)
    raw = scene([(R0, eta0, 1.0)], fdc=fdc, n_lines=768, n_samples=640)
    dop = GeometricDoppler(7000.0, sin_squint(fdc), 0.0566)
    slc = focus_omegak(raw, dop, device="cuda")
    monkeypatch.setattr(omegak_xp, "ROWS", 7)
    b = focus_omegak(raw, dop, device="cuda").image
    # rows are independent, so a tile changes only how the FFT library batches rows: the round-off of the
    # range IFFT, eps32 log2(L) relative, and of the azimuth IFFT that sums it, log2(N) (as tests/gpu/test_rd_xp.py)
    n = slc.parameters["azimuth_fft_length"] * slc.parameters["range_fft_length"]
    peak = float(np.abs(slc.image).max())
    assert np.max(np.abs(slc.image - b)) <= 2 * np.log2(n) * np.finfo(np.float32).eps * peak


def test_device_option_is_checked_before_any_work(monkeypatch):
    """``OmegakOptions.device`` is normalised, and ``cuda`` without CuPy is one line (exit 2 at the CLI)."""
    import sys

    from sarcli.errors import ConfigError
    from sarcli.focus.omegak import OmegakOptions

    monkeypatch.setenv("NUMBA_ENABLE_CUDASIM", "1")
    assert OmegakOptions(device=" CUDA ").device == "cuda"
    monkeypatch.delenv("NUMBA_ENABLE_CUDASIM")
    monkeypatch.setitem(sys.modules, "cupy", None)  # a None entry makes the import raise ImportError
    with pytest.raises(ConfigError, match="needs CuPy"):
        OmegakOptions(device="cuda")
    with pytest.raises(ConfigError, match="unknown device"):
        OmegakOptions(device="gpu")
