"""The J2 propagator, the truth behind the Hermite, simulator-phase and Doppler tests, against theory."""

from __future__ import annotations

import math

import numpy as np
import pytest

from orbit.constants import GM_EARTH, J2_EARTH, WGS84_A
from orbit.propagate import Keplerian, _solve_kepler, kepler_to_state, propagate_j2

RS1 = Keplerian(7167100.0, 0.00115, math.radians(98.594), 0.35, math.radians(90.0), math.radians(-40.3))


def _kepler_analytic(k: Keplerian, t: np.ndarray) -> np.ndarray:
    """Two-body positions at times t from the mean anomaly advancing at n = sqrt(GM/a^3)."""
    n = math.sqrt(GM_EARTH / k.semi_major_axis_m**3)
    out = []
    for ti in t:
        m = k.mean_anomaly_rad + n * ti
        out.append(kepler_to_state(Keplerian(k.semi_major_axis_m, k.eccentricity, k.inclination_rad, k.raan_rad,
                                             k.arg_perigee_rad, m))[0])
    return np.array(out)


def test_kepler_equation_solver():
    for e in (0.0, 0.001, 0.3, 0.9):
        for m in np.linspace(-math.pi, math.pi, 13):
            E = _solve_kepler(m, e)
            assert E - e * math.sin(E) == pytest.approx(m, abs=1e-13)


def test_kepler_state_energy_and_momentum():
    r, v = kepler_to_state(RS1)
    a = RS1.semi_major_axis_m
    assert (v @ v) / 2 - GM_EARTH / np.linalg.norm(r) == pytest.approx(-GM_EARTH / (2 * a), rel=1e-12)
    h = np.cross(r, v)
    assert math.acos(h[2] / np.linalg.norm(h)) == pytest.approx(RS1.inclination_rad, abs=1e-12)
    assert np.linalg.norm(h) == pytest.approx(math.sqrt(GM_EARTH * a * (1 - RS1.eccentricity**2)), rel=1e-12)


def test_without_j2_the_integrator_is_keplerian():
    t = np.array([-3600.0, -480.0, 0.0, 900.0, 5400.0])
    r0, v0 = kepler_to_state(RS1)
    r, _ = propagate_j2(r0, v0, t, j2=0.0)
    assert np.abs(np.linalg.norm(r - _kepler_analytic(RS1, t), axis=1)).max() < 1e-3


def test_j2_nodal_regression_matches_theory():
    """Secular RAAN rate -1.5 n J2 (Re/p)^2 cos i (Vallado eq. 9-41); sun-synchronous ~ +0.9856 deg/day."""
    r0, v0 = kepler_to_state(RS1)
    days = 1.0
    t = np.linspace(0.0, days * 86400.0, 97)
    r, v = propagate_j2(r0, v0, t)
    h = np.cross(r, v)
    raan = np.unwrap(np.arctan2(h[:, 0], -h[:, 1]))
    rate = np.polyfit(t, raan, 1)[0]  # rad/s, short-period terms average out over 16 orbits
    a, e, i = RS1.semi_major_axis_m, RS1.eccentricity, RS1.inclination_rad
    n = math.sqrt(GM_EARTH / a**3)
    p = a * (1 - e * e)
    theory = -1.5 * n * J2_EARTH * (WGS84_A / p) ** 2 * math.cos(i)
    assert rate == pytest.approx(theory, rel=0.02)
    assert math.degrees(theory) * 86400 == pytest.approx(0.9856, abs=0.01)  # the orbit is sun-synchronous


def test_default_tolerance_is_converged():
    """rtol 1e-13 (the default) against 1e-14: sub-millimetre over +-1 h, the truth the accuracy tables assume."""
    r0, v0 = kepler_to_state(RS1)
    t = np.linspace(-3600.0, 3600.0, 31)
    a, _ = propagate_j2(r0, v0, t)
    b, _ = propagate_j2(r0, v0, t, rtol=1e-14, atol=1e-8)
    assert np.linalg.norm(a - b, axis=1).max() < 1e-3


def test_repeated_and_unsorted_times():
    r0, v0 = kepler_to_state(RS1)
    t = np.array([100.0, -50.0, 100.0, 0.0])
    r, _ = propagate_j2(r0, v0, t)
    np.testing.assert_array_equal(r[0], r[2])
    np.testing.assert_allclose(r[3], r0, atol=1e-9)
