"""Scene geometry: targets on the ellipsoid or flat ground, target motion, range and Doppler truth.

Frames: the simulation frame is ECI (orbit scenes) or LOCAL (linear scenes). Targets are stored in
a TARGET frame: ECEF with ``earth_rotation`` (p_eci(t) = M(t) q(t), M(t) = Rz(theta(t))^T with the
GMST angle theta of ``orbit.frames``), ECI without it (inertial scene, M = I), LOCAL for linear
scenes (M = I). Target motion: q(t) = q_ref + u (t - t_ref) (``target_motion``; else u = 0).
Derivatives in the simulation frame (w = (0, 0, OMEGA_EARTH) with earth rotation, else 0):

    p' = w x p + M u,      p'' = w x (w x p) + 2 w x (M u)

Range and Doppler of a target seen from the platform state (r, v, a), d = p - r, R = |d|:

    R' = d.(p' - v)/R,  R'' = (|p' - v|^2 + d.(p'' - a) - R'^2)/R,
    f_dc = -(2/lam) R',  f_R = -(2/lam) R''                     (see notes/orbit-to-doppler-sim-focus)

(The seed's eq. 4-6 write f_dc = -(2/lam) v_rel.L; with our phase convention exp(-j 4 pi R/lam)
the sign is +(2/lam) v_rel.L = -(2/lam) R', which is what is used here.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from orbit.constants import OMEGA_EARTH, WGS84_A, WGS84_B
from orbit.frames import gmst
from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef
from orbit.pointing import ellipsoid_normal

_BISECT = 64


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


@dataclass
class Motion:
    """Target-frame -> simulation-frame mapping M(t) and its angular rate (module docstring)."""

    epoch_utc: str
    center_time_s: float
    earth_rotation: bool

    @property
    def omega(self) -> np.ndarray:
        return np.array([0.0, 0.0, OMEGA_EARTH if self.earth_rotation else 0.0])

    def rotation(self, t: np.ndarray) -> np.ndarray:
        """M(t) (..., 3, 3) for relative times t."""
        t = np.asarray(t, np.float64)
        if not self.earth_rotation:
            return np.broadcast_to(np.eye(3), t.shape + (3, 3)).copy()
        th = gmst(self.epoch_utc, self.center_time_s + t)
        c, s = np.cos(th), np.sin(th)
        z, o = np.zeros_like(c), np.ones_like(c)
        return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)

    def state(self, q_ref: np.ndarray, u: np.ndarray, t_ref: np.ndarray, t: np.ndarray):
        """(p, p', p'') in the simulation frame at relative times t (broadcast with the targets)."""
        t = np.asarray(t, np.float64)
        m = self.rotation(t)
        q = q_ref + u * (t - t_ref)[..., None]
        p = np.einsum("...ij,...j->...i", m, q)
        mu = np.einsum("...ij,...j->...i", m, u)
        w = np.broadcast_to(self.omega, p.shape)
        pd = np.cross(w, p) + mu
        pdd = np.cross(w, np.cross(w, p)) + 2.0 * np.cross(w, mu)
        return p, pd, pdd

    def to_target_frame(self, p_sim: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Simulation-frame positions at relative times t -> target frame (M^T p)."""
        return np.einsum("...ji,...j->...i", self.rotation(t), p_sim)


def range_derivatives(r, v, a, p, pd, pdd):
    """(R, R', R'') of targets (p, p', p'') seen from platform states (r, v, a)."""
    d = p - r
    dd = pd - v
    R = np.linalg.norm(d, axis=-1)
    Rd = _dot(d, dd) / R
    Rdd = (_dot(dd, dd) + _dot(d, pdd - a) - Rd * Rd) / R
    return R, Rd, Rdd


def surface_point(r: np.ndarray, n: np.ndarray, rho: np.ndarray, h: np.ndarray, toward: np.ndarray,
                  frame: str) -> np.ndarray:
    """Point(s) p with |p - r| = rho, (p - r).n = 0, on the surface at height h, on the side of ``toward``.

    Surface: WGS-84 ellipsoid at geodetic height h (ECI/ECEF; rotation about Z leaves it unchanged)
    or the plane z = h (LOCAL). The circle of radius rho about r in the plane normal to n is
    parametrized from its lowest point by the angle alpha in [0, pi/2] towards ``toward`` and the
    crossing is bisected (64 steps: float64-exact); geodetic height is then corrected with pyproj
    (3 rounds). NaN where the circle misses the surface (range shorter than the altitude or beyond
    the horizon). Arrays broadcast: r, n, toward (m, 3); rho, h (m,).
    """
    r, n, toward = (np.asarray(x, np.float64) for x in (r, n, toward))
    rho, h = np.broadcast_arrays(np.asarray(rho, np.float64), np.asarray(h, np.float64))
    r, n, toward = (np.broadcast_to(x, rho.shape + (3,)) for x in (r, n, toward))
    n = _unit(n)
    down = np.broadcast_to([0.0, 0.0, -1.0], r.shape) if frame == "LOCAL" else -_unit(r)
    e1 = _unit(down - _dot(down, n)[..., None] * n)
    e2 = np.cross(n, e1)
    e2 = np.where((_dot(e2, toward) < 0)[..., None], -e2, e2)

    def point(alpha):
        return r + rho[..., None] * (np.cos(alpha)[..., None] * e1 + np.sin(alpha)[..., None] * e2)

    def f(alpha, hh):
        p = point(alpha)
        if frame == "LOCAL":
            return p[..., 2] - hh
        return (p[..., 0] ** 2 + p[..., 1] ** 2) / (WGS84_A + hh) ** 2 + p[..., 2] ** 2 / (WGS84_B + hh) ** 2 - 1.0

    hh = h.copy()
    for _ in range(1 if frame == "LOCAL" else 4):
        lo = np.zeros_like(rho)
        hi = np.full_like(rho, np.pi / 2)
        ok = (f(lo, hh) < 0) & (f(hi, hh) > 0)
        for _ in range(_BISECT):
            mid = 0.5 * (lo + hi)
            neg = f(mid, hh) < 0
            lo = np.where(neg, mid, lo)
            hi = np.where(neg, hi, mid)
        p = point(0.5 * (lo + hi))
        p[~ok] = np.nan
        if frame != "LOCAL":
            good = np.isfinite(p[..., 0])
            if np.any(good):
                _, _, h_now = ecef_to_geodetic(p[good])
                hh[good] += h[good] - h_now
    return p


def enu_basis(p: np.ndarray, frame: str) -> np.ndarray:
    """(..., 3, 3) columns east, north, up at points p (LOCAL: x, y, z)."""
    if frame == "LOCAL":
        return np.broadcast_to(np.eye(3), p.shape[:-1] + (3, 3)).copy()
    up = ellipsoid_normal(p)
    east = _unit(np.cross(np.broadcast_to([0.0, 0.0, 1.0], up.shape), up))
    north = np.cross(up, east)
    return np.stack([east, north, up], axis=-1)


def snap_to_height(p: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Move ellipsoid-frame points along their geodetic normal to geodetic height h (pyproj)."""
    lat, lon, _ = ecef_to_geodetic(p)
    return geodetic_to_ecef(lat, lon, np.broadcast_to(h, lat.shape))


def closest_approach(traj, motion: Motion, q_ref, u, t_ref, iterations: int = 8):
    """Zero-Doppler (closest-approach) time (relative s) and range of each target: Newton on R R' = 0.

    Starts at the scene centre; clipped to the trajectory's valid span. Returns (t0, R0).
    """
    lo, hi = traj.span
    t = np.zeros(len(q_ref))
    for _ in range(iterations):
        r, v, a = traj.state(t)
        p, pd, pdd = motion.state(q_ref, u, t_ref, t)
        d, dd = p - r, pd - v
        f = _dot(d, dd)
        fp = _dot(dd, dd) + _dot(d, pdd - a)
        t = np.clip(t - f / fp, lo, hi)
    r, _, _ = traj.state(t)
    p, _, _ = motion.state(q_ref, u, t_ref, t)
    return t, np.linalg.norm(p - r, axis=-1)
