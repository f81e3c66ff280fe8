"""Precession-nutation (IAU 1976 / IAU 1980, truncated series): the "full" alternative to GMST-only.

Radarsat-1 vectors are taken to be in the GMST frame of date (``orbit.frames``: true equator, mean
equinox, "TEME"). If a product's vectors are instead mean-of-J2000 (EME2000) or true-of-date (TOD),
convert them to that frame first with the functions here; the ground error of NOT doing so is in the
README table (km for J2000, ~0.5 km for TOD in 2002). Formulas (SOFA/ERFA conventions, passive
rotations R1, R2, R3 as ``orbit.frames._rz``):

    P = R3(-z) R2(theta) R3(-zeta)                       IAU 1976 precession from J2000 (Lieske 1977)
    N = R1(-(eps0 + deps)) R3(-dpsi) R1(eps0)            nutation, eps0 = IAU 1980 mean obliquity
    r_TOD = N P r_J2000,   GAST = GMST + EE,  EE = dpsi cos(eps0) + 0.00264" sin(Om) + 0.000063" sin(2 Om)
    r_GMSTframe = R3(EE) r_TOD        (so that r_ECEF = R3(GMST) r_GMSTframe = R3(GAST) r_TOD)

dpsi, deps: the IAU 1980 series truncated to its ``N_TERMS`` largest terms (measured against ERFA's
full 106-term nut80 in the tests: <= 16 mas within +-8 years of J2000, i.e. < 0.5 m at the ground).
The ~23 mas frame bias between J2000 and the GCRS, polar motion and UT1-UTC are not modelled (see
``orbit.frames``).
Velocities are rotated with the same matrix: the precession/nutation rates (< 1e-11 rad/s) change
them by < 1e-4 m/s. T is Julian centuries since J2000 on the UTC scale (TT - UTC = 64 s in 2002 shifts
the angles by < 1e-4 arcsec).
"""

from __future__ import annotations

import numpy as np

from orbit.timeutil import J2000_JD, SECONDS_PER_DAY, julian_date_parts

AS2R = np.pi / (180.0 * 3600.0)  # arcseconds to radians

# IAU 1980 nutation, largest terms: multipliers of (l, l', F, D, Om), then dpsi (A + A1 T) and
# deps (B + B1 T) in units of 0.1 mas.
_NUT80 = np.array([
    [0, 0, 0, 0, 1, -171996.0, -174.2, 92025.0, 8.9],
    [0, 0, 2, -2, 2, -13187.0, -1.6, 5736.0, -3.1],
    [0, 0, 2, 0, 2, -2274.0, -0.2, 977.0, -0.5],
    [0, 0, 0, 0, 2, 2062.0, 0.2, -895.0, 0.5],
    [0, 1, 0, 0, 0, 1426.0, -3.4, 54.0, -0.1],
    [1, 0, 0, 0, 0, 712.0, 0.1, -7.0, 0.0],
    [0, 1, 2, -2, 2, -517.0, 1.2, 224.0, -0.6],
    [0, 0, 2, 0, 1, -386.0, -0.4, 200.0, 0.0],
    [1, 0, 2, 0, 2, -301.0, 0.0, 129.0, -0.1],
    [0, -1, 2, -2, 2, 217.0, -0.5, -95.0, 0.3],
    [1, 0, 0, -2, 0, -158.0, 0.0, -1.0, 0.0],
    [0, 0, 2, -2, 1, 129.0, 0.1, -70.0, 0.0],
    [-1, 0, 2, 0, 2, 123.0, 0.0, -53.0, 0.0],
    [1, 0, 0, 0, 1, 63.0, 0.1, -33.0, 0.0],
    [0, 0, 0, 2, 0, 63.0, 0.0, -2.0, 0.0],
    [-1, 0, 2, 2, 2, -59.0, 0.0, 26.0, 0.0],
    [-1, 0, 0, 0, 1, -58.0, -0.1, 32.0, 0.0],
    [1, 0, 2, 0, 1, -51.0, 0.0, 27.0, 0.0],
    [2, 0, 0, -2, 0, 48.0, 0.0, 1.0, 0.0],
    [-2, 0, 2, 0, 1, 46.0, 0.0, -24.0, 0.0],
])
N_TERMS = _NUT80.shape[0]


def centuries_since_j2000(epoch_utc: str, t) -> np.ndarray:
    """Julian centuries (UTC scale) since J2000.0 at ``t`` seconds after ``epoch_utc``."""
    jd0, sod = julian_date_parts(epoch_utc)
    return ((jd0 - J2000_JD) + (sod + np.asarray(t, np.float64)) / SECONDS_PER_DAY) / 36525.0


def mean_obliquity(T) -> np.ndarray:
    """IAU 1980 mean obliquity of the ecliptic (rad)."""
    T = np.asarray(T, np.float64)
    return (84381.448 + (-46.8150 + (-0.00059 + 0.001813 * T) * T) * T) * AS2R


