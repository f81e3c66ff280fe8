"""ECI <-> ECEF (GMST) and the precession-nutation alternative, against ERFA and astropy (independent).

Documented model differences: our ECI frame is astropy's TEME; GMST is computed with UT1 = UTC and
polar motion is ignored. With astropy's own UT1-UTC and polar motion applied to our result the two
must agree to < 1 mm; without them the difference is bounded by those two terms. The J2000 path
(IAU 1976/1980, 20 nutation terms, no frame bias) agrees with astropy's GCRS -> ITRS to < 1.5 m at
orbit radius (frame bias 23 mas + truncated nutation <= 16 mas + IAU 2006/2000A differences).
"""

from __future__ import annotations

import numpy as np
import pytest

from orbit import precession as P
from orbit.frames import ecef_to_eci, eci_to_ecef, gmst
from orbit.timeutil import add_seconds, julian_date_parts

EPOCH = "2002-06-16T15:41:00Z"
SECS = np.array([0.0, 3000.0, 40 * 86400.0])


@pytest.fixture(scope="module")
def astro():
    """astropy with its bundled IERS-B tables only (no downloads), at the test times."""
    pytest.importorskip("astropy")
    from astropy.utils import iers

    iers.conf.auto_download = False
    import astropy.units as u
    from astropy.time import Time

    t = Time(EPOCH.rstrip("Z"), scale="utc") + SECS * u.s
    xp, yp = iers.IERS_Auto.open().pm_xy(t)
    return {"t": t, "u": u, "dut1": np.asarray(t.delta_ut1_utc, float), "xp": xp.to_value(u.rad),
            "yp": yp.to_value(u.rad)}


def _points(n=3, radius=7e6, seed=0):
    r = np.random.default_rng(seed).normal(size=(n, 3))
    return r / np.linalg.norm(r, axis=1)[:, None] * radius


def _ours_with_eop(astro, r_eci):
    """Our GMST rotation evaluated on UT1, then astropy's polar motion W: the full TEME -> ITRS chain."""
    import erfa

    rot = np.array([eci_to_ecef(add_seconds(EPOCH, d), s, rr) for d, s, rr in zip(astro["dut1"], SECS, r_eci,
                                                                                   strict=True)])
    W = erfa.pom00(astro["xp"], astro["yp"], np.zeros_like(astro["xp"]))
    return np.einsum("nij,nj->ni", W, rot)


def _astropy(astro, frame_name, r):
    from astropy.coordinates import GCRS, ITRS, TEME, CartesianRepresentation

    frame = {"TEME": TEME, "GCRS": GCRS}[frame_name]
    c = frame(CartesianRepresentation(r.T * astro["u"].m), obstime=astro["t"])
    return c.transform_to(ITRS(obstime=astro["t"])).cartesian.xyz.to_value(astro["u"].m).T


def test_gmst_matches_erfa_gmst82():
    erfa = pytest.importorskip("erfa")
    jd0, sod = julian_date_parts(EPOCH)
    t = np.linspace(-2e6, 2e6, 101)
    assert np.abs(gmst(EPOCH, t) - erfa.gmst82(jd0, (sod + t) / 86400.0)).max() < 1e-12


def test_our_eci_is_astropy_teme_up_to_ut1_and_polar_motion(astro):
    r = _points()
    raw = np.linalg.norm(eci_to_ecef(EPOCH, SECS, r) - _astropy(astro, "TEME", r), axis=1)
    # bound of the two neglected terms at this radius: rotation by w*dUT1 and by the pole offset
    bound = 7e6 * (7.2921158553e-5 * np.abs(astro["dut1"]) + np.hypot(astro["xp"], astro["yp"]))
    assert np.all(raw <= bound) and np.all(raw > 1.0)  # the terms are real (tens of metres) ...
    full = np.linalg.norm(_ours_with_eop(astro, r) - _astropy(astro, "TEME", r), axis=1)
    assert full.max() < 3e-4  # ... and they are the ONLY difference (README: <= 0.2 mm)


def test_j2000_path_matches_astropy_gcrs(astro):
    r = _points(seed=1)
    ours = _ours_with_eop(astro, P.j2000_to_eci(EPOCH, SECS, r))
    diff = np.linalg.norm(ours - _astropy(astro, "GCRS", r), axis=1)
    assert diff.max() < 1.0  # README: < 0.75 m (IAU-80 nutation truncated to 20 terms)
    # treating J2000 vectors as if they were the GMST frame is wrong by kilometres in 2002
    wrong = np.linalg.norm(_ours_with_eop(astro, r) - _astropy(astro, "GCRS", r), axis=1)
    assert wrong.min() > 500.0


def test_precession_nutation_against_erfa():
    erfa = pytest.importorskip("erfa")
    jd0, sod = julian_date_parts(EPOCH)
    days = np.array([-3000.0, 0.0, 100.0, 3000.0])
    T = P.centuries_since_j2000(EPOCH, days * 86400.0)
    for k, d in enumerate(days):
        jd2 = sod / 86400.0 + d
        assert np.abs(P.precession_matrix(T[k]) - erfa.pmat76(jd0, jd2)).max() < 1e-14
        assert P.mean_obliquity(T[k]) == pytest.approx(erfa.obl80(jd0, jd2), abs=1e-15)
        dpsi, deps = erfa.nut80(jd0, jd2)
        mine = P.nutation(T[k])
        mas = P.AS2R * 1e-3
        assert abs(mine[0] - dpsi) < 20 * mas and abs(mine[1] - deps) < 5 * mas  # truncation: 20 terms
        assert abs(P.equation_of_equinoxes(T[k]) - erfa.eqeq94(jd0, jd2)) < 20 * mas
        assert np.abs(P.nutation_matrix(T[k]) @ P.precession_matrix(T[k]) - erfa.pnm80(jd0, jd2)).max() < 20 * mas


def test_round_trips_and_velocity_transport():
    r = _points(4)
    v = np.cross([0, 0, 1.0], r) * 1e-3 + 10.0
    t = np.array([0.0, 10.0, 1e4, 1e6])
    re, ve = eci_to_ecef(EPOCH, t, r, v)
    ri, vi = ecef_to_eci(EPOCH, t, re, ve)
    assert np.abs(ri - r).max() < 1e-8 and np.abs(vi - v).max() < 1e-11
    rj, vj = P.eci_to_j2000(EPOCH, t, r, v)
    rb, vb = P.j2000_to_eci(EPOCH, t, rj, vj)
    assert np.abs(rb - r).max() < 1e-8 and np.abs(vb - v).max() < 1e-11
    # ECEF velocity = time derivative of the ECEF position of a uniformly moving ECI point
    dt = 0.1  # rounding of t ~ 1e6 s limits the angle to ~1e-14 rad: keep the step long enough
    num = (eci_to_ecef(EPOCH, t + dt, r + v * dt) - eci_to_ecef(EPOCH, t - dt, r - v * dt)) / (2 * dt)
    assert np.abs(num - ve).max() < 1e-6
    # true-of-date differs from the GMST frame by the equation of equinoxes only (a Z rotation)
    rt = P.tod_to_eci(EPOCH, t, r)
    assert np.allclose(rt[:, 2], r[:, 2]) and np.allclose(np.linalg.norm(rt, axis=1), np.linalg.norm(r, axis=1))
