"""Unwrapping methods and weighted least squares against plain-numpy references."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.ati.fit import noise_power, phase_weights, propagate, wls_poly
from sarcli.ati.unwrap import dominant_chirp, unwrap
from sarcli.errors import SarcliError


def _chirp(k, f, n=1024, dt=1 / 3000, phi0=0.3):
    t = np.arange(n) * dt
    return t, 2 * np.pi * (f * t + 0.5 * k * t * t) + phi0


@settings(max_examples=30, deadline=None)
@given(k=st.floats(-2000, 2000), f=st.floats(-600, 600))   # |f + k t| < 0.45 PRF
def test_both_methods_recover_a_clean_chirp(k, f):
    t, ph = _chirp(k, f)
    s = np.exp(1j * ph)
    for m in ("itoh", "dechirp"):
        chirp = dominant_chirp(s, t) if m == "dechirp" else None
        u = unwrap(s, t, m, chirp)
        d = u - ph
        assert np.allclose(d, d[0], atol=1e-6)
        assert abs(d[0] / (2 * np.pi) - round(d[0] / (2 * np.pi))) < 1e-6


def test_dominant_chirp_estimates_rate_and_frequency():
    t, ph = _chirp(-2300.0, 250.0, n=1800)
    k, f = dominant_chirp(np.exp(1j * ph), t)
    assert abs(k + 2300.0) < 0.25 / (t[-1] ** 2) + 1e-6
    assert abs(f - 250.0) < 1.0


def test_dechirp_survives_low_snr_where_itoh_slips():
    t, ph = _chirp(-2300.0, 400.0, n=1800)
    rng = np.random.default_rng(3)
    s = np.exp(1j * ph) + 0.7 * (rng.standard_normal(t.size) + 1j * rng.standard_normal(t.size))
    wrong = {}
    for m in ("itoh", "dechirp"):
        u = unwrap(s, t, m, dominant_chirp(s, t) if m == "dechirp" else None)
        d = u - ph
        wrong[m] = np.mean(np.round((d - np.median(d)) / (2 * np.pi)) != 0)   # samples on a wrong cycle
    assert wrong["itoh"] > 0.2              # cycle slips accumulate
    assert wrong["dechirp"] < 0.01          # only isolated noise samples beyond +-pi


def test_unknown_method_is_a_clear_error():
    with pytest.raises(SarcliError):
        unwrap(np.ones(8), np.arange(8.0), "magic")
    with pytest.raises(SarcliError):
        unwrap(np.ones(8), np.arange(8.0), "dechirp")


def test_wls_matches_numpy_polyfit_and_its_covariance():
    rng = np.random.default_rng(1)
    t = np.linspace(-0.3, 0.3, 400)
    sig = 0.05 + 0.2 * rng.random(t.size)
    y = 1.0 - 2.0 * t + 3.0 * t * t + sig * rng.standard_normal(t.size)
    q = wls_poly(t, y, 1 / sig ** 2, 2)
    ref, cov = np.polyfit(t, y, 2, w=1 / sig, cov="unscaled")
    assert np.allclose(q.coef, ref[::-1], rtol=1e-10, atol=1e-12)
    assert np.allclose(q.cov, cov[::-1, ::-1] * max(1.0, q.chi2_red), rtol=1e-8)
    assert 0.8 < q.chi2_red < 1.2


def test_wls_inflates_covariance_on_misfit():
    t = np.linspace(-1, 1, 200)
    y = t ** 3                                     # cubic data, quadratic model
    q = wls_poly(t, y, np.full(t.size, 1e4), 2)
    assert q.chi2_red > 10
    with pytest.raises(SarcliError):
        wls_poly(t[:3], y[:3], np.ones(3), 2)


def test_noise_power_and_weights():
    rng = np.random.default_rng(2)
    n = 0.3 * (rng.standard_normal(20000) + 1j * rng.standard_normal(20000)) / np.sqrt(2)
    assert abs(noise_power(2.0 + n) / 0.09 - 1) < 0.05
    w = phase_weights(np.r_[np.full(40, 2.0), np.full(40, 0.1)], 0.09, smooth=5)
    assert np.allclose(w[:38], 2 * (4 - 0.09) / 0.09) and np.all(w[42:] == 0)


def test_propagate_linear_map_is_exact():
    a = np.array([[1.0, 2.0], [0.5, -1.0], [3.0, 0.0]])
    c = np.array([[0.04, 0.01], [0.01, 0.09]])
    y, cy = propagate(lambda v: a @ v, np.array([1.0, 2.0]), c)
    assert np.allclose(y, a @ [1, 2]) and np.allclose(cy, a @ c @ a.T, rtol=1e-6)