def _fundamental_arguments(T) -> np.ndarray:
    """Delaunay arguments (l, l', F, D, Om) in rad, IAU 1980 expressions (stacked on the last axis)."""
    T = np.asarray(T, np.float64)
    turns = (1325.0, 99.0, 1342.0, 1236.0, -5.0)
    arcsec = ((485866.733, 715922.633, 31.310, 0.064), (1287099.804, 1292581.224, -0.577, -0.012),
              (335778.877, 295263.137, -13.257, 0.011), (1072261.307, 1105601.328, -6.891, 0.019),
              (450160.280, -482890.539, 7.455, 0.008))
    args = [(c0 + (c1 + (c2 + c3 * T) * T) * T) * AS2R + 2.0 * np.pi * np.fmod(n * T, 1.0)
            for n, (c0, c1, c2, c3) in zip(turns, arcsec, strict=True)]
    return np.stack(args, axis=-1)


def nutation(T) -> tuple[np.ndarray, np.ndarray]:
    """(dpsi, deps) in rad: IAU 1980 nutation in longitude and obliquity, truncated to N_TERMS terms."""
    T = np.asarray(T, np.float64)
    arg = _fundamental_arguments(T) @ _NUT80[:, :5].T  # (..., N_TERMS)
    Te = T[..., None]
    dpsi = np.sum((_NUT80[:, 5] + _NUT80[:, 6] * Te) * np.sin(arg), axis=-1)
    deps = np.sum((_NUT80[:, 7] + _NUT80[:, 8] * Te) * np.cos(arg), axis=-1)
    return dpsi * 1e-4 * AS2R, deps * 1e-4 * AS2R


def equation_of_equinoxes(T) -> np.ndarray:
    """GAST - GMST (rad), IAU 1994 form with the two Moon-node terms."""
    dpsi, _ = nutation(T)
    om = _fundamental_arguments(T)[..., 4]
    return dpsi * np.cos(mean_obliquity(T)) + (0.00264 * np.sin(om) + 0.000063 * np.sin(2.0 * om)) * AS2R


def _r1(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, s], -1), np.stack([z, -s, c], -1)], -2)


def _r2(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, z, -s], -1), np.stack([z, o, z], -1), np.stack([s, z, c], -1)], -2)


def _r3(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, s, z], -1), np.stack([-s, c, z], -1), np.stack([z, z, o], -1)], -2)


def precession_matrix(T) -> np.ndarray:
    """IAU 1976 precession matrix P (..., 3, 3), J2000 mean -> mean of date."""
    t = np.asarray(T, np.float64)
    zeta = (2306.2181 + (0.30188 + 0.017998 * t) * t) * t * AS2R
    z = (2306.2181 + (1.09468 + 0.018203 * t) * t) * t * AS2R
    theta = (2004.3109 + (-0.42665 - 0.041833 * t) * t) * t * AS2R
    return _r3(-z) @ _r2(theta) @ _r3(-zeta)


def nutation_matrix(T) -> np.ndarray:
    """Nutation matrix N (..., 3, 3), mean of date -> true of date."""
    eps0 = mean_obliquity(T)
    dpsi, deps = nutation(T)
    return _r1(-(eps0 + deps)) @ _r3(-dpsi) @ _r1(eps0)


def _rotate(M, r, v):
    out_r = np.einsum("...ij,...j->...i", M, np.asarray(r, np.float64))
    if v is None:
        return out_r
    return out_r, np.einsum("...ij,...j->...i", M, np.asarray(v, np.float64))


def j2000_to_eci_matrix(epoch_utc: str, t) -> np.ndarray:
    """M (..., 3, 3) with r_ECI(GMST frame of date) = M r_J2000: R3(EE) N P."""
    T = centuries_since_j2000(epoch_utc, t)
    return _r3(equation_of_equinoxes(T)) @ nutation_matrix(T) @ precession_matrix(T)


def j2000_to_eci(epoch_utc: str, t, r, v=None):
    """Mean-of-J2000 (EME2000) vectors at times t -> the GMST ECI frame of ``orbit.frames``."""
    return _rotate(j2000_to_eci_matrix(epoch_utc, t), r, v)


def eci_to_j2000(epoch_utc: str, t, r, v=None):
    """Inverse of :func:`j2000_to_eci`."""
    return _rotate(np.swapaxes(j2000_to_eci_matrix(epoch_utc, t), -1, -2), r, v)


def tod_to_eci(epoch_utc: str, t, r, v=None):
    """True-of-date (true equator and equinox, GAST) vectors -> the GMST ECI frame: R3(EE)."""
    return _rotate(_r3(equation_of_equinoxes(centuries_since_j2000(epoch_utc, t))), r, v)
