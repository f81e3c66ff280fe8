"""Ambiguity resolution (margins, half-integer case, unwrapping across the PRF/2 boundary) and the
weighted 2-D polynomial fit with outlier flags."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.doppler.ambiguity import coverage_factor, resolve, rounding_confidence, unwrap_blocks
from sarcli.doppler.cde import wrap_frequency
from sarcli.doppler.polyfit import fit_poly2d

PRF = 1256.98


def _grid(na=4, nr=8):
    y, x = np.meshgrid(np.linspace(0, 10, na), np.linspace(850e3, 900e3, nr), indexing="ij")
    return x, y


@settings(max_examples=40, deadline=None)
@given(n=st.integers(-10, 10), frac=st.floats(-0.49, 0.49), slope=st.floats(-400, 400),
       pred_err=st.floats(-0.45, 0.45), seed=st.integers(0, 1000))
def test_unwrap_and_resolve_recover_every_block(n, frac, slope, pred_err, seed):
    """True centroid = smooth surface with |ambiguity| up to 10, possibly straddling +-PRF/2; the
    prediction is off by up to 0.45 PRF: every block must get its true ambiguity."""
    rng = np.random.default_rng(seed)
    x, y = _grid()
    u = (x - x.mean()) / 25e3
    true = (n + frac) * PRF + slope * u + 20 * (y - 5) / 5
    meas = wrap_frequency(true + rng.normal(0, 3, true.shape), PRF)
    w = np.ones_like(true)
    fu = unwrap_blocks(meas, w, PRF, x, y)
    pred = true + pred_err * PRF
    r = resolve(meas, fu, pred, w, PRF)
    np.testing.assert_array_equal(r.block_ambiguity, np.rint((true - meas) / PRF).astype(int))
    np.testing.assert_allclose(meas + r.block_ambiguity * PRF, true, atol=15)
    assert r.margin == pytest.approx(0.5 - abs(pred_err), abs=0.02)


def test_half_integer_case_is_declared_not_silently_rounded():
    x, y = _grid(1, 4)
    meas = np.full(x.shape, 100.0)
    w = np.ones_like(meas)
    fu = unwrap_blocks(meas, w, PRF, x, y)
    r = resolve(meas, fu, 100.0 + 2.5 * PRF, w, PRF)  # exactly half-way between n = 2 and n = 3
    assert not r.resolved and r.margin == pytest.approx(0.0, abs=1e-9)
    r = resolve(meas, fu, 100.0 + 2.4 * PRF, w, PRF)
    assert r.resolved and r.n0 == 2 and r.margin == pytest.approx(0.1)


def test_near_boundary_scene_does_not_flip_between_blocks():
    """True centroid within 3 % PRF of the baseband wrap: blocks alternate between +PRF/2 and -PRF/2
    in baseband; the absolute centroid must stay continuous (no neighbouring flips)."""
    rng = np.random.default_rng(1)
    x, y = _grid(6, 16)
    true = -6.5 * PRF + 0.02 * PRF + 15 * np.sin(x / 7e3) + rng.normal(0, 8, x.shape)
    meas = wrap_frequency(true, PRF)
    assert np.any(meas > 0.4 * PRF) and np.any(meas < -0.4 * PRF)
    w = np.ones_like(true)
    fu = unwrap_blocks(meas, w, PRF, x, y)
    r = resolve(meas, fu, true + 0.3 * PRF, w, PRF)
    absolute = meas + r.block_ambiguity * PRF
    assert np.max(np.abs(np.diff(absolute, axis=1))) < 0.1 * PRF
    np.testing.assert_allclose(absolute, true, atol=1e-6)


def test_rounding_confidence_is_a_probability():
    assert rounding_confidence(3.0, 0.01) == pytest.approx(1.0)
    assert rounding_confidence(3.5 - 1e-12, 0.01) == pytest.approx(0.5, abs=1e-6)
    from scipy.special import ndtr
    assert rounding_confidence(3.2, 0.3) == pytest.approx(ndtr(0.3 / 0.3) - ndtr(-0.7 / 0.3))
    # a scatter estimated from 3 blocks (2 dof) is less sure than a Gaussian with the same sigma
    assert rounding_confidence(3.3, 0.05, dof=2) < rounding_confidence(3.3, 0.05)
    assert rounding_confidence(np.nan, 0.1) == 0.0


def test_poly2d_recovers_surface_and_flags_outliers():
    rng = np.random.default_rng(4)
    x, y = _grid(5, 12)
    truth = 300 + 40 * ((x - 875e3) / 25e3) - 25 * ((x - 875e3) / 25e3) ** 2 + 6 * (y - 5) / 5
    z = truth + rng.normal(0, 1.0, x.shape)
    bad = np.zeros(x.shape, bool)
    bad[1, 3] = bad[4, 9] = True
    z[bad] += np.array([250.0, -400.0])
    p, flags = fit_poly2d(x, y, z, np.ones_like(z), degree=(2, 1), k_sigma=4.0)
    np.testing.assert_array_equal(flags.reshape(x.shape), bad)
    np.testing.assert_allclose(p(x, y), truth, atol=2.0)


def test_poly2d_degrades_degree_with_one_range_block():
    x = np.full(3, 850e3)
    y = np.array([0.0, 1.0, 2.0])
    p, flags = fit_poly2d(x, y, np.array([1.0, 2.0, 3.0]), np.ones(3), degree=(2, 1))
    assert p.coef.shape == (1, 2) and not flags.any()
    assert p(850e3, 1.5) == pytest.approx(2.5)
    assert p(850e3, 3.0) == pytest.approx(3.0)  # held at the domain edge, not extrapolated
    assert p(900e3, -7.0) == pytest.approx(1.0)


def test_rounding_confidence_student_t_one_dof_is_the_cauchy_law():
    """With one degree of freedom Student's t is the Cauchy law, CDF 1/2 + atan(t)/pi (closed form)."""
    off, sigma = 3.2, 0.3
    expected = (np.arctan((3.5 - off) / sigma) - np.arctan((2.5 - off) / sigma)) / np.pi
    assert rounding_confidence(off, sigma, dof=1.0) == pytest.approx(expected, rel=1e-12)


def test_coverage_factor_closed_forms_and_table():
    """t_{0.975, nu} / z_{0.975} from the closed-form Student-t quantiles (nu = 1: Cauchy, tan(pi (p - 1/2));
    nu = 2: (2p - 1) / sqrt(2 p (1 - p))), a published table value (t_{0.975, 7} = 2.3646) and the
    Gaussian limit; z_{0.975} = 1.959964 (tables)."""
    p, z = 0.975, 1.959963985
    assert coverage_factor(1) == pytest.approx(np.tan(np.pi * (p - 0.5)) / z, rel=1e-9)
    assert coverage_factor(2) == pytest.approx((2 * p - 1) / np.sqrt(2 * p * (1 - p)) / z, rel=1e-9)
    assert coverage_factor(7) == pytest.approx(2.3646 / z, abs=1e-4)
    assert coverage_factor(1e9) == pytest.approx(1.0, abs=1e-6)
    assert coverage_factor(0) == float("inf")
