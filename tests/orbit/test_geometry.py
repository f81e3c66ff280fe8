"""Ellipsoid geometry: target solves, look/incidence/range, Doppler and Doppler time, geolocation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from orbit import geometry as G
from orbit.errors import GeometryError
from orbit.frames import eci_to_ecef, gmst
from orbit.geodetic import ecef_to_geodetic
from orbit.pointing import beam_vector, flight_frame
from orbit.statevectors import StateVectors
from tests.orbit.truth import EPOCH, make_truth

LAM = 0.05656  # Radarsat-1 wavelength, m
RS1_PITCH, RS1_YAW = np.radians(0.03), np.radians(0.004)


def _states(sv, n=12):
    t = np.linspace(sv.span[0] + 100, sv.span[1] - 100, n)
    r, v, a = sv.interpolate(t)
    return t, r, v, a


@pytest.mark.parametrize("h", [0.0, 5000.0])
@pytest.mark.parametrize("look_deg", [0.0, 20.0, 45.0])
def test_target_from_look_satisfies_every_constraint(ecef_truth, look_deg, h):
    _, r, v, _ = _states(ecef_truth)
    look = np.radians(look_deg)
    pitch, yaw = (RS1_PITCH, RS1_YAW) if look_deg else (0.0, 0.0)
    p, rho = G.target_from_look(r, v, look, pitch=pitch, yaw=yaw, h=h)
    assert np.abs(ecef_to_geodetic(p)[2] - h).max() < 1e-4
    assert np.abs(np.linalg.norm(p - r, axis=-1) - rho).max() < 1e-6
    L = beam_vector(r, v, look, pitch, yaw)
    assert np.abs((p - r) / rho[:, None] - L).max() < 1e-12
    if look_deg == 0:  # nadir: the sub-satellite point, straight down the ellipsoid normal
        lat, lon, hs = ecef_to_geodetic(r)
        la, lo, _ = ecef_to_geodetic(p)
        assert np.abs(la - lat).max() < 1e-9 and np.abs(lo - lon).max() < 1e-9
        assert np.abs(rho - (hs - h)).max() < 1e-4


def test_offset_ellipsoid_alone_is_not_a_constant_height_surface():
    """Why the solves correct the (a + h, b + h) ellipsoid with pyproj heights: it is mm off at 5 km."""
    from orbit.constants import WGS84_A, WGS84_B

    th = np.radians(np.linspace(0.0, 90.0, 91))
    p = np.stack([(WGS84_A + 5e3) * np.cos(th), 0 * th, (WGS84_B + 5e3) * np.sin(th)], -1)
    err = np.abs(ecef_to_geodetic(p)[2] - 5e3)
    assert 5e-3 < err.max() < 1e-2 and err[0] < 1e-6 and err[-1] < 1e-6


def test_look_that_misses_the_earth_is_a_clear_error(ecef_truth):
    _, r, v, _ = _states(ecef_truth, 3)
    with pytest.raises(GeometryError, match=r"misses the Earth \(horizon at 6\d\.\d+ deg\)") as e:
        G.target_from_look(r, v, np.radians(80.0))
    assert "\n" not in str(e.value) and isinstance(e.value, ValueError)
    hz = G.horizon_look_angle(r, v)
    p, _ = G.target_from_look(r, v, hz * (1 - 1e-9))  # just inside the horizon: grazing incidence
    assert np.all(np.isfinite(p)) and np.all(np.degrees(G.incidence_angle(r, p)) > 89.0)
    with pytest.raises(GeometryError, match="beyond the horizon"):
        G.target_from_doppler(r, v, 4.5e6, LAM)
    with pytest.raises(GeometryError, match="no target on the Earth"):
        G.target_from_doppler(r, v, 5e5, LAM)  # shorter than the altitude
    with pytest.raises(GeometryError, match="too large"):
        G.target_from_doppler(r, v, 9e5, LAM, fdc=3e5)


def test_attitude_look_plane_solve_recovers_the_beam_target(ecef_truth):
    """Three-equation solve of [Koh2003, §3.1] (range, ellipsoid, look plane) vs the direct ray intersection."""
    _, r, v, _ = _states(ecef_truth)
    for scale in (0.0, 1.0, 100.0):
        for exact in (True, False):
            p, rho = G.target_from_look(r, v, 0.4, pitch=scale * RS1_PITCH, yaw=scale * RS1_YAW, h=5000.0,
                                        exact=exact)
            q = G.target_from_look_plane(r, v, rho, scale * RS1_PITCH, scale * RS1_YAW, h=5000.0, exact=exact)
            assert np.abs(q - p).max() < 1e-4


@pytest.mark.parametrize("side", ["right", "left"])
def test_target_from_doppler_constraints_and_side(ecef_truth, side):
    _, r, v, _ = _states(ecef_truth)
    rho = np.linspace(8.5e5, 1.1e6, r.shape[0])
    fdc = np.linspace(-2000, 2000, r.shape[0])
    p = G.target_from_doppler(r, v, rho, LAM, fdc, side, h=1234.5)
    assert np.abs(G.doppler_hz(r, v, p, LAM) - fdc).max() < 1e-6
    assert np.abs(np.linalg.norm(p - r, axis=-1) - rho).max() < 1e-6
    assert np.abs(ecef_to_geodetic(p)[2] - 1234.5).max() < 1e-4
    yf = flight_frame(r, v)[..., 1]
    assert np.all(np.sign(np.sum((p - r) * yf, -1)) == (1 if side == "right" else -1))


def test_doppler_sign_convention_and_eci_equivalence(polar_truth):
    """f_D = -(2/lam) dR/dt (phase exp(-j4piR/lam)): check by finite differences, and ECI ([Koh2003, eq. 4-5])
    with v_rel = v - w x r gives the same Doppler as ECEF.

    Error analysis of the central differences of R(t) = |p - r(t)| (r(t) the Hermite interpolant; t0 and
    t0 +- h lie in one interpolation window, [2880, 3360] s, so R is one smooth polynomial there):

    - truncation: D1 = R' + h^2 R3/6 + ...,  D2 = R'' + h^2 R4/12 + ...  (R3, R4: third, fourth derivative)
    - round-off: each R carries an error dR <= eps |r| (the position components, ~7.2e6 m, are Horner
      sums of degree 19 whose terms fall off fast; FMA contraction or not changes the last bits, which is
      why the former 1 ms step passed on one machine and failed on another), so |dD1| <= dR / h and
      |dD2| <= 4 dR / h^2 (weights 1, 2, 1).

    Minimizing h^2 |R4|/12 + 4 eps|r|/h^2 gives h2 = (48 eps|r| / |R4|)^(1/4) ~ 0.05 s (at 1 ms the
    round-off bound alone is 1.2e-4 relative); the first difference's optimum is h1 = (3 eps|r| / |R3|)^(1/3)
    ~ 0.01 s. R3 and R4 come from wide stencils (H = 2 s, 4 s, whose own errors are below 1e-3 relative).
    Tolerance: twice the bound at the chosen step, ~2e-7 relative for the rate, which resolves the
    v_r^2 / R term of the rate (~7e-6 relative here).
    """
    sv_i = polar_truth.sv
    sv_e = sv_i.to_ecef()
    t0 = 3000.0
    r, v, a = sv_e.interpolate(t0)
    p, _ = G.target_from_look(r, v, 0.45, pitch=2e-3, yaw=-1e-3)

    def rng(t):
        return np.linalg.norm(p - sv_e.interpolate(np.asarray(t, np.float64))[0], axis=-1)

    d_r = np.finfo(np.float64).eps * np.linalg.norm(r)  # round-off bound of one R evaluation, m
    r3 = abs(np.dot([-1, 2, 0, -2, 1], rng(t0 + 2.0 * np.arange(-2, 3)))) / (2 * 2.0**3)
    r4 = abs(np.dot([1, -4, 6, -4, 1], rng(t0 + 4.0 * np.arange(-2, 3)))) / 4.0**4
    h1 = (3 * d_r / r3) ** (1 / 3)
    h2 = (48 * d_r / r4) ** 0.25
    assert 1e-3 < h1 < 0.1 and 1e-2 < h2 < 0.5  # the analysis' orders of magnitude hold for this orbit
    R = rng(t0 + h1 * np.array([-1.0, 1.0]))
    tol1 = 2 * 2 / LAM * (r3 * h1**2 / 6 + d_r / h1)
    assert G.doppler_hz(r, v, p, LAM) == pytest.approx(-2 / LAM * (R[1] - R[0]) / (2 * h1), abs=tol1)
    R = rng(t0 + h2 * np.array([-1.0, 0.0, 1.0]))
    fr = -2 / LAM * (R[2] - 2 * R[1] + R[0]) / h2**2
    tol2 = 2 * 2 / LAM * (r4 * h2**2 / 12 + 4 * d_r / h2**2)
    assert tol2 < 1e-6 * abs(fr)
    assert G.doppler_rate_hz_per_s(r, v, a, p, LAM) == pytest.approx(fr, abs=tol2)
    assert G.doppler_rate_hz_per_s(r, v, a, p, LAM) < 0
    # ECI: rotate the fixed target into ECI at t0 and use the relative velocity
    ri, vi, _ = sv_i.interpolate(t0)
    th = gmst(EPOCH, t0)
    c, s = np.cos(th), np.sin(th)
    pi = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ p
    assert G.doppler_hz(ri, G.relative_velocity_eci(ri, vi), pi, LAM) == pytest.approx(
        G.doppler_hz(r, v, p, LAM), abs=1e-7)
    assert np.allclose(eci_to_ecef(EPOCH, t0, G.relative_velocity_eci(ri, vi)), v, atol=1e-9)


@pytest.mark.parametrize("inclination", [98.6, 90.0, 0.0])
def test_geolocation_round_trip_grid(inclination):
    """Acceptance: geolocate (t, R, fdc, h) -> p -> Doppler time and range: < 1 us and < 1 mm,
    over looks 15..55 deg, all latitudes of a polar (and an equatorial) orbit, h = 0 and 5 km,
    zero and large Doppler, both sides."""
    tr = make_truth(inclination, n_dense=2)
    sv = tr.sv.to_ecef()
    t = np.linspace(sv.span[0] + 500, sv.span[1] - 500, 41)
    r, v, _ = sv.interpolate(t)
    lat = ecef_to_geodetic(r)[0]
    if inclination == 90.0:
        assert lat.max() > 85 and lat.min() < -85  # the pass goes over (near) both poles
    for look in np.radians([15.0, 35.0, 55.0]):
        for h in (0.0, 5000.0):
            for fdc in (0.0, -7000.0):
                for side in ("right", "left"):
                    rho = G.slant_range_from_look(r, v, look, side, h)
                    p = G.geolocate(sv, t, rho, LAM, fdc, h, side)
                    t2, rho2 = G.doppler_time(sv, p, LAM, fdc, t_guess=t)  # > 1 rev: passes overlap
                    assert np.abs(t2 - t).max() < 1e-6
                    assert np.abs(rho2 - rho).max() < 1e-3
                    assert np.abs(ecef_to_geodetic(p)[2] - h).max() < 1e-3


def test_targets_near_the_pole():
    tr = make_truth(92.4, n_dense=2)  # track reaches 87.6 deg: a target 2.5 deg off-track crosses the pole
    sv = tr.sv.to_ecef()
    t = np.linspace(sv.span[0] + 500, sv.span[1] - 500, 801)
    best = None
    for side in ("right", "left"):
        lat = ecef_to_geodetic(G.geolocate(sv, t, 8.5e5, LAM, 0.0, 5000.0, side))[0]
        k = int(np.argmax(np.abs(lat)))
        if best is None or abs(lat[k]) > best[0]:
            best = (abs(lat[k]), t[k], side)
    assert best[0] > 89.5
    p = G.geolocate(sv, best[1], 8.5e5, LAM, 0.0, 5000.0, best[2])
    t2, rho2 = G.doppler_time(sv, p)
    assert abs(t2 - best[1]) < 1e-6 and abs(rho2 - 8.5e5) < 1e-3
    lat_deg, _, h2 = G.geolocate_geodetic(sv, best[1], 8.5e5, LAM, 0.0, 5000.0, best[2])
    assert abs(lat_deg) == pytest.approx(best[0]) and h2 == pytest.approx(5000.0, abs=1e-4)


def test_doppler_time_outside_span_is_an_error(ecef_truth):
    short = StateVectors(ecef_truth.time[:6], ecef_truth.position[:6], ecef_truth.velocity[:6], "ECEF", EPOCH)
    r, v, _ = short.interpolate(short.span[0] + 1.0)
    p = G.target_from_doppler(r, v, 9e5, LAM, fdc=0.0)
    assert abs(G.doppler_time(short, p)[0] - (short.span[0] + 1.0)) < 1e-6
    r0, v0, _ = short.interpolate(short.span)  # zero-Doppler exactly at the first and the last vector
    p0 = G.target_from_doppler(r0, v0, 9e5, LAM, fdc=0.0)
    assert np.abs(G.doppler_time(short, p0)[0] - np.array(short.span)).max() < 1e-6
    with pytest.raises(GeometryError, match="1 target.* no zero-Doppler time"):
        G.doppler_time(short, np.stack([p, p - 50 * v]))  # the second: 50 s before the first vector
    with pytest.raises(GeometryError, match="wavelength"):
        G.doppler_time(short, p, fdc=100.0)


def test_multi_pass_target_takes_the_pass_nearest_the_guess(ecef_truth):
    """A span longer than a revolution sees a high-latitude target on two passes."""
    tt = np.linspace(ecef_truth.span[0] + 100.0, ecef_truth.span[0] + 800.0, 71)
    t = tt[np.argmax(np.abs(ecef_to_geodetic(ecef_truth.interpolate(tt)[0])[0]))]  # highest latitude
    r, v, _ = ecef_truth.interpolate(t)
    assert abs(ecef_to_geodetic(r)[0]) > 75
    p = G.target_from_doppler(r, v, 9e5, LAM, fdc=0.0)
    t_a, _ = G.doppler_time(ecef_truth, p, t_guess=t)
    t_b, _ = G.doppler_time(ecef_truth, p, t_guess=t + 6000.0)
    assert abs(t_a - t) < 1e-6 and abs(t_b - t - 6040) < 200


def test_plane_solve_at_nadir_range(ecef_truth):
    """Slant range equal to the nadir distance: the in-plane solve returns the nadir (look 0)."""
    _, r, v, _ = _states(ecef_truth, 4)
    p0, rho0 = G.target_from_look(r, v, 0.0)
    assert np.abs(G.look_from_slant_range(r, v, rho0)).max() < 1e-5
    with pytest.raises(GeometryError, match="no target on the Earth"):
        G.look_from_slant_range(r, v, rho0 - 1.0)


def test_look_incidence_range_relations(ecef_truth):
    _, r, v, _ = _states(ecef_truth, 5)
    look = np.radians(np.array([10.0, 20.0, 30.0, 40.0, 50.0]))
    inc = G.incidence_from_look(r, v, look)
    assert np.all(inc > look)  # Earth curvature
    assert np.abs(G.look_from_incidence(r, v, inc) - look).max() < 1e-12
    rho = G.slant_range_from_look(r, v, look)
    assert np.abs(G.look_from_slant_range(r, v, rho) - look).max() < 1e-12
    with pytest.raises(GeometryError, match="incidence"):
        G.look_from_incidence(r, v, np.radians(95.0))


def test_spherical_formulas_exact_in_the_equatorial_plane():
    """For an equatorial satellite the cross-track plane cuts the ellipsoid in a circle of radius a(+h):
    the spherical formulas of [Koh2003, §4] must then agree with the ellipsoid solve to rounding."""
    rs = 7_167_000.0
    r = np.array([rs, 0.0, 0.0])
    v = np.array([0.0, 7450.0, 0.0])  # flying east along the equator; cross-track plane = x-z plane? no:
    # the cross-track plane contains the nadir (-x) and the right-hand direction (-z for eastward flight)
    look = np.radians(np.array([5.0, 25.0, 45.0]))
    p, rho = G.target_from_look(r, v, look, h=0.0)
    assert np.abs(p[:, 1]).max() < 1e-6  # stays in the meridian plane y = 0 ...
    # ... which is NOT a circle: compare instead with a north-flying satellite (plane = equator)
    v = np.array([0.0, 0.0, 7450.0])
    p, rho = G.target_from_look(r, v, look, h=5000.0)
    re = 6_378_137.0 + 5000.0
    inc = G.sphere_incidence_from_look(look, re, rs)
    assert np.abs(inc - G.incidence_angle(np.broadcast_to(r, p.shape), p)).max() < 1e-10
    assert np.abs(G.sphere_slant_range(inc, re, rs) - rho).max() < 1e-6
    with pytest.raises(GeometryError, match="horizon"):
        G.sphere_incidence_from_look(np.radians(80.0), re, rs)


@pytest.mark.parametrize("scale", [0.0, 1.0, 100.0])
def test_doppler_from_attitude_is_the_beam_doppler(polar_truth, scale):
    """[Koh2003, eq. 4-6]: fdc = (2/lam) v_rel . L, with L the beam that reaches slant range rho
    (ECI, v_rel = v - w x r)."""
    sv = polar_truth.sv
    t = np.array([500.0, 2500.0, 4500.0])
    r, v, _ = sv.interpolate(t)
    pitch, yaw = scale * RS1_PITCH, scale * RS1_YAW
    look = np.radians(np.array([22.0, 31.0, 44.0]))
    _, rho = G.target_from_look(r, v, look, pitch=pitch, yaw=yaw, h=300.0)
    L = beam_vector(r, v, look, pitch, yaw)
    expect = 2 / LAM * np.sum(G.relative_velocity_eci(r, v) * L, -1)
    got = G.doppler_from_attitude(sv, t, rho, LAM, pitch, yaw, h=300.0)
    assert np.abs(got - expect).max() < 1e-6
    if scale == 0:  # zero attitude in ECI: only the Earth rotation's Doppler remains (kHz at C band)
        assert np.all(np.abs(got) > 100.0)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 6720.0), st.floats(0.2, 1.0), st.floats(-5000.0, 5000.0), st.floats(-300.0, 8000.0),
       st.sampled_from(["right", "left"]))
def test_property_geolocation_constraints_and_inverse(t, look, fdc, h, side):
    """Any time, look (11-57 deg), Doppler and height: the geolocated point has that range, Doppler and
    height, lies on the requested side, and its Doppler time is t again."""
    sv = _PROP_SV
    r, v, _ = sv.interpolate(t)
    rho = float(G.slant_range_from_look(r, v, look, side, h))
    p = G.geolocate(sv, t, rho, LAM, fdc, h, side)
    assert abs(np.linalg.norm(p - r) - rho) < 1e-6
    assert abs(G.doppler_hz(r, v, p, LAM) - fdc) < 1e-6
    assert abs(ecef_to_geodetic(p)[2] - h) < 1e-4
    assert np.sign((p - r) @ flight_frame(r, v)[:, 1]) == (1 if side == "right" else -1)
    t2, rho2 = G.doppler_time(sv, p, LAM, fdc, t_guess=t)
    assert abs(t2 - t) < 1e-6 and abs(rho2 - rho) < 1e-3


_PROP_SV = make_truth(98.6, n_dense=2).sv.to_ecef()
