"""Ellipsoid geometry: targets from range + Doppler (or look plane) + ellipsoid, look/incidence/range,
Doppler of a fixed target, zero-/given-Doppler time, geolocation. See [Koh2003, §2-3].

Frames and conventions
    Satellite position r, velocity v and target p are in ONE Cartesian frame. For a target fixed on the
    Earth use ECEF (then v is already the velocity relative to the rotating Earth, the v_rel of [Koh2003, eq. 4]), or
    ECI with v replaced by ``relative_velocity_eci(r, v)`` = v - w x r ([Koh2003, eq. 5], whose printed vector
    is garbled). Angles in radians, lengths in m, times in s after the state vectors' epoch.
Doppler sign (phase exp(-j*4*pi*R/lam), R = |p - r|):
    f_D = -(2/lam) dR/dt = (2/lam) v . (p - r)/R        (positive when the beam looks forward)
    f_R = -(2/lam) d2R/dt2,  d2R/dt2 = (|v|^2 - a.(p - r))/R - (v.(p - r))^2/R^3
    [Koh2003, eq. 4]'s "fdc = -(2/lam) v_rel . L" has the opposite sign; it contradicts the phase
    convention and the paper's own (eq. 9) f_R = -(2/lam) d2R/deta2, so it is a sign typo.
Surfaces of height h
    Solves first use the ellipsoid with semi-axes (a + h, b + h), then correct the offset with the true
    geodetic height of the solution (pyproj) until it is within 0.1 mm of h: exact heights, not the
    (a + h, b + h) approximation (off by up to 7 mm at h = 5 km, 11 mm at 8 km; see the tests).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from orbit.constants import OMEGA_EARTH, WGS84_A, WGS84_B
from orbit.errors import GeometryError
from orbit.geodetic import ecef_to_geodetic
from orbit.pointing import (
    along_track_axis,
    beam_vector,
    ellipsoid_normal,
    flight_frame,
    look_vector_control,
    side_sign,
)
from orbit.statevectors import StateVectors

_HEIGHT_TOL_M = 1e-4
_NADIR_TOL = 1e-12  # |G| below this at the nadir-most direction (~6 um) counts as a nadir solution
_MAX_HEIGHT_ITER = 8


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _norm(a):
    return np.linalg.norm(a, axis=-1)


def relative_velocity_eci(r_eci, v_eci) -> np.ndarray:
    """v - w x r: ECI satellite velocity relative to the rotating Earth ([Koh2003, eq. 5], corrected)."""
    r = np.asarray(r_eci, np.float64)
    v = np.asarray(v_eci, np.float64)
    return v - np.cross(np.array([0.0, 0.0, OMEGA_EARTH]), r)


def doppler_hz(r, v, p, wavelength: float) -> np.ndarray:
    """Doppler (Hz) of a target p seen from (r, v): (2/lam) v.(p - r)/|p - r| (see module notes)."""
    d = np.asarray(p, np.float64) - np.asarray(r, np.float64)
    return 2.0 / wavelength * _dot(np.asarray(v, np.float64), d) / _norm(d)


def doppler_rate_hz_per_s(r, v, a, p, wavelength: float) -> np.ndarray:
    """Doppler rate (Hz/s) of a fixed target: -(2/lam) d2R/dt2 (negative for a side-looking radar)."""
    d = np.asarray(p, np.float64) - np.asarray(r, np.float64)
    R = _norm(d)
    vd = _dot(v, d)
    r2 = (_dot(v, v) - _dot(a, d)) / R - vd * vd / R**3
    return -2.0 / wavelength * r2


def _on_height_surface(solve: Callable[[float | np.ndarray], np.ndarray], h) -> np.ndarray:
    """Run ``solve(dh)`` (a solve on the ellipsoid (a + dh, b + dh)) and adjust dh until the solution's
    geodetic height equals h to 0.1 mm."""
    h = np.asarray(h, np.float64)
    dh = h.copy()
    for _ in range(_MAX_HEIGHT_ITER):
        p = solve(dh)
        err = h - ecef_to_geodetic(p)[2]
        if np.all(np.abs(err) < _HEIGHT_TOL_M):
            return p
        dh = dh + err
    raise GeometryError(f"height iteration did not converge (residual {np.max(np.abs(err)):.3g} m)")


def _ray_ellipsoid(r, L, dh) -> np.ndarray:
    """Range s > 0 to the first intersection of r + s L (L unit) with the ellipsoid (a+dh, b+dh); NaN if none."""
    A = WGS84_A + dh
    B = WGS84_B + dh
    sc = np.stack(np.broadcast_arrays(1.0 / A, 1.0 / A, 1.0 / B), axis=-1)
    rs, Ls = r * sc, L * sc
    qa = _dot(Ls, Ls)
    qb = _dot(rs, Ls)
    qc = _dot(rs, rs) - 1.0
    disc = qb * qb - qa * qc
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
        s = qc / (-qb + root)  # = (-qb - root)/qa, without cancellation when qb < 0
    return np.where((disc >= 0) & (qb < 0) & (qc > 0), s, np.nan)


def horizon_look_angle(r, v, side: str = "right", h=0.0) -> np.ndarray:
    """Largest look angle (rad, from geodetic nadir, zero pitch/yaw) that still hits the surface of height h."""
    r = np.asarray(r, np.float64)
    Q = flight_frame(r, v)
    lo = np.zeros(r.shape[:-1])
    hi = np.full(r.shape[:-1], np.pi / 2)
    for _ in range(60):  # bisection to ~1e-18 rad on [0, pi/2]
        mid = 0.5 * (lo + hi)
        L = np.einsum("...ij,...j->...i", Q, look_vector_control(mid, side))
        hit = np.isfinite(_ray_ellipsoid(r, L, np.asarray(h, np.float64)))
        lo = np.where(hit, mid, lo)
        hi = np.where(hit, hi, mid)
    return lo


def target_from_look(r, v, look, side: str = "right", pitch=0.0, yaw=0.0, h=0.0, exact: bool = True):
    """Target (ECEF-like, same frame as r) where the beam (look angle, attitude, side) meets height h.

    Returns (p (..., 3), slant range (...)). A look that misses the Earth raises :class:`GeometryError`.
    Look angle 0 is the geodetic nadir (the sub-satellite point).
    """
    r = np.asarray(r, np.float64)
    L = beam_vector(r, v, look, pitch, yaw, side, exact)
    rr = np.broadcast_to(r, L.shape)
    s0 = _ray_ellipsoid(rr, L, np.asarray(h, np.float64))
    if not np.all(np.isfinite(s0)):
        raise GeometryError(
            f"look angle {np.degrees(np.max(np.where(np.isfinite(s0), -np.inf, look))):.4f} deg misses the "
            f"Earth (horizon at {np.degrees(np.min(horizon_look_angle(rr, v, side, h))):.4f} deg)")
    p = _on_height_surface(lambda dh: rr + _ray_ellipsoid(rr, L, dh)[..., None] * L, h)
    return p, _norm(p - rr)


def _plane_solve(r, n_hat, alpha, rho, e1, e2, dh) -> np.ndarray:
    """Point r + rho u, u = alpha n + k (cos b e1 + sin b e2), k = sqrt(1 - alpha^2), on the ellipsoid (a+dh, b+dh).

    Newton on g(b) = G(r + rho u(b)), G = (x^2+y^2)/A^2 + z^2/B^2 - 1, safeguarded by the bracket
    [0, pi/2] (g < 0 at the nadir-most direction, g > 0 horizontally) with bisection when a Newton step
    leaves it. Raises if the root is the far (exit) intersection or the iteration does not converge.
    """
    A = WGS84_A + dh
    B = WGS84_B + dh
    inv2 = np.stack(np.broadcast_arrays(1.0 / A**2, 1.0 / A**2, 1.0 / B**2), axis=-1)
    k = np.sqrt(1.0 - alpha**2)

    def point(beta):
        return r + rho[..., None] * (alpha[..., None] * n_hat
                                     + k[..., None] * (np.cos(beta)[..., None] * e1 + np.sin(beta)[..., None] * e2))

    def g_and_slope(beta):
        p = point(beta)
        g = _dot(p * p, inv2) - 1.0
        du = k[..., None] * (-np.sin(beta)[..., None] * e1 + np.cos(beta)[..., None] * e2)
        return g, _dot(2.0 * p * inv2, rho[..., None] * du)

    lo = np.zeros(rho.shape)
    hi = np.full(rho.shape, np.pi / 2)
    g_lo, _ = g_and_slope(lo)
    g_hi, _ = g_and_slope(hi)
    if np.any(g_lo > _NADIR_TOL) or np.any(g_hi <= 0):
        raise GeometryError(
            f"no target on the Earth at slant range {np.min(rho):.3f}..{np.max(rho):.3f} m from this "
            "position: the range is shorter than the distance to the surface or the Doppler/look plane "
            "does not reach it")
    # spherical start: law of cosines with the local radii
    rs = _norm(r)
    re = rs - ecef_to_geodetic(r)[2] + dh
    rho_in = rho * k
    cosb = np.clip((rs**2 + rho_in**2 - re**2) / (2.0 * rs * rho_in), -1.0, 1.0)
    beta = np.where(g_lo >= 0, 0.0, np.clip(np.arccos(cosb), 0.0, np.pi / 2))  # g_lo ~ 0: the nadir itself
    for _ in range(100):
        g, dg = g_and_slope(beta)
        lo = np.where(g < 0, beta, lo)
        hi = np.where(g > 0, beta, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            nb = beta - g / dg
        bad = ~np.isfinite(nb) | (nb <= lo) | (nb >= hi)
        nb = np.where(bad, 0.5 * (lo + hi), nb)
        step = np.abs(nb - beta) * rho
        beta = nb
        if np.all((step < 1e-7) | (g == 0)):
            break
    else:
        raise GeometryError("target solve did not converge (100 iterations)")
    p = point(beta)
    if np.any(_dot(p * inv2, p - r) > 0):  # outward normal . (p - r) > 0: the line of sight EXITS at p
        raise GeometryError(
            f"slant range up to {np.max(rho):.3f} m reaches beyond the horizon (the solution would be on the "
            "far side of the Earth)")
    return p


def target_in_plane(r, n, c, rho, side: str = "right", h=0.0) -> np.ndarray:
    """Target p with n.(p - r) = c, |p - r| = rho, geodetic height h, on the given side of the plane's normal.

    ``n`` is the plane normal (along track: the relative velocity for a Doppler plane, the control
    frame's x-axis for the look plane of [Koh2003, §3.1]). "right" means towards n_hat x ... i.e. the side of
    Yf = nadir x n. All inputs broadcast; returns (..., 3). Raises :class:`GeometryError` if no such
    point exists (range too short, Doppler too large for the range, beyond the horizon).
    """
    r = np.asarray(r, np.float64)
    n = np.asarray(n, np.float64)
    rho = np.asarray(rho, np.float64)
    c = np.asarray(c, np.float64)
    shape = np.broadcast_shapes(r.shape[:-1], n.shape[:-1], rho.shape, c.shape, np.shape(h))
    r = np.broadcast_to(r, shape + (3,))
    n = np.broadcast_to(n, shape + (3,))
    rho = np.broadcast_to(rho, shape).astype(np.float64)
    if np.any(~np.isfinite(rho)) or np.any(rho <= 0):
        raise GeometryError("slant range must be positive and finite")
    nn = _norm(n)
    if np.any(nn == 0):
        raise GeometryError("plane normal (velocity) is zero")
    n_hat = n / nn[..., None]
    alpha = np.broadcast_to(c / (rho * nn), shape)
    if np.any(np.abs(alpha) >= 1):
        raise GeometryError("Doppler/plane offset is too large for the slant range (|cos| >= 1)")
    down = -ellipsoid_normal(r)
    e1 = down - _dot(down, n_hat)[..., None] * n_hat
    e1 = e1 / _norm(e1)[..., None]
    e2 = side_sign(side) * np.cross(e1, n_hat)

    return _on_height_surface(lambda dh: _plane_solve(r, n_hat, alpha, rho, e1, e2, np.broadcast_to(dh, shape)),
                              np.broadcast_to(np.asarray(h, np.float64), shape))


def target_from_doppler(r, v, rho, wavelength: float, fdc=0.0, side: str = "right", h=0.0) -> np.ndarray:
    """Target at slant range rho and Doppler fdc (Hz) on the surface of height h; r, v in ECEF.

    fdc = (2/lam) v.(p - r)/rho  <=>  v.(p - r) = lam fdc rho / 2: a plane with normal v.
    """
    rho = np.asarray(rho, np.float64)
    return target_in_plane(r, v, 0.5 * wavelength * np.asarray(fdc, np.float64) * rho, rho, side, h)


def target_from_look_plane(r, v, rho, pitch=0.0, yaw=0.0, side: str = "right", h=0.0,
                           exact: bool = True) -> np.ndarray:
    """Solve of [Koh2003, §3.1]: |p - r| = rho, p on the surface, (p - r).w = 0, w the control along-track axis."""
    return target_in_plane(r, along_track_axis(r, v, pitch, yaw, exact), 0.0, rho, side, h)


def doppler_from_attitude(sv: StateVectors, t, rho, wavelength: float, pitch=0.0, yaw=0.0, side: str = "right",
                          h=0.0, exact: bool = True) -> np.ndarray:
    """Geometric Doppler centroid (Hz) of the beam centre ([Koh2003, eq. 4-6], its "fdc_orbit").

    At azimuth time(s) t: the target at slant range rho on the surface of height h in the control
    frame's look plane (flight frame of the state vectors' own frame; [Koh2003] uses ECI, where zero
    attitude means a beam perpendicular to the INERTIAL velocity), then
    fdc = (2/lam) v_rel . (p - r)/rho with v_rel = v - w x r in ECI (v in ECEF).
    """
    if sv.frame == "LOCAL":
        raise GeometryError("geometric Doppler needs ECI or ECEF state vectors, not LOCAL")
    t = np.asarray(t, np.float64)
    shape = np.broadcast_shapes(t.shape, np.shape(rho), np.shape(pitch), np.shape(yaw), np.shape(h))
    r, v, _ = sv.interpolate(np.broadcast_to(t, shape))
    p = target_from_look_plane(r, v, np.broadcast_to(rho, shape), np.broadcast_to(pitch, shape),
                               np.broadcast_to(yaw, shape), side, np.broadcast_to(h, shape), exact)
    vrel = relative_velocity_eci(r, v) if sv.frame == "ECI" else v
    return doppler_hz(r, vrel, p, wavelength)


def look_angle(r, p) -> np.ndarray:
    """Angle (rad) between the line of sight r -> p and the geodetic nadir at r."""
    d = np.asarray(p, np.float64) - np.asarray(r, np.float64)
    cosl = -_dot(d, ellipsoid_normal(r)) / _norm(d)
    return np.arccos(np.clip(cosl, -1.0, 1.0))


def incidence_angle(r, p) -> np.ndarray:
    """Angle (rad) at the target p between the ellipsoid normal and the direction back to r."""
    d = np.asarray(r, np.float64) - np.asarray(p, np.float64)
    cosi = _dot(d, ellipsoid_normal(p)) / _norm(d)
    return np.arccos(np.clip(cosi, -1.0, 1.0))


def incidence_from_look(r, v, look, side: str = "right", h=0.0) -> np.ndarray:
    """Incidence angle on the ellipsoid (+h) for a look angle in the cross-track plane (zero attitude)."""
    p, _ = target_from_look(r, v, look, side, h=h)
    return incidence_angle(np.broadcast_to(r, p.shape), p)


def slant_range_from_look(r, v, look, side: str = "right", h=0.0) -> np.ndarray:
    """Slant range (m) to the surface of height h for a look angle in the cross-track plane."""
    return target_from_look(r, v, look, side, h=h)[1]


def look_from_slant_range(r, v, rho, side: str = "right", h=0.0) -> np.ndarray:
    """Look angle (rad) of the point at slant range rho in the cross-track plane (normal Xf)."""
    r = np.asarray(r, np.float64)
    xf = flight_frame(r, v)[..., :, 0]
    p = target_in_plane(r, xf, 0.0, rho, side, h)
    return look_angle(np.broadcast_to(r, p.shape), p)


def look_from_incidence(r, v, incidence, side: str = "right", h=0.0) -> np.ndarray:
    """Look angle (rad) giving the incidence angle (rad); inverse of :func:`incidence_from_look` by
    bisection on [0, horizon] (incidence grows monotonically with look)."""
    r = np.asarray(r, np.float64)
    inc = np.asarray(incidence, np.float64)
    if np.any((inc < 0) | (inc >= np.pi / 2)):
        raise GeometryError("incidence angle must be in [0, 90) deg")
    shape = np.broadcast_shapes(r.shape[:-1], inc.shape)
    rr = np.broadcast_to(r, shape + (3,))
    lo = np.zeros(shape)
    hi = horizon_look_angle(rr, v, side, h) * (1 - 1e-12)
    for _ in range(55):  # (pi/2) / 2^55 ~ 4e-17 rad
        mid = 0.5 * (lo + hi)
        up = incidence_from_look(rr, v, mid, side, h) < inc
        lo = np.where(up, mid, lo)
        hi = np.where(up, hi, mid)
    return 0.5 * (lo + hi)


def sphere_incidence_from_look(look, earth_radius: float, orbit_radius: float) -> np.ndarray:
    """Spherical Earth: sin(i) = sin(look) * orbit_radius / earth_radius (r+h = orbit radius; [Koh2003, eq. 9])."""
    s = np.sin(np.asarray(look, np.float64)) * orbit_radius / earth_radius
    if np.any(s > 1):
        raise GeometryError("look angle beyond the horizon of the spherical Earth")
    return np.arcsin(s)


def sphere_slant_range(incidence, earth_radius: float, orbit_radius: float) -> np.ndarray:
    """Spherical Earth: rho = -Re cos(i) + sqrt(Re^2 cos^2(i) + H^2 + 2 Re H), H = orbit_radius - Re ([Koh2003, §4])."""
    ci = np.cos(np.asarray(incidence, np.float64))
    H = orbit_radius - earth_radius
    return -earth_radius * ci + np.sqrt(earth_radius**2 * ci**2 + H * H + 2.0 * earth_radius * H)


def _ecef(sv: StateVectors) -> StateVectors:
    if sv.frame == "LOCAL":
        raise GeometryError("Earth geometry needs ECI or ECEF state vectors, not LOCAL")
    return sv.to_ecef()


def doppler_time(sv: StateVectors, p, wavelength: float | None = None, fdc=0.0, n_nodes: int | None = None,
                 t_guess=None, tol_s: float = 1e-10):
    """Time(s) when the fixed target(s) p (ECEF, (..., 3)) are seen at Doppler fdc (0: zero-Doppler).

    Solves F(t) = v.d - kappa |d| = 0, d = p - r(t), kappa = lam fdc / 2 (equivalent to
    (2/lam) v.d/|d| = fdc), which is nearly linear in t: Newton with F' = a.d - |v|^2 + kappa v.d/|d|,
    started by linear interpolation between the two state vectors where F changes sign.
    A span longer than one revolution can see a (high-latitude) target on several passes: then the
    pass whose bracket is nearest ``t_guess`` (s; broadcast to the targets) is taken, or without a
    guess the pass with the shortest range. Targets below the satellite's horizon do not count.
    Returns (t (...), slant range (...)). A target whose Doppler time is not inside the span raises.
    """
    sv = _ecef(sv)
    p = np.asarray(p, np.float64)
    if fdc is not None and np.any(np.asarray(fdc) != 0) and not wavelength:
        raise GeometryError("a non-zero Doppler needs the wavelength")
    kappa = np.broadcast_to(0.5 * (wavelength or 0.0) * np.asarray(fdc, np.float64), p.shape[:-1])
    flat = p.reshape(-1, 3)
    kap = kappa.reshape(-1)
    # starting bracket from the nodes (chunked: memory n_nodes x chunk); candidates are sign changes
    # where the target is above the satellite's horizon (outward ellipsoid normal at p towards r)
    guess = None if t_guess is None else np.broadcast_to(np.asarray(t_guess, np.float64), p.shape[:-1]).reshape(-1)
    t_start = np.empty(flat.shape[0])
    tn = sv.time
    chunk = max(1, 2_000_000 // len(sv))
    up = flat / np.array([WGS84_A**2, WGS84_A**2, WGS84_B**2])
    for s0 in range(0, flat.shape[0], chunk):
        d = flat[s0:s0 + chunk, None, :] - sv.position[None]
        R = _norm(d)
        F = _dot(sv.velocity[None], d) - kap[s0:s0 + chunk, None] * R
        visible = _dot(up[s0:s0 + chunk, None, :], -d) > 0
        ftol = 1e-7 * _dot(sv.velocity, sv.velocity)[None, :-1]  # F' ~ -|v|^2: a 0.1 us slack at the ends
        ok = (F[:, :-1] >= -ftol) & (F[:, 1:] <= ftol) & (F[:, :-1] > F[:, 1:]) & (visible[:, :-1] | visible[:, 1:])
        has = ok.any(axis=1)
        if not np.all(has):
            raise GeometryError(
                f"{np.count_nonzero(~has)} target(s) have no {'zero-' if not np.any(kap) else ''}Doppler time "
                f"within the state-vector span [{tn[0]:.3f}, {tn[-1]:.3f}] s")
        if guess is None:
            cost = np.minimum(R[:, :-1], R[:, 1:])
        else:
            cost = np.abs(0.5 * (tn[:-1] + tn[1:])[None, :] - guess[s0:s0 + chunk, None])
        k = np.argmin(np.where(ok, cost, np.inf), axis=1)
        rows = np.arange(k.size)
        f0, f1 = F[rows, k], F[rows, k + 1]
        t_start[s0:s0 + chunk] = tn[k] + (tn[k + 1] - tn[k]) * f0 / (f0 - f1)
    t = np.clip(t_start, tn[0], tn[-1])
    for _ in range(30):
        r, v, a = sv.interpolate(t, n_nodes)
        d = flat - r
        R = _norm(d)
        vd = _dot(v, d)
        F = vd - kap * R
        dF = _dot(a, d) - _dot(v, v) + kap * vd / R
        dt = -F / dF
        t = np.clip(t + dt, tn[0], tn[-1])
        if np.all(np.abs(dt) < tol_s):
            break
    else:
        raise GeometryError("Doppler-time solve did not converge")
    r, _, _ = sv.interpolate(t, n_nodes)
    return t.reshape(p.shape[:-1]), _norm(flat - r).reshape(p.shape[:-1])


def geolocate(sv: StateVectors, t, rho, wavelength: float, fdc=0.0, h=0.0, side: str = "right",
              n_nodes: int | None = None) -> np.ndarray:
    """ECEF position (..., 3) of the target seen at azimuth time t, slant range rho, Doppler fdc, height h."""
    sv = _ecef(sv)
    t = np.asarray(t, np.float64)
    shape = np.broadcast_shapes(t.shape, np.shape(rho), np.shape(fdc), np.shape(h))
    r, v, _ = sv.interpolate(np.broadcast_to(t, shape), n_nodes)
    return target_from_doppler(r, v, np.broadcast_to(rho, shape), wavelength, np.broadcast_to(fdc, shape),
                               side, np.broadcast_to(h, shape))


def geolocate_geodetic(sv: StateVectors, t, rho, wavelength: float, fdc=0.0, h=0.0, side: str = "right",
                       n_nodes: int | None = None):
    """(lat_deg, lon_deg, h_m) of :func:`geolocate` (WGS-84 via pyproj)."""
    return ecef_to_geodetic(geolocate(sv, t, rho, wavelength, fdc, h, side, n_nodes))
