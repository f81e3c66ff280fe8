"""Doppler centroid and rate from orbit + attitude ([Koh2003, eq. 4-6 and 9], corrected).

Sign (project phase convention exp(-j*4*pi*R/lam), see ``orbit.geometry``):
    fdc = -(2/lam) dR/deta = +(2/lam) v_rel . L,   fr = -(2/lam) d2R/deta2,
with L the unit line of sight satellite -> target and v_rel the satellite velocity relative to the
(Earth-fixed) target. [Koh2003, eq. 4]'s "-(2/lam) v_rel . L" has the opposite sign (typo).

Full vector model (``fdc_vector``): at azimuth time eta, the target p is the point of the ellipsoid
(+ height) at slant range rho in the beam-centre plane (p - r) . w = 0, w = Q R e_x the control
frame's along-track axis (attitude pitch/yaw; flight frame Q from the ECI state, [Koh2003, eq. 2-3]), and
fdc = (2/lam) (v - w_e x r) . (p - r)/rho, exact because (w_e x (p - r)) . (p - r) = 0
(``orbit.geometry.doppler_from_attitude``).

Closed form (``fdc_closed``, [Koh2003, eq. 6] in our notation): with R Lc expanded to first order in
pitch pp and yaw py, R Lc = (pp cos g - s py sin g, s sin g, cos g) (s = +1 right-looking), and
v_rel approximated by the satellite-position form v - w_e x r ([Koh2003, eq. 5]), projected on the flight
axes V_k = v_rel . {Xf, Yf, Zf}:

    fdc(g) = A cos g + B sin g,   A = (2/lam) (V_z + pp V_x),   B = (2/lam) s (V_y - py V_x)     (eq. 6)

where g is the look angle of the slant range in the cross-track plane. Its inversion for [Koh2003]'s
fr route (eq. 9 chain) is g = phi +- acos(fdc / C), C = sqrt(A^2 + B^2), phi = atan2(B, A) (equivalent
to the printed g = asin(alpha f +- beta sqrt(alpha^2 + beta^2 - f^2)) with alpha = B/C^2, beta = A/C^2);
the root in (0, pi/2) closest to the look angle of the block's slant range is kept; |fdc| > C (sqrt
domain) or no root in (0, pi/2) (asin domain) is reported as NaN, never clipped silently. Then the
spherical incidence i = asin(sin g (r + h)/r) and slant range rho = -r cos i + sqrt(r^2 cos^2 i + h^2
+ 2 r h) ([Koh2003, §4], ``orbit.geometry.sphere_*``), and fr is evaluated exactly for the target at p = r + rho L(g)
(the printed coefficients f_0, f_s, f_c, f_phi of eq. 9 contain typos and are not used).

Exact rate (``fr_exact``): the target at slant range rho with the ABSOLUTE centroid fdc on the
ellipsoid (``orbit.geometry.target_from_doppler``, ECEF) and fr = -(2/lam) d2R/deta2 from the
Hermite-interpolated orbit (position, velocity AND acceleration, ``orbit.statevectors``).

Terrain (``heights``). Every target above lies on the surface of geodetic height h; h is the height of
the terrain (:class:`sarcli.model.terrain.Terrain`) under the beam centre, never the simulator's truth.
At (rho, t) it is the root of g(h) = T(lat(h), lon(h)) - h, where (lat, lon)(h) is the beam-centre-plane
target at slant range rho on the surface of height h. Raising h moves that target away from the radar
by dh cot(incidence) at fixed range, so the plain iteration h <- T(h) contracts by s cot(inc) (s the
terrain slope along ground range) and diverges on slopes steeper than the incidence; instead the root
is bracketed (the fixed-point step from h = 0, doubled until g changes sign: g > 0 below the terrain's
lowest and < 0 above its highest point) and refined by the Illinois variant of regula falsi to
|g| <= 1 mm (converges for any continuous T; in layover, where several heights share the range, it
returns one of them). A constant height is found exactly after one step: g(H) = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from orbit import geometry as og
from orbit.constants import OMEGA_EARTH
from orbit.errors import OrbitError
from orbit.frames import eci_to_ecef
from orbit.geodetic import ecef_to_geodetic
from orbit.pointing import beam_vector, flight_frame, side_sign
from orbit.statevectors import StateVectors
from sarcli.errors import ProductError, SarcliError
from sarcli.model.raw import RawProduct
from sarcli.model.terrain import ConstantHeight, Terrain

HEIGHT_TOL_M = 1e-3  # |T(h) - h| at the returned terrain height
_MAX_BRACKET_STEPS = 30  # the step doubles: 2^30 x the first step
_MAX_ROOT_ITER = 60


@dataclass
class OrbitGeometry:
    """Orbit + attitude of a raw product, ready for Doppler evaluation at (slant range, azimuth time)."""

    sv_eci: StateVectors
    sv_ecef: StateVectors
    att_time: np.ndarray
    att_pitch: np.ndarray
    att_yaw: np.ndarray
    wavelength: float
    side: str = "right"
    terrain: Terrain = ConstantHeight(0.0)
    n_nodes: int | None = None
    exact_attitude: bool = True

    @classmethod
    def from_raw(cls, raw: RawProduct, terrain: Terrain | None = None, n_nodes: int | None = None,
                 exact_attitude: bool = True) -> OrbitGeometry:
        """The geometry of ``raw`` over ``terrain`` (default: the ellipsoid, 0 m)."""
        o = raw.orbit
        if o is None or o.frame not in ("ECI", "ECEF"):
            raise SarcliError("the geometric Doppler model needs ECI or ECEF state vectors in /orbit")
        try:
            sv = StateVectors(o.time, o.position, o.velocity, o.frame, raw.epoch_utc)
            sv_eci, sv_ecef = sv.to_eci(), sv.to_ecef()
        except OrbitError as e:
            raise SarcliError(f"orbit: {e}") from None
        if raw.attitude is not None and np.size(raw.attitude.time) > 0:
            a = raw.attitude
            at, ap, ay = (np.atleast_1d(np.asarray(x, np.float64)) for x in (a.time, a.pitch, a.yaw))
        else:
            at, ap, ay = np.zeros(1), np.zeros(1), np.zeros(1)
        return cls(sv_eci, sv_ecef, at, ap, ay, raw.radar.wavelength_m, raw.look_side,
                   ConstantHeight(0.0) if terrain is None else terrain, n_nodes, exact_attitude)

    def attitude(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(pitch, yaw) rad at times t (linear interpolation, held constant outside the table)."""
        if self.att_time.size == 1:
            return np.full(np.shape(t), self.att_pitch[0]), np.full(np.shape(t), self.att_yaw[0])
        return np.interp(t, self.att_time, self.att_pitch), np.interp(t, self.att_time, self.att_yaw)

    def _states(self, t):
        try:
            r, v, _ = self.sv_eci.interpolate(t, self.n_nodes)
            re, ve, ae = self.sv_ecef.interpolate(t, self.n_nodes)
        except OrbitError as e:
            raise SarcliError(f"orbit: {e}") from None
        return r, v, re, ve, ae

    def _to_ecef(self, t, p_eci):
        return eci_to_ecef(self.sv_eci.epoch_utc, t, p_eci)

    def _height(self, rho, t, h) -> np.ndarray:
        """``h`` broadcast to (rho, t), or the terrain height there when ``h`` is None."""
        return self.heights(rho, t) if h is None else np.broadcast_to(np.asarray(h, np.float64), np.shape(rho))

    def _terrain_misfit(self, rho, t, h) -> np.ndarray:
        """g(h) = T(lat, lon) - h of the beam-centre-plane target at slant range rho on the surface h."""
        r, v, _ = self.sv_eci.interpolate(t)
        pp, py = self.attitude(t)
        p = og.target_from_look_plane(r, v, rho, pp, py, self.side, h, self.exact_attitude)
        lat, lon, _ = ecef_to_geodetic(self._to_ecef(t, p))
        th = np.asarray(self.terrain.height(lat, lon), np.float64)
        if not np.all(np.isfinite(th)):
            k = int(np.flatnonzero(~np.isfinite(th))[0])
            raise ProductError(f"terrain: no height at latitude {lat[k]:.5f}, longitude {lon[k]:.5f} deg "
                               "(outside the terrain model or a void in it)")
        return th - h

    def heights(self, rho, t) -> np.ndarray:
        """Terrain height (m above the ellipsoid) under the beam centre at slant range rho (m) and
        azimuth time t (s): bracketing + Illinois iteration (module docstring)."""
        rho, t = np.broadcast_arrays(np.asarray(rho, np.float64), np.asarray(t, np.float64))
        shape = rho.shape
        rho, t = rho.ravel(), t.ravel()
        try:
            return self._solve_heights(rho, t).reshape(shape)
        except OrbitError as e:
            raise SarcliError(f"geometry: {e}") from None

    def _solve_heights(self, rho: np.ndarray, t: np.ndarray) -> np.ndarray:
        def g(h, i):
            return self._terrain_misfit(rho[i], t[i], h)

        a = np.zeros(rho.size)
        ga = g(a, slice(None))
        b, gb = a.copy(), ga.copy()
        todo = np.flatnonzero(np.abs(ga) > HEIGHT_TOL_M)
        step = ga.copy()
        for _ in range(_MAX_BRACKET_STEPS):  # step in the direction of g until its sign changes
            if todo.size == 0:
                break
            b[todo] = a[todo] + step[todo]
            gb[todo] = g(b[todo], todo)
            same = np.sign(gb[todo]) == np.sign(ga[todo])
            same &= np.abs(gb[todo]) > HEIGHT_TOL_M
            move = todo[same]
            a[move], ga[move] = b[move], gb[move]
            step[move] *= 2.0
            todo = move
        else:
            if todo.size:
                raise ProductError(f"terrain: no height under the beam centre at slant range {rho[todo[0]]:.0f} m "
                                   f"(the terrain's heights reach {b[todo[0]]:.0f} m?)")
        todo = np.flatnonzero((np.abs(gb) > HEIGHT_TOL_M) & (np.abs(b - a) > HEIGHT_TOL_M))
        for _ in range(_MAX_ROOT_ITER):  # Illinois: regula falsi with the stale end's g halved
            if todo.size == 0:
                return b
            c = b[todo] - gb[todo] * (b[todo] - a[todo]) / (gb[todo] - ga[todo])
            gc = g(c, todo)
            flip = np.sign(gc) != np.sign(gb[todo])
            a[todo] = np.where(flip, b[todo], a[todo])
            ga[todo] = np.where(flip, gb[todo], 0.5 * ga[todo])
            b[todo], gb[todo] = c, gc
            todo = todo[(np.abs(gc) > HEIGHT_TOL_M) & (np.abs(b[todo] - a[todo]) > HEIGHT_TOL_M)]
        raise ProductError(f"terrain: the height under the beam centre did not converge at slant range "
                           f"{rho[todo[0]]:.0f} m (|T - h| = {abs(gb[todo[0]]):.3g} m): is the terrain continuous?")

    def fdc_vector(self, rho, t, h=None) -> np.ndarray:
        """Full vector model: absolute fdc (Hz) of the beam-centre-plane target at (rho, t) on the
        surface of height h (default: the terrain's, :meth:`heights`)
        (``orbit.geometry.doppler_from_attitude``; it interpolates the orbit with its default order,
        ``n_nodes`` applies to the rates, where the order matters - see the bench)."""
        rho, t = np.broadcast_arrays(np.asarray(rho, np.float64), np.asarray(t, np.float64))
        h = self._height(rho, t, h)
        pp, py = self.attitude(t)
        try:
            return og.doppler_from_attitude(self.sv_eci, t, rho, self.wavelength, pp, py, self.side,
                                            h, self.exact_attitude)
        except OrbitError as e:
            raise SarcliError(f"geometry: {e}") from None

    def fdc(self, model: str, rho, t, h=None) -> np.ndarray:
        """The geometric centroid of ``model`` ("vector" or "closed") at (rho, t, h)."""
        return self.fdc_vector(rho, t, h) if model == "vector" else self.fdc_closed(rho, t, h)

    def _closed_coeffs(self, r, v, pp, py):
        q = flight_frame(r, v)
        vrel = v - np.cross(np.array([0.0, 0.0, OMEGA_EARTH]), r)
        vx, vy, vz = (np.einsum("...i,...i->...", vrel, q[..., :, k]) for k in range(3))
        s = side_sign(self.side)
        k = 2.0 / self.wavelength
        return k * (vz + pp * vx), k * s * (vy - py * vx)

    def _cross_track_look(self, r, v, rho, h):
        try:
            return og.look_from_slant_range(r, v, rho, self.side, h)
        except OrbitError as e:
            raise SarcliError(f"geometry: {e}") from None

    def fdc_closed(self, rho, t, h=None) -> np.ndarray:
        """[Koh2003, eq. 6] (corrected, module docstring): A cos g + B sin g, g from the slant range on the
        surface of height h (default: the terrain's)."""
        rho, t = np.broadcast_arrays(np.asarray(rho, np.float64), np.asarray(t, np.float64))
        h = self._height(rho, t, h)
        r, v, _, _, _ = self._states(t)
        pp, py = self.attitude(t)
        A, B = self._closed_coeffs(r, v, pp, py)
        g = self._cross_track_look(r, v, rho, h)
        return A * np.cos(g) + B * np.sin(g)

    def look_from_fdc(self, fdc, rho, t, h=None) -> np.ndarray:
        """Inversion of [Koh2003, eq. 6] for the look angle (rad); NaN outside the sqrt/asin domains."""
        fdc, rho, t = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (fdc, rho, t)))
        h = self._height(rho, t, h)
        r, v, _, _, _ = self._states(t)
        pp, py = self.attitude(t)
        A, B = self._closed_coeffs(r, v, pp, py)
        return invert_closed_form(fdc, A, B, self._cross_track_look(r, v, rho, h))

    def fr_exact(self, rho, t, fdc, h=None) -> np.ndarray:
        """-(2/lam) d2R/deta2 (Hz/s) of the target at slant range rho seen at absolute Doppler fdc, on
        the surface of height h (default: the terrain's under the beam centre)."""
        rho, t, fdc = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (rho, t, fdc)))
        h = self._height(rho, t, h)
        _, _, re, ve, ae = self._states(t)
        try:
            p = og.target_from_doppler(re, ve, rho, self.wavelength, fdc, self.side, h)
        except OrbitError as e:
            raise SarcliError(f"geometry: {e}") from None
        return og.doppler_rate_hz_per_s(re, ve, ae, p, self.wavelength)

    def fr_seed(self, fdc, rho, t, h=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Route of [Koh2003, §4]: look angle re-solved from fdc (eq. 6 inverse), spherical incidence and slant
        range, then the exact rate at that target. Returns (fr Hz/s, look rad, slant range m); NaN
        where the inversion leaves its domain."""
        fdc, rho, t = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (fdc, rho, t)))
        h = self._height(rho, t, h)
        r, v, re, ve, ae = self._states(t)
        pp, py = self.attitude(t)
        g = self.look_from_fdc(fdc, rho, t, h)
        rs = np.linalg.norm(r, axis=-1)
        h_sat = ecef_to_geodetic(re)[2]
        re_local = rs - h_sat + h
        out_fr = np.full(fdc.shape, np.nan)
        out_rho = np.full(fdc.shape, np.nan)
        ok = np.isfinite(g)
        with np.errstate(invalid="ignore"):
            s = np.sin(g) * rs / re_local
        ok &= s < 1.0  # asin domain of the incidence
        if np.any(ok):
            inc = og.sphere_incidence_from_look(g[ok], re_local[ok], rs[ok])
            rr = og.sphere_slant_range(inc, re_local[ok], rs[ok])
            L = beam_vector(r[ok], v[ok], g[ok], pp[ok], py[ok], self.side, self.exact_attitude)
            p = self._to_ecef(t[ok], r[ok] + rr[:, None] * L)
            out_fr[ok] = og.doppler_rate_hz_per_s(re[ok], ve[ok], ae[ok], p, self.wavelength)
            out_rho[ok] = rr
        return out_fr, g, out_rho


def invert_closed_form(fdc, A, B, look_hint) -> np.ndarray:
    """Roots g of A cos g + B sin g = fdc in (0, pi/2), the one closest to ``look_hint``; NaN when
    |fdc| > sqrt(A^2 + B^2) (the sqrt domain of [Koh2003, §4]) or no root lies in (0, pi/2) (its asin domain)."""
    fdc, A, B, hint = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (fdc, A, B, look_hint)))
    C = np.hypot(A, B)
    phi = np.arctan2(B, A)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = fdc / C
        d = np.where(np.abs(c) <= 1.0, np.arccos(np.clip(c, -1.0, 1.0)), np.nan)
    best = np.full(fdc.shape, np.nan)
    for sgn in (1.0, -1.0):
        g = np.mod(phi + sgn * d + np.pi, 2 * np.pi) - np.pi
        inside = (g > 0) & (g < np.pi / 2)
        closer = ~np.isfinite(best) | (np.abs(g - hint) < np.abs(best - hint))
        best = np.where(inside & closer, g, best)
    return best
