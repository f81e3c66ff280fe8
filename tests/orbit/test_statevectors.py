"""StateVectors: validation, Hermite interpolation (numba vs numpy vs scipy), accuracy on J2 truth."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import KroghInterpolator

from orbit.errors import InterpolationRangeError, OrbitError, StateVectorError
from orbit.statevectors import DEFAULT_N_NODES, StateVectors, hermite_reference
from tests.orbit.truth import EPOCH, SPACING, make_truth


def _err(a, b):
    return np.linalg.norm(a - b, axis=-1)


def test_default_order_meets_acceptance_away_from_ends(polar_truth):
    """Default N: < 1 mm and < 1 um/s at 480 s spacing, more than two spacings from the span ends."""
    tr = polar_truth
    p, v, _ = tr.sv.interpolate(tr.t)
    t0, t1 = tr.sv.span
    inner = (tr.t >= t0 + 2 * SPACING) & (tr.t <= t1 - 2 * SPACING)
    assert _err(p, tr.r)[inner].max() < 1e-3
    assert _err(v, tr.v)[inner].max() < 1e-6
    # whole span incl. the one-sided end windows: still centimetre-level
    assert _err(p, tr.r).max() < 0.02


@pytest.mark.parametrize("inclination", [0.0, 90.0, 98.6, 135.0])
def test_accuracy_polar_equatorial_retrograde(inclination):
    tr = make_truth(inclination, n_dense=301)
    p, v, a = tr.sv.interpolate(tr.t)
    inner = (tr.t >= 2 * SPACING) & (tr.t <= tr.t[-1] - 2 * SPACING)
    assert _err(p, tr.r)[inner].max() < 1e-3
    assert _err(v, tr.v)[inner].max() < 1e-6
    # acceleration: two-body + J2 gravity at the interpolated position, to the J2 term's level
    gm = 3.986004418e14
    rn = np.linalg.norm(p, axis=-1, keepdims=True)
    assert np.abs(_err(a, -gm * p / rn**3) / np.linalg.norm(a, axis=-1)).max() < 3e-3  # |a_J2|/|a| ~ 2e-3


def test_ascending_and_descending_segments_are_both_covered(polar_truth):
    vz = polar_truth.v[:, 2]
    p, _, _ = polar_truth.sv.interpolate(polar_truth.t)
    err = _err(p, polar_truth.r)
    inner = (polar_truth.t >= 2 * SPACING) & (polar_truth.t <= polar_truth.t[-1] - 2 * SPACING)
    assert err[inner & (vz > 0)].max() < 1e-3 and err[inner & (vz < 0)].max() < 1e-3


@pytest.mark.parametrize("n_nodes", [2, 3, 4, 7, 8, 10, 12, 16])
def test_kernel_matches_numpy_reference(n_nodes):
    rng = np.random.default_rng(n_nodes)
    tr = make_truth(98.6, n_dense=2, node_times=np.cumsum(rng.uniform(400, 560, 17)))
    t = np.concatenate([tr.sv.time, rng.uniform(*tr.sv.span, 200)])
    got = tr.sv.interpolate(t, n_nodes)
    ref = hermite_reference(tr.sv.time, tr.sv.position, tr.sv.velocity, t, n_nodes)
    # both are float64 evaluations of the same degree-(2N-1) polynomial: the rounding grows like ~3^N
    # (measured: 4e-9 m at N = 2, 6e-6 m at N = 12, 2.6e-3 m at N = 16 in the one-sided end windows)
    g3 = 3.0**n_nodes
    tol = (1e-8 + 2e-10 * g3, 1e-10 + 2e-12 * g3, 1e-12 + 3e-14 * g3)
    for g, r, tl in zip(got, ref, tol, strict=True):
        assert np.abs(g - r).max() < tl


def test_matches_scipy_krogh_on_one_window(polar_truth):
    """Independent reference: scipy's Krogh interpolator with repeated abscissae = Hermite data."""
    sv = polar_truth.sv
    N = 6
    nodes = slice(4, 4 + N)  # the window used for the interval [t6, t7]
    xi = np.repeat(sv.time[nodes], 2)
    yi = np.empty((2 * N, 3))
    yi[0::2], yi[1::2] = sv.position[nodes], sv.velocity[nodes]
    t = np.linspace(sv.time[6], sv.time[7], 9)[:-1]  # at t7 the next window takes over
    kr = KroghInterpolator(xi, yi).derivatives(t, der=3)
    got = sv.interpolate(t, N)
    for g, k, tol in zip(got, kr, (1e-6, 1e-9, 1e-12), strict=True):
        assert np.abs(g - k).max() < tol


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 8), st.integers(0, 2**32 - 1))
def test_reproduces_polynomials_up_to_degree_2n_minus_1(n_nodes, seed):
    """Hermite over N nodes is exact for degree <= 2N-1, on uneven nodes and at any time in the span."""
    rng = np.random.default_rng(seed)
    n = n_nodes + 3
    tn = np.cumsum(rng.uniform(0.7, 1.3, n))
    deg = 2 * n_nodes - 1
    c = rng.normal(size=(deg + 1, 3))
    P = [np.polynomial.Polynomial(c[:, i]) for i in range(3)]

    def ev(poly_list, t, d):
        return np.stack([p.deriv(d)(t) if d else p(t) for p in poly_list], -1)

    sv = StateVectors(tn, ev(P, tn, 0), ev(P, tn, 1), "LOCAL")
    t = rng.uniform(tn[0], tn[-1], 50)
    p, v, a = sv.interpolate(t, n_nodes)
    scale = np.abs(c).sum() * max(1.0, tn[-1]) ** deg
    assert np.abs(p - ev(P, t, 0)).max() < 1e-11 * scale
    assert np.abs(v - ev(P, t, 1)).max() < 1e-10 * scale
    assert np.abs(a - ev(P, t, 2)).max() < 1e-9 * scale


