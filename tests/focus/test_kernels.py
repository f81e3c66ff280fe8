"""Numba kernels against their plain-numpy references; interpolator and geometry properties."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.focus.backprojection import backproject, backproject_numpy
from sarcli.focus.interp import INTERPOLATORS, interpolate_numpy, sinc_weights, table_for
from sarcli.focus.kinematics import beam_centre_offset, velocity_and_squint
from sarcli.focus.rangecomp import apply_range_filter_2d, apply_range_filter_2d_numpy
from sarcli.focus.rcmc import rcmc_azimuth, rcmc_azimuth_numpy
from sarcli.focus.windows import window_table
from sarcli.model.doppler import GeometricDoppler


@pytest.mark.parametrize("interp", INTERPOLATORS)
def test_rcmc_azimuth_kernel_matches_numpy(interp):
    rng = np.random.default_rng(5)
    na, nr = 64, 96
    s = (rng.standard_normal((na, nr)) + 1j * rng.standard_normal((na, nr))).astype(np.complex128)
    prf = 1500.0
    f_bin = np.fft.fftfreq(na, 1 / prf)
    dr = 6.0
    r0 = 850e3 + np.arange(nr) * dr
    # range variation of a Radarsat-1 swath scaled to 96 bins (the kernel interpolates position and
    # phase linearly over 32 bins): centroid 130 Hz, velocity 20 m/s, orbit timing 0.1 ms per 2400 bins
    v = np.linspace(7000, 7000.8, nr)
    fdc = np.linspace(-5100, -5095, nr)
    dt = np.linspace(-2e-6, 2e-6, nr)
    ph0 = np.linspace(0, 0.05, nr)
    kind, table = table_for(interp)
    out = np.zeros_like(s)
    rcmc_azimuth(s, f_bin, r0[0], dr, r0, v, fdc, dt, ph0, 0.0566, prf, 1200.0, window_table("hamming"), kind,
                 table, 3, out)
    ref = rcmc_azimuth_numpy(s, f_bin, r0[0], dr, r0, v, fdc, dt, ph0, 0.0566, prf, 1200.0, "hamming", interp, 3)
    # table lookups (window: 4097 points, sinc: 2048 phases) vs exact weights
    assert np.max(np.abs(out - ref)) < 2e-3 * np.max(np.abs(ref))
    # in place gives the same result (each row is copied before it is overwritten)
    inplace = s.copy()
    rcmc_azimuth(inplace, f_bin, r0[0], dr, r0, v, fdc, dt, ph0, 0.0566, prf, 1200.0, window_table("hamming"), kind,
                 table, 3, inplace)
    np.testing.assert_allclose(inplace, out, rtol=0, atol=1e-12)


def test_range_filter_2d_matches_numpy():
    rng = np.random.default_rng(1)
    x = rng.standard_normal((16, 40)) + 1j * rng.standard_normal((16, 40))
    h = np.exp(1j * rng.uniform(0, 6, 40))
    f = np.fft.fftfreq(40, 1 / 30e6)
    ik = rng.uniform(0, 1e-14, 16)
    for n_out in (41, 80, 97):  # zero padding (Fourier interpolation) into a longer row
        ref = apply_range_filter_2d_numpy(x, h, f, ik, n_out)
        out = np.full((16, n_out), np.nan, complex)
        apply_range_filter_2d(x, h, f, ik, out)
        np.testing.assert_allclose(out, ref, rtol=1e-12, atol=0)
    ref = apply_range_filter_2d_numpy(x, h, f, ik, 40)
    apply_range_filter_2d(x, h, f, ik, x)  # in place
    np.testing.assert_allclose(x, ref, rtol=1e-12)


def test_backprojection_kernel_matches_numpy():
    rng = np.random.default_rng(2)
    na, nr = 80, 64
    rc = rng.standard_normal((na, nr)) + 1j * rng.standard_normal((na, nr))
    t = np.arange(na) / 500.0
    pos = np.stack([0 * t, 200.0 * t, 3000 + 0 * t], 1)
    vel = np.tile([0.0, 200.0, 0.0], (na, 1))
    pix = np.array([[4000.0, 8.0, 0.0], [4010.0, 8.1, 0.0], [4005.0, 7.5, 0.0]])
    r_ref = np.linalg.norm(pix - [0, 0, 3000], axis=1)
    fdc = np.zeros(3)
    out = np.zeros(3, complex)
    backproject(rc, 4990.0, 1.0, 0.03, pos, vel, pix, r_ref, fdc, 400.0, window_table("kaiser:2.5"), out)
    ref = backproject_numpy(rc, 4990.0, 1.0, 0.03, pos, vel, pix, r_ref, fdc, 400.0, "kaiser:2.5")
    np.testing.assert_allclose(out, ref, rtol=1e-3)


@settings(max_examples=30, deadline=None)
@given(mu=st.floats(0, 0.999), taps=st.sampled_from([4, 8, 16]))
def test_sinc_weights_are_normalized_and_exact_at_integers(mu, taps):
    w = sinc_weights(taps, np.array(mu))
    assert abs(w.sum() - 1) < 1e-12
    w0 = sinc_weights(taps, np.array(0.0))
    assert np.argmax(w0) == taps // 2 - 1 and abs(w0.max() - 1) < 1e-12


@pytest.mark.parametrize("interp,tol", [("sinc4", 0.08), ("sinc8", 0.01), ("sinc16", 0.002), ("linear", 0.08)])
def test_interpolators_on_a_signal_at_a_quarter_of_the_sampling_rate(interp, tol):
    """After the 2x range upsampling the RCMC sees signals below fs/4: error bounds per kernel."""
    rng = np.random.default_rng(3)
    n = 512
    spec = np.zeros(n, complex)
    k = np.arange(-n // 8, n // 8)
    spec[k] = rng.standard_normal(k.size) + 1j * rng.standard_normal(k.size)
    x = np.fft.ifft(spec)
    p = np.linspace(100, 400, 997)
    exact = np.array([np.sum(spec[k] * np.exp(2j * np.pi * k * q / n)) / n for q in p])
    got = interpolate_numpy(x[None, :], p[None, :], interp)[0]
    assert np.sqrt(np.mean(np.abs(got - exact) ** 2) / np.mean(np.abs(exact) ** 2)) < tol


@settings(max_examples=40, deadline=None)
@given(v=st.floats(100, 8000), sq=st.floats(-0.3, 0.3), r=st.floats(5e3, 1.2e6))
def test_velocity_and_squint_invert_the_geometric_model(v, sq, r):
    lam = 0.0566
    m = GeometricDoppler(v, sq, lam)
    rc = r / np.sqrt(1 - sq**2)  # the model is indexed by beam-centre range
    vv, ss = velocity_and_squint(m.fdc(rc), m.fr(rc), np.array(r), lam)
    assert vv == pytest.approx(v, rel=1e-11)
    assert ss == pytest.approx(sq, abs=1e-9)
    # Delta = R0 tan(theta) / V: the hyperbola's beam-centre time after zero Doppler
    assert beam_centre_offset(r, v, sq) == pytest.approx(r * sq / np.sqrt(1 - sq**2) / v)
