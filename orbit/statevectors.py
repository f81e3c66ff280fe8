"""State vectors and their Hermite interpolation (positions AND velocities), numba for vectors of times.

Interpolant
-----------
Over a window of N consecutive nodes t_0..t_{N-1} with positions p_i and velocities v_i, the Hermite
interpolant H is the unique polynomial of degree 2N-1 with H(t_i) = p_i and H'(t_i) = v_i ([Koh2003, §2.1]:
Hermite interpolation, i.e. using both positions and velocities). Its error for a smooth orbit r(t) is

    r(t) - H(t) = r^(2N)(xi) / (2N)! * prod_i (t - t_i)^2 ,

so with spacing h and orbital rate w it scales like |r| (w h)^(2N) / (2N)! times a node product that is
smallest in the central interval of the window. Window rule: for t in [t_k, t_{k+1}] the window starts
at k - (N-1)//2, clipped to the available nodes; windows therefore change only AT nodes, where every
window reproduces p_k and v_k exactly, so the interpolated position and velocity are continuous
(C1) everywhere; the acceleration may jump slightly at nodes. Near the span ends the window is one-sided
and the error grows (measured in the README table).

Implementation: per window, the Newton form of H on the confluent nodes (z = u_0,u_0,u_1,u_1,...) in a
scaled time u = (t - t_ref)/h, nodes ordered from the window centre outwards (good conditioning), with
divided differences computed once per window (numpy). Evaluation is a nested (Horner-like) scheme
carrying the first and second derivatives: O(2N) per component per time. ``hermite_reference`` is an
independent plain-numpy Lagrange-form implementation used by the tests.

Times are float64 seconds after ``epoch_utc``; positions m, velocities m/s, accelerations m/s^2.
Frames: "ECI" (the GMST inertial frame of ``orbit.frames``), "ECEF" (WGS-84 Earth-fixed) or "LOCAL"
(a flat-Earth Cartesian frame, no conversion defined).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from orbit.errors import InterpolationRangeError, StateVectorError
from orbit.frames import ecef_to_eci, eci_to_ecef

FRAMES = ("ECI", "ECEF", "LOCAL")
DEFAULT_N_NODES = 10  # from the accuracy/cost table (README, section Orbit): 10x margin on both bars
MIN_N_NODES, MAX_N_NODES = 2, 16
_NEAR_DUPLICATE = 1e-6  # a spacing below this fraction of the median spacing is a duplicate


def _window_starts(n: int, n_nodes: int) -> np.ndarray:
    """First node of the window used for each interval [t_k, t_{k+1}], k = 0..n-2."""
    k = np.arange(n - 1)
    return np.clip(k - (n_nodes - 1) // 2, 0, n - n_nodes)


def _newton_tables(t: np.ndarray, p: np.ndarray, v: np.ndarray, n_nodes: int):
    """Per-window Newton coefficients of the Hermite interpolant.

    Returns (tref (W,), inv_h (W,), z (W, 2N), coef (W, 3, 2N)) for the W = n - N + 1 windows.
    """
    n, N = t.size, n_nodes
    idx = np.arange(n - N + 1)[:, None] + np.arange(N)[None, :]
    tw = t[idx]
    h = (tw[:, -1] - tw[:, 0]) / (N - 1)
    tref = 0.5 * (tw[:, (N - 1) // 2] + tw[:, N // 2])
    u = (tw - tref[:, None]) / h[:, None]
    order = np.argsort(np.abs(u), axis=1, kind="stable")
    idx = np.take_along_axis(idx, order, axis=1)
    u = np.take_along_axis(u, order, axis=1)
    z = np.repeat(u, 2, axis=1)  # confluent nodes
    f = np.repeat(p[idx], 2, axis=1)  # (W, 2N, 3) values
    d = v[idx] * h[:, None, None]  # dH/du = h * velocity
    m = 2 * N
    coef = np.empty((idx.shape[0], m, 3))
    coef[:, 0] = f[:, 0]
    # first divided differences: derivative at a repeated node, slope between distinct nodes
    col = np.empty((idx.shape[0], m - 1, 3))
    col[:, 0::2] = d
    col[:, 1::2] = (f[:, 2::2] - f[:, 1:-1:2]) / (z[:, 2::2] - z[:, 1:-1:2])[:, :, None]
    coef[:, 1] = col[:, 0]
    for j in range(2, m):
        col = (col[:, 1:] - col[:, :-1]) / (z[:, j:] - z[:, :-j])[:, :, None]
        coef[:, j] = col[:, 0]
    return tref, 1.0 / h, np.ascontiguousarray(z), np.ascontiguousarray(coef.transpose(0, 2, 1))


@njit(cache=True, fastmath={"contract"})
def _hermite_kernel(tn, win_of_interval, tref, inv_h, z, coef, t, out_p, out_v, out_a):  # pragma: no cover
    """Evaluate the per-window Newton forms at times t (1-D); writes (len(t), 3) outputs.

    Nested scheme per component: b_j = c_j + (u - z_j) b_{j+1}, b_j' = b_{j+1} + (u - z_j) b_{j+1}',
    b_j'' = 2 b_{j+1}' + (u - z_j) b_{j+1}''; the three components share u - z_j (unrolled by hand).
    Only FMA contraction is allowed (no reassociation), so results match the plain evaluation order.
    """
    n = tn.shape[0]
    m = z.shape[1]
    for q in range(t.shape[0]):
        tq = t[q]
        if tq <= tn[0]:
            k = 0
        elif tq >= tn[n - 1]:
            k = n - 2
        else:
            lo = 0
            hi = n - 1
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if tn[mid] <= tq:
                    lo = mid
                else:
                    hi = mid
            k = lo
        w = win_of_interval[k]
        s = inv_h[w]
        u = (tq - tref[w]) * s
        cx = coef[w, 0]
        cy = coef[w, 1]
        cz = coef[w, 2]
        zw = z[w]
        px = cx[m - 1]
        py = cy[m - 1]
        pz = cz[m - 1]
        vx = vy = vz = ax = ay = az = 0.0
        for j in range(m - 2, -1, -1):
            dz = u - zw[j]
            ax = ax * dz + 2.0 * vx
            ay = ay * dz + 2.0 * vy
            az = az * dz + 2.0 * vz
            vx = vx * dz + px
            vy = vy * dz + py
            vz = vz * dz + pz
            px = px * dz + cx[j]
            py = py * dz + cy[j]
            pz = pz * dz + cz[j]
        s2 = s * s
        out_p[q, 0] = px
        out_p[q, 1] = py
        out_p[q, 2] = pz
        out_v[q, 0] = vx * s
        out_v[q, 1] = vy * s
        out_v[q, 2] = vz * s
        out_a[q, 0] = ax * s2
        out_a[q, 1] = ay * s2
        out_a[q, 2] = az * s2


def hermite_reference(tn: np.ndarray, pn: np.ndarray, vn: np.ndarray, t: np.ndarray, n_nodes: int):
    """Plain-numpy Hermite interpolation (Lagrange form), same window rule; for tests and benchmarks.

    With Lagrange polynomials L_i over the window and c_i = L_i'(t_i) = sum_{j!=i} 1/(t_i - t_j):
        H(t) = sum_i (1 - 2 c_i (t - t_i)) L_i(t)^2 p_i + (t - t_i) L_i(t)^2 v_i,
    differentiated twice analytically (L_i, L_i', L_i'' by the product rule). Returns (pos, vel, acc).
    """
    tn = np.asarray(tn, np.float64)
    t = np.atleast_1d(np.asarray(t, np.float64))
    n = tn.size
    k = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, n - 2)
    start = _window_starts(n, n_nodes)[k]
    out = [np.zeros((t.size, 3)) for _ in range(3)]
    for i_loc in range(n_nodes):
        i = start + i_loc
        ti = tn[i]
        L, dL, d2L = np.ones(t.size), np.zeros(t.size), np.zeros(t.size)
        ci = np.zeros(t.size)
        for j_loc in range(n_nodes):
            if j_loc == i_loc:
                continue
            inv = 1.0 / (ti - tn[start + j_loc])
            fj = (t - tn[start + j_loc]) * inv
            d2L = d2L * fj + 2.0 * dL * inv
            dL = dL * fj + L * inv
            L = L * fj
            ci += inv
        x = t - ti
        g = 1.0 - 2.0 * ci * x
        A = g * L * L
        dA = -2.0 * ci * L * L + 2.0 * g * L * dL
        d2A = -8.0 * ci * L * dL + 2.0 * g * (dL * dL + L * d2L)
        B = x * L * L
        dB = L * L + 2.0 * x * L * dL
        d2B = 4.0 * L * dL + 2.0 * x * (dL * dL + L * d2L)
        for o, wa, wb in zip(out, (A, dA, d2A), (B, dB, d2B), strict=True):
            o += wa[:, None] * pn[i] + wb[:, None] * vn[i]
    return tuple(out)


class StateVectors:
    """Orbit state vectors: validated, immutable, interpolable.

    Parameters: ``time`` (n,) s after ``epoch_utc``, strictly increasing (spacing need not be uniform);
    ``position`` (n, 3) m; ``velocity`` (n, 3) m/s; ``frame`` "ECI" | "ECEF" | "LOCAL";
    ``epoch_utc`` ISO-8601 UTC (needed for frame conversion). Raises :class:`StateVectorError`.
    """

    def __init__(self, time, position, velocity, frame: str = "ECI", epoch_utc: str = ""):
        t = np.array(time, dtype=np.float64, copy=True).reshape(-1) if np.ndim(time) <= 1 else None
        if t is None:
            raise StateVectorError(f"state-vector times must be 1-D, got shape {np.shape(time)}")
        n = t.size
        if n < 2:
            raise StateVectorError(f"need at least 2 state vectors, got {n}")
        p = np.array(position, dtype=np.float64, copy=True)
        v = np.array(velocity, dtype=np.float64, copy=True)
        if p.shape != (n, 3) or v.shape != (n, 3):
            raise StateVectorError(f"positions {p.shape} and velocities {v.shape} must both be ({n}, 3)")
        for name, a in (("times", t), ("positions", p), ("velocities", v)):
            if not np.all(np.isfinite(a)):
                bad = int(np.flatnonzero(~np.isfinite(a.reshape(n, -1)).all(axis=1))[0])
                raise StateVectorError(f"state-vector {name} contain NaN or inf (vector {bad})")
        dt = np.diff(t)
        if np.any(dt <= 0):
            k = int(np.flatnonzero(dt <= 0)[0])
            what = "duplicated" if dt[k] == 0 else "not increasing"
            raise StateVectorError(f"state-vector times are {what}: t[{k}] = {t[k]!r}, t[{k + 1}] = {t[k + 1]!r}")
        med = float(np.median(dt))
        if np.any(dt < _NEAR_DUPLICATE * med):
            k = int(np.flatnonzero(dt < _NEAR_DUPLICATE * med)[0])
            raise StateVectorError(f"state-vector times t[{k}] and t[{k + 1}] are only {dt[k]:.3g} s apart "
                                   f"(median spacing {med:.6g} s): duplicated vector?")
        frame = str(frame).upper()
        if frame not in FRAMES:
            raise StateVectorError(f"unknown state-vector frame {frame!r}; expected one of {FRAMES}")
        for a in (t, p, v):
            a.flags.writeable = False
        self.time, self.position, self.velocity = t, p, v
        self.frame, self.epoch_utc = frame, str(epoch_utc)
        self._tables: dict[int, tuple] = {}
        self._ecef: StateVectors | None = None

    @classmethod
    def from_record(cls, orbit, epoch_utc: str) -> StateVectors:
        """From any object with ``time``, ``position``, ``velocity``, ``frame`` (e.g. a product's orbit)."""
        return cls(orbit.time, orbit.position, orbit.velocity, orbit.frame, epoch_utc)

    def __len__(self) -> int:
        return self.time.size

    def __repr__(self) -> str:
        return (f"StateVectors(n={len(self)}, frame={self.frame}, span=[{self.time[0]:.6g}, "
                f"{self.time[-1]:.6g}] s, spacing={self.spacing:.6g} s, epoch={self.epoch_utc!r})")

    @property
    def span(self) -> tuple[float, float]:
        """(first, last) node time, s after the epoch."""
        return float(self.time[0]), float(self.time[-1])

    @property
    def spacing(self) -> float:
        """Median node spacing (s)."""
        return float(np.median(np.diff(self.time)))

    def default_n_nodes(self) -> int:
        """DEFAULT_N_NODES, or all nodes when there are fewer."""
        return min(DEFAULT_N_NODES, len(self))

    def _check_n(self, n_nodes: int | None) -> int:
        N = self.default_n_nodes() if n_nodes is None else int(n_nodes)
        if not MIN_N_NODES <= N <= MAX_N_NODES:
            raise StateVectorError(f"n_nodes must be in {MIN_N_NODES}..{MAX_N_NODES}, got {N}")
        if N > len(self):
            raise StateVectorError(f"n_nodes = {N} exceeds the {len(self)} state vectors available")
        return N

    def _table(self, N: int) -> tuple:
        if N not in self._tables:
            tref, inv_h, z, coef = _newton_tables(self.time, self.position, self.velocity, N)
            self._tables[N] = (_window_starts(len(self), N).astype(np.int64), tref, inv_h, z, coef)
        return self._tables[N]

    def check_times(self, t: np.ndarray, max_extrapolation_s: float = 0.0) -> None:
        """Raise :class:`InterpolationRangeError` unless all t are finite and within the span +- margin."""
        t = np.asarray(t, np.float64)
        if t.size == 0:
            return
        if not np.all(np.isfinite(t)):
            raise InterpolationRangeError("interpolation times contain NaN or inf")
        if max_extrapolation_s < 0 or not np.isfinite(max_extrapolation_s):
            raise InterpolationRangeError(f"max_extrapolation_s must be >= 0, got {max_extrapolation_s}")
        t0, t1 = self.span
        lo, hi = float(t.min()), float(t.max())
        if lo < t0 - max_extrapolation_s or hi > t1 + max_extrapolation_s:
            bad = lo if lo < t0 - max_extrapolation_s else hi
            raise InterpolationRangeError(
                f"time {bad:.6f} s is outside the state-vector span [{t0:.6f}, {t1:.6f}] s"
                + (f" + {max_extrapolation_s:g} s allowed extrapolation" if max_extrapolation_s else
                   " (pass max_extrapolation_s to allow a bounded extrapolation)"))

    def interpolate(self, t, n_nodes: int | None = None, max_extrapolation_s: float = 0.0):
        """Hermite-interpolate at times ``t`` (s after the epoch; scalar or any shape).

        Returns (position m, velocity m/s, acceleration m/s^2), each of shape ``t.shape + (3,)``, in
        this object's frame. Times outside the span raise :class:`InterpolationRangeError` unless
        within ``max_extrapolation_s`` of it (then the end window is extrapolated).
        """
        N = self._check_n(n_nodes)
        ta = np.asarray(t, dtype=np.float64)
        self.check_times(ta, max_extrapolation_s)
        flat = np.ascontiguousarray(ta.reshape(-1))
        out = [np.empty((flat.size, 3)) for _ in range(3)]
        win, tref, inv_h, z, coef = self._table(N)
        _hermite_kernel(self.time, win, tref, inv_h, z, coef, flat, *out)
        return tuple(o.reshape(ta.shape + (3,)) for o in out)

    def to_ecef(self) -> StateVectors:
        """These state vectors in ECEF (rotation by GMST, velocity with the w x r term; orbit.frames); cached."""
        if self.frame == "ECEF":
            return self
        if self._ecef is None:
            r, v = eci_to_ecef(self._epoch_for(self.frame), self.time, self.position, self.velocity)
            self._ecef = StateVectors(self.time, r, v, "ECEF", self.epoch_utc)
        return self._ecef

    def to_eci(self) -> StateVectors:
        """These state vectors in the GMST inertial frame (inverse of :meth:`to_ecef`)."""
        if self.frame == "ECI":
            return self
        r, v = ecef_to_eci(self._epoch_for(self.frame), self.time, self.position, self.velocity)
        return StateVectors(self.time, r, v, "ECI", self.epoch_utc)

    def _epoch_for(self, frame: str) -> str:
        if frame == "LOCAL":
            raise StateVectorError("LOCAL (flat-Earth) state vectors have no ECI/ECEF conversion")
        if not self.epoch_utc:
            raise StateVectorError("frame conversion needs the state vectors' epoch_utc")
        return self.epoch_utc