def test_exact_on_nodes_and_span_ends(polar_truth):
    sv = polar_truth.sv
    for N in (2, 5, DEFAULT_N_NODES):
        p, v, _ = sv.interpolate(sv.time, N)
        assert np.abs(p - sv.position).max() < 1e-6
        assert np.abs(v - sv.velocity).max() < 1e-9


def test_position_and_velocity_continuous_across_nodes(polar_truth):
    sv = polar_truth.sv
    eps = 1e-3
    for k in (1, 5, 7, 13):  # the window changes at these nodes: no jump beyond the Taylor step
        lo = sv.interpolate(sv.time[k] - eps)
        hi = sv.interpolate(sv.time[k] + eps)
        _, vk, ak = sv.interpolate(sv.time[k])
        assert _err(hi[0] - lo[0], 2 * eps * vk) < 1e-6
        assert _err(hi[1] - lo[1], 2 * eps * ak) < 1e-9


def test_scalar_and_shaped_times(polar_truth):
    sv = polar_truth.sv
    p, v, a = sv.interpolate(1000.0)
    assert p.shape == v.shape == a.shape == (3,)
    p2, _, _ = sv.interpolate(np.full((2, 4), 1000.0))
    assert p2.shape == (2, 4, 3) and np.array_equal(p2[1, 3], p)
    assert sv.interpolate(np.empty(0))[0].shape == (0, 3)


def test_slightly_uneven_spacing_is_accepted_and_accurate():
    """9.999999 s vs 10.000001 s (and 480 s +- 0.5 ms) are not errors and interpolate as well."""
    rng = np.random.default_rng(1)
    tn = np.arange(15) * SPACING + rng.uniform(-5e-4, 5e-4, 15)
    tr = make_truth(98.6, n_dense=301, node_times=tn)
    p, v, _ = tr.sv.interpolate(tr.t)
    inner = (tr.t >= tn[2]) & (tr.t <= tn[-3])
    assert _err(p, tr.r)[inner].max() < 1e-3 and _err(v, tr.v)[inner].max() < 1e-6
    sv = StateVectors([0.0, 9.999999, 20.000000, 30.000001], np.zeros((4, 3)), np.zeros((4, 3)), "LOCAL")
    assert sv.spacing == pytest.approx(10.0, abs=1e-5)


def test_strongly_uneven_spacing_still_interpolates():
    rng = np.random.default_rng(2)
    tn = np.concatenate([[0.0], np.cumsum(rng.uniform(240, 720, 14))])
    tr = make_truth(98.6, n_dense=301, node_times=tn)
    p, v, _ = tr.sv.interpolate(tr.t)
    inner = (tr.t >= tn[3]) & (tr.t <= tn[-4])
    assert _err(p, tr.r)[inner].max() < 5e-2  # gaps up to 720 s: error follows the local spacing


