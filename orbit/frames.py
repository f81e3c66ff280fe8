"""Earth frames: ECI (true equator, mean equinox of date, "GMST frame") <-> ECEF (WGS-84).

Model: a single rotation about Z by the Greenwich mean sidereal angle theta(t) (IAU-1982 GMST with
UT1 = UTC). This is the model the Radarsat-1 CEOS product implies: its state vectors are "inertial"
and the platform-position record gives a Greenwich mean hour angle at the first vector, i.e. the
vectors are rotated into the Earth-fixed frame by that angle plus the sidereal rate (ISCE and ASF
MapReady do exactly this). Precession-nutation and polar motion are ignored; their size at the
ground is measured against astropy in the tests and reported in the README.

    r_ecef = Rz(theta) r_eci,  v_ecef = Rz(theta) v_eci - w x r_ecef,  w = (0, 0, OMEGA_EARTH)
    Rz(theta) = [[cos, sin, 0], [-sin, cos, 0], [0, 0, 1]]
"""

from __future__ import annotations

import numpy as np

from orbit.constants import OMEGA_EARTH
from orbit.timeutil import J2000_JD, SECONDS_PER_DAY, julian_date_parts


def gmst(epoch_utc: str, t: np.ndarray | float) -> np.ndarray:
    """Greenwich mean sidereal angle (rad, in [0, 2pi)) at ``t`` seconds after ``epoch_utc``.

    IAU-1982: GMST[s] = 67310.54841 + (876600 h + 8640184.812866) T + 0.093104 T^2 - 6.2e-6 T^3,
    T = Julian centuries of UT1 since J2000.
    """
    jd0, sod = julian_date_parts(epoch_utc)
    t = np.asarray(t, dtype=np.float64)
    # 876600 h * T in seconds is exactly the elapsed UT1 seconds since J2000 (one turn per day), which
    # only matters modulo a day: du0 is a whole number of days plus one half (J2000 is at noon), so
    # reduce it first. This keeps ~1e-11 s resolution instead of the 1.5e-8 s ulp of ~8e7 s.
    du0 = jd0 - J2000_JD
    secs = sod + t
    T = (du0 + secs / SECONDS_PER_DAY) / 36525.0
    g = 67310.54841 + np.mod(du0 * SECONDS_PER_DAY, SECONDS_PER_DAY) + secs
    g = g + (8640184.812866 + (0.093104 - 6.2e-6 * T) * T) * T
    g = np.mod(g, SECONDS_PER_DAY)
    return g * (2.0 * np.pi / SECONDS_PER_DAY)


def _rz(theta: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, s, z], -1), np.stack([-s, c, z], -1), np.stack([z, z, o], -1)], -2)


def eci_to_ecef(epoch_utc: str, t: np.ndarray, r: np.ndarray, v: np.ndarray | None = None,
                theta: np.ndarray | None = None):
    """Rotate ECI positions (..., 3) [and velocities] at times t to ECEF. Returns r or (r, v)."""
    th = gmst(epoch_utc, t) if theta is None else np.asarray(theta, np.float64)
    R = _rz(th)
    re = np.einsum("...ij,...j->...i", R, r)
    if v is None:
        return re
    w = np.array([0.0, 0.0, OMEGA_EARTH])
    ve = np.einsum("...ij,...j->...i", R, v) - np.cross(w, re)
    return re, ve


def ecef_to_eci(epoch_utc: str, t: np.ndarray, r: np.ndarray, v: np.ndarray | None = None,
                theta: np.ndarray | None = None):
    """Inverse of :func:`eci_to_ecef`."""
    th = gmst(epoch_utc, t) if theta is None else np.asarray(theta, np.float64)
    Rt = np.swapaxes(_rz(th), -1, -2)
    ri = np.einsum("...ij,...j->...i", Rt, r)
    if v is None:
        return ri
    w = np.array([0.0, 0.0, OMEGA_EARTH])
    vi = np.einsum("...ij,...j->...i", Rt, np.asarray(v) + np.cross(w, r))
    return ri, vi
