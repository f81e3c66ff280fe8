"""Platform trajectory truth: positions and velocities at every pulse, and (r, v, a) at any time.

Simulation frames: ECI (orbit and state-vector platforms; ``orbit.frames`` GMST inertial frame)
or LOCAL (linear airborne platform: x cross-track ground range, y along track, z up).
Times here are RELATIVE to the scene centre (s); absolute = ``scene.center_time_s`` + t.

- ``orbit``: Keplerian elements at the scene epoch propagated with J2 (``orbit.propagate``, DOP853
  rtol 1e-13) to every pulse time (the dense truth the echo uses) and to a 1 s support grid
  (+-``MARGIN_S`` around the data) whose Hermite interpolant (``orbit.statevectors``, position +
  velocity, 8 nodes) serves truth solves at arbitrary times. The product stores 15 ECI vectors
  480 s apart centred on the scene, as Radarsat-1 delivers them.
- ``state_vectors``: the given vectors (ECI or ECEF, converted to ECI) ARE the truth: their Hermite
  interpolation is used at every pulse; they are stored as given.
- ``linear``: r(t) = (x_m, y_m + V t, H), v = (0, V, 0), a = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from orbit.statevectors import StateVectors
from sarcli.errors import FormatError
from sarcli.model.raw import Orbit
from sarcli.sim.scene import LinearPlatform, OrbitPlatform, Scene

MARGIN_S = 60.0
N_PRODUCT_VECTORS = 15
PRODUCT_SPACING_S = 480.0


@dataclass
class Trajectory:
    frame: str  # "ECI" or "LOCAL"
    pulse_time: np.ndarray  # (n_lines,) s relative to the scene centre
    position: np.ndarray  # (n_lines, 3) m at each pulse (dense truth)
    velocity: np.ndarray  # (n_lines, 3) m/s
    product_orbit: Orbit  # what the product stores (times absolute, s after the epoch)
    _sv: StateVectors | None  # interpolant for truth solves (times relative to the centre)
    _linear: LinearPlatform | None

    def state(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(r, v, a) at times t (s relative to the scene centre), any shape -> (..., 3)."""
        if self._linear is not None:
            return linear_state(self._linear, t)
        assert self._sv is not None
        return self._sv.interpolate(np.asarray(t, np.float64))

    @property
    def span(self) -> tuple[float, float]:
        """Time span (relative s) where :meth:`state` is valid."""
        if self._sv is None:
            return (-np.inf, np.inf)
        return self._sv.span


def linear_state(lp: LinearPlatform, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Straight flight: r = (x_m, y_m + V t, H), v = (0, V, 0), a = 0 (LOCAL frame)."""
    t = np.asarray(t, np.float64)
    r = np.stack(np.broadcast_arrays(lp.x_m, lp.y_m + lp.velocity_mps * t, lp.height_m), -1)
    v = np.zeros_like(r)
    v[..., 1] = lp.velocity_mps
    return r, v, np.zeros_like(r)


def pulse_times(scene: Scene) -> np.ndarray:
    """Pulse transmit times relative to the scene centre: (k - (n-1)/2) / PRF."""
    n = scene.radar.n_lines
    return (np.arange(n) - (n - 1) / 2.0) / scene.radar.prf_hz


def build_trajectory(scene: Scene) -> Trajectory:
    """The platform truth for ``scene`` (see the module docstring)."""
    t = pulse_times(scene)
    p = scene.platform
    tc = scene.center_time_s
    if isinstance(p, LinearPlatform):
        r, v, _ = linear_state(p, t)
        return Trajectory("LOCAL", t, r, v, Orbit(tc + t[[0, -1]], r[[0, -1]], v[[0, -1]], "LOCAL"), None, p)
    if isinstance(p, OrbitPlatform):
        from orbit.propagate import kepler_to_state, propagate_j2

        r0, v0 = kepler_to_state(p.elements)
        grid = np.arange(np.floor(t[0] - MARGIN_S), np.ceil(t[-1] + MARGIN_S) + 1.0)
        prod_t = (np.arange(N_PRODUCT_VECTORS) - N_PRODUCT_VECTORS // 2) * PRODUCT_SPACING_S
        allt = np.concatenate([t, grid, prod_t]) + tc
        try:
            r, v = propagate_j2(r0, v0, allt)
        except RuntimeError as e:
            raise FormatError(f"{scene.path}: orbit propagation failed ({e})") from None
        n, m = t.size, grid.size
        sv = StateVectors(grid, r[n:n + m], v[n:n + m], "ECI", _shifted_epoch(scene))
        orbit = Orbit(prod_t + tc, r[n + m:], v[n + m:], "ECI")
        return Trajectory("ECI", t, r[:n], v[:n], orbit, sv, None)
    given = StateVectors(p.time - tc, p.position, p.velocity, p.frame, _shifted_epoch(scene))
    sv = given.to_eci()
    lo, hi = sv.span
    if t[0] - MARGIN_S < lo or t[-1] + MARGIN_S > hi:
        raise FormatError(f"{scene.path}: state vectors must cover the scene +- {MARGIN_S:g} s "
                          f"(relative span {lo:.1f}..{hi:.1f} s, pulses {t[0]:.2f}..{t[-1]:.2f} s)")
    r, v, _ = sv.interpolate(t)
    return Trajectory("ECI", t, r, v, Orbit(p.time.copy(), p.position.copy(), p.velocity.copy(), p.frame),
                      sv, None)


def _shifted_epoch(scene: Scene) -> str:
    """The epoch of the scene centre (relative times are measured from it)."""
    from orbit.timeutil import add_seconds

    return add_seconds(scene.epoch_utc, scene.center_time_s)