def test_outside_span_refused_unless_bounded_extrapolation_allowed(polar_truth):
    sv = polar_truth.sv
    t_out = sv.span[1] + SPACING  # one node-width outside
    with pytest.raises(InterpolationRangeError, match="outside the state-vector span"):
        sv.interpolate(t_out)
    with pytest.raises(InterpolationRangeError):
        sv.interpolate(np.array([100.0, sv.span[0] - 1e-3]))
    with pytest.raises(InterpolationRangeError):
        sv.interpolate(t_out, max_extrapolation_s=SPACING / 2)
    p, v, _ = sv.interpolate(t_out, n_nodes=6, max_extrapolation_s=SPACING)
    assert np.all(np.isfinite(p)) and 6.7e6 < np.linalg.norm(p) < 7.3e6
    with pytest.raises(InterpolationRangeError, match="NaN"):
        sv.interpolate(np.nan)


@pytest.mark.parametrize("time,pos,frame,match", [
    ([0.0, 1.0, 1.0], None, "ECI", "duplicated"),
    ([0.0, 2.0, 1.0], None, "ECI", "not increasing"),
    ([0.0, 1.0, np.nan], None, "ECI", "NaN"),
    ([0.0, 1.0, 2.0], np.full((3, 3), np.inf), "ECI", "NaN"),
    ([0.0, 1.0, 2.0], np.zeros((3, 2)), "ECI", r"must both be \(3, 3\)"),
    ([0.0, 1.0, 2.0], None, "J2000", "unknown state-vector frame"),
    ([0.0], None, "ECI", "at least 2"),
    ([0.0, 10.0, 10.0 + 1e-9, 20.0], None, "ECI", "apart"),
])
def test_validation_errors(time, pos, frame, match):
    n = len(time)
    pos = np.zeros((n, 3)) if pos is None else pos
    with pytest.raises(StateVectorError, match=match) as e:
        StateVectors(time, pos, np.zeros((n, 3)), frame)
    assert isinstance(e.value, ValueError) and isinstance(e.value, OrbitError)
    assert "\n" not in str(e.value)


def test_n_nodes_bounds(polar_truth):
    sv = polar_truth.sv
    for bad in (1, 17):
        with pytest.raises(StateVectorError, match="n_nodes"):
            sv.interpolate(100.0, bad)
    with pytest.raises(StateVectorError, match="exceeds"):
        sv.interpolate(100.0, 16)  # only 15 vectors
    few = StateVectors(sv.time[:3], sv.position[:3], sv.velocity[:3], "ECI", EPOCH)
    assert few.default_n_nodes() == 3


def test_inputs_are_copied_and_read_only(polar_truth):
    t = polar_truth.sv.time.copy()
    sv = StateVectors(t, polar_truth.sv.position, polar_truth.sv.velocity, "eci", EPOCH)
    t[0] = -99.0
    assert sv.time[0] == 0.0 and sv.frame == "ECI"
    with pytest.raises(ValueError):
        sv.position[0, 0] = 1.0


def test_ecef_round_trip_and_interpolation_in_ecef(polar_truth, ecef_truth):
    back = ecef_truth.to_eci()
    assert np.abs(back.position - polar_truth.sv.position).max() < 1e-6
    assert np.abs(back.velocity - polar_truth.sv.velocity).max() < 1e-9
    assert ecef_truth.to_ecef() is ecef_truth
    # interpolating in ECEF agrees with interpolating in ECI and then rotating
    from orbit.frames import eci_to_ecef

    t = polar_truth.t[300:900:7]
    pi, vi, _ = polar_truth.sv.interpolate(t)
    pe, ve = eci_to_ecef(EPOCH, t, pi, vi)
    p2, v2, _ = ecef_truth.interpolate(t)
    assert _err(p2, pe).max() < 1e-3 and _err(v2, ve).max() < 1e-6


def test_local_frame_has_no_conversion():
    sv = StateVectors([0.0, 1.0], np.zeros((2, 3)), np.ones((2, 3)), "LOCAL")
    with pytest.raises(StateVectorError, match="LOCAL"):
        sv.to_ecef()
    with pytest.raises(StateVectorError, match="epoch_utc"):
        StateVectors([0.0, 1.0], np.zeros((2, 3)), np.ones((2, 3)), "ECI").to_ecef()
