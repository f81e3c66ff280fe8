"""Map-drift autofocus on plain-numpy point-target raw data with a known Doppler rate, and the swath
model (one effective velocity) on a simulated airborne scene."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.doppler.api import estimate_doppler
from sarcli.doppler.mapdrift import _drift_lines, _unit_phasor, map_drift
from sarcli.doppler.options import DopplerOptions
from sarcli.doppler.rangecomp import range_compress_valid
from sarcli.errors import SarcliError
from sarcli.io.doppler_product import read_doppler, write_doppler
from sarcli.model.poly import Poly2D
from sarcli.model.raw import Radar
from sarcli.threads import limited
from tests.doppler.conftest import SCENES, simulate_text
from tests.doppler.synth import C, point_target_raw

PRF, FS, F0, K, TP = 1000.0, 60e6, 5.3e9, -12.5e12, 4e-6
RADAR = Radar(F0, C / F0, PRF, FS, K, TP, 2 * 850e3 / C, 850e3)


@pytest.mark.parametrize("fdc,fr,start", [(-3400.0, -2000.0, 0.8), (150.0, -1500.0, 1.2)])
def test_map_drift_recovers_the_rate(fdc, fr, start):
    rng = np.random.default_rng(2)
    x = point_target_raw(512, 512, PRF, FS, F0, K, TP, fdc, fr, 40, rng, beam_s=0.12)
    rc, v = range_compress_valid(x, RADAR)
    r_mid = 850e3 + 0.5 * (v.start + v.stop) * C / (2 * FS)
    res = map_drift(rc, PRF, C / F0, r_mid, C / (2 * FS), fdc, start * fr)
    assert res.converged
    assert res.fr_hz_per_s == pytest.approx(fr, rel=1e-3)


def test_map_drift_refuses_bad_start():
    with pytest.raises(SarcliError, match="negative"):
        map_drift(np.ones((128, 8), np.complex64), PRF, 0.05, 8e5, 5.0, 0.0, +100.0)
    with pytest.raises(SarcliError, match="64 azimuth lines"):
        map_drift(np.ones((10, 8), np.complex64), PRF, 0.05, 8e5, 5.0, 0.0, -100.0)


def test_poly2d_range_power_is_evaluated_everywhere():
    """x_power = -1: c/R at any range (plain numpy), no clipping to the fitted domain."""
    p = Poly2D(np.array([[-3.0e9]]), 1.0e6, 1.0e4, 0.0, 1.0, x_power=-1)
    r = np.array([1.0e5, 9.9e5, 1.0e6, 2.0e6])
    np.testing.assert_allclose(p(r, 5.0), -3.0e9 / r, rtol=1e-15)


@pytest.fixture(scope="module")
def airborne_raw():
    """Airborne LOCAL-frame clutter scene, straight flight at 2000 m/s (true fr = -2 V^2/(lam R)); the
    nominal velocity is removed from the product so map-drift starts from a 10 % wrong guess."""
    raw = simulate_text((SCENES / "airborne_clutter.toml").read_text())
    return dataclasses.replace(raw, radar=dataclasses.replace(raw.radar, platform_velocity_mps=None))


def test_mapdrift_rate_follows_inverse_range_over_the_swath(airborne_raw, tmp_path):
    """One effective velocity for the swath: the model equals the simulator truth -2 V^2/(lam R) within
    0.1 % over every range sample, keeps the 1/R law far outside the swath (no flat hold), and reports
    Vr with an uncertainty that covers the true 2000 m/s. The product keeps the 1/R law."""
    raw = airborne_raw
    rho, lam, v = raw.slant_range(), raw.radar.wavelength_m, 2000.0
    tr = raw.truth["doppler_rate_hz_per_s"]
    np.testing.assert_allclose(tr, -2 * v**2 / (lam * rho), rtol=1e-12)  # the scene is what it says
    m = estimate_doppler(raw, DopplerOptions(velocity_guess_mps=2200.0, ambiguity_value=0))
    assert m.summary.fr_method == "mapdrift"
    assert np.max(np.abs(m.fr(rho, 0.0) / tr - 1.0)) < 1e-3
    far = np.linspace(0.5 * rho[0], 2.0 * rho[-1], 50)
    assert np.max(np.abs(m.fr(far, 0.3) / (-2 * v**2 / (lam * far)) - 1.0)) < 1e-3
    md = m.summary.fr_info.mapdrift
    assert md.n_segments_used == 8
    assert md.velocity_mps == pytest.approx(v, rel=5e-4)
    assert 0 < md.velocity_sigma_mps < 5e-4 * v
    assert abs(md.velocity_mps - v) < 4 * md.velocity_sigma_mps
    write_doppler(tmp_path / "d.h5", m)
    back = read_doppler(tmp_path / "d.h5")
    np.testing.assert_allclose(back.fr(far, 0.0), m.fr(far, 0.0), rtol=1e-14)
    assert back.summary.fr_info.mapdrift == md and back.summary == m.summary  # typed summary round trip


def test_mapdrift_segments_side_by_side_give_the_serial_result(airborne_raw):
    """The range segments run on a thread each (budget 3: a pool even on a smaller machine); the rates,
    iterations and Vr are those of one thread, bit for bit."""
    opts = DopplerOptions(velocity_guess_mps=2200.0, ambiguity_value=0)
    with limited(1):
        serial = estimate_doppler(airborne_raw, opts).summary.fr_info
    with limited(3):
        pooled = estimate_doppler(airborne_raw, opts).summary.fr_info
    assert pooled == serial


@settings(max_examples=40, deadline=None)
@given(st.floats(-1e4, 1e4), st.integers(0, 2**31))
def test_unit_phasor_matches_complex128_exp(scale, seed):
    # bound from the docstring's error budget: reduction ~1e-12, float32 phase 1e-7 rad, 2 pi product
    # 2e-7 rad, cos/sin a few float32 ulp: 5e-7 in all (1e-6 allows for the ulp count of numpy's SIMD)
    turns = np.random.default_rng(seed).uniform(-1.0, 1.0, (7, 33)) * scale
    got = _unit_phasor(turns)
    assert got.dtype == np.complex64
    np.testing.assert_array_less(np.abs(got - np.exp(2j * np.pi * turns)), 1e-6)


def _drift_lines_numpy(i1, i2):
    """Plain float64 reference: circular cross-correlation of the mean-removed columns, summed over
    range, parabolic peak."""
    a = i1 - i1.mean(axis=0)
    b = i2 - i2.mean(axis=0)
    n = a.shape[0]
    xc = sum(np.array([np.dot(np.roll(b[:, j], -lag), a[:, j]) for lag in range(n)]) for j in range(a.shape[1]))
    k = int(np.argmax(xc))
    y0, y1, y2 = xc[(k - 1) % n], xc[k], xc[(k + 1) % n]
    s = k + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    return s - n if s > n / 2 else s


@settings(max_examples=25, deadline=None)
@given(st.integers(-20, 20), st.floats(-0.45, 0.45), st.integers(0, 2**31))
def test_drift_lines_matches_the_direct_correlation(shift, frac, seed):
    # a smooth random texture and a copy moved by shift + frac lines (Fourier shift). The float32 FFTs
    # perturb the correlation by ~1e-6 of its peak; the parabolic offset then moves by ~1e-6 / curvature
    # (~0.1 of the peak here): 1e-4 lines leaves a margin of ~10
    rng = np.random.default_rng(seed)
    n, m = 128, 6
    spec = (rng.standard_normal((n, m)) + 1j * rng.standard_normal((n, m))) * np.exp(
        -0.5 * (np.fft.fftfreq(n)[:, None] / 0.06) ** 2)
    f = np.fft.fftfreq(n)[:, None]
    i1 = (np.abs(np.fft.ifft(spec, axis=0)) ** 2).astype(np.float32)
    i2 = (np.abs(np.fft.ifft(spec * np.exp(-2j * np.pi * f * (shift + frac)), axis=0)) ** 2).astype(np.float32)
    want = _drift_lines_numpy(i1.astype(np.float64), i2.astype(np.float64))
    assert _drift_lines(i1, i2) == pytest.approx(want, abs=1e-4)
    assert want == pytest.approx(shift + frac, abs=0.2)  # the reference itself finds the shift
