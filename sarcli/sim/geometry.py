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

([Koh2003, eq. 4-6] write f_dc = -(2/lam) v_rel.L; with our phase convention exp(-j 4 pi R/lam)
the sign is +(2/lam) v_rel.L = -(2/lam) R', which is what is used here.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from orbit.constants import OMEGA_EARTH
from orbit.errors import GeometryError
from orbit.frames import gmst
from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef
from orbit.geometry import target_in_plane
from orbit.pointing import ellipsoid_normal, side_sign


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


def surface_point(r: np.ndarray, n: np.ndarray, rho: np.ndarray, h: float, side: str, frame: str) -> np.ndarray:
    """Point(s) p with |p - r| = rho, (p - r).n = 0 on the surface at height h, on the looking ``side``.

    Ellipsoid frames (ECI or ECEF: the WGS-84 surface is symmetric about Z) use
    ``orbit.geometry.target_in_plane`` (exact geodetic height). LOCAL: the plane z = h in closed form,
    p = r + rho (cos(a) e1 + sin(a) e2) with e1 the downward direction in the plane and e2 towards the
    side, a in [0, pi/2] solving r_z + rho (cos(a) e1_z + sin(a) e2_z) = h. ``rho`` is (m,) increasing
    (or a single value), r and n (3,). NaN rows where the range does not reach the surface.
    """
    r = np.asarray(r, np.float64)
    n = _unit(np.asarray(n, np.float64))
    rho = np.atleast_1d(np.asarray(rho, np.float64))
    if frame == "LOCAL":
        down = np.array([0.0, 0.0, -1.0])
        e1 = _unit(down - (down @ n) * n)
        e2 = side_sign(side) * np.cross(e1, n)
        amp = np.hypot(e1[2], e2[2])
        phi0 = np.arctan2(e2[2], e1[2])
        with np.errstate(invalid="ignore"):
            d = np.arccos((h - r[2]) / (rho * amp))
        best = np.full(rho.shape, np.nan)
        for cand in (np.mod(phi0 + d, 2 * np.pi), np.mod(phi0 - d, 2 * np.pi)):
            ok = (cand <= np.pi / 2 + 1e-12) & np.isnan(best)
            best = np.where(ok, cand, best)
        return r + rho[:, None] * (np.cos(best)[:, None] * e1 + np.sin(best)[:, None] * e2)

    def solve(sl):
        return target_in_plane(r, n, 0.0, rho[sl], side=side, h=h)

    def valid(i):
        try:
            solve(slice(i, i + 1))
            return True
        except GeometryError:
            return False

    out = np.full((rho.size, 3), np.nan)
    try:
        return solve(slice(None))
    except GeometryError:
        pass
    # the valid ranges form one interval [nadir, horizon]: bracket it by bisection, then solve it at once
    inside = [i for i in (0, rho.size // 2, rho.size - 1) if valid(i)]
    if not inside:
        return out
    lo_ok, hi_ok = inside[0], inside[-1]
    lo, hi = 0, lo_ok
    while lo < hi:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if valid(mid) else (mid + 1, hi)
    first = lo
    lo, hi = hi_ok, rho.size - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        lo, hi = (mid, hi) if valid(mid) else (lo, mid - 1)
    out[first:lo + 1] = solve(slice(first, lo + 1))
    return out


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
