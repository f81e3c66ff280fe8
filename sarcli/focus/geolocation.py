"""Positions of image pixels: the zero-Doppler target of (azimuth time t, slant range R, height h).

Earth-fixed products (orbit frame ECI or ECEF): ``orbit.geometry.geolocate`` with Doppler 0 in ECEF
(Hermite-interpolated state vectors, exact WGS-84 height). LOCAL products (flat Earth, z up): the
point at height h, range R from the antenna, perpendicular to its velocity, on the look side:
``T = P + a r_hat + b u_hat + (h - P_z) z_hat`` with u_hat the horizontal flight direction,
r_hat = u_hat x z_hat (right) or its opposite (left), ``b = -(h - P_z) V_z / |V_h|`` (zero Doppler)
and ``a = sqrt(R^2 - b^2 - (h - P_z)^2)``.
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError
from sarcli.model.raw import Orbit


def state_vectors(orbit: Orbit | None, epoch_utc: str):
    """``orbit.statevectors.StateVectors`` of a product's orbit (ECEF for Earth frames)."""
    from orbit.statevectors import StateVectors

    if orbit is None:
        raise SarcliError("the product has no orbit: cannot geolocate (ingested MATLAB blocks carry none)")
    sv = StateVectors.from_record(orbit, epoch_utc)
    return sv if sv.frame == "LOCAL" else sv.to_ecef()


def platform_state(orbit: Orbit | None, epoch_utc: str, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Antenna position and velocity at times t (ECEF, or LOCAL), shapes t.shape + (3,)."""
    sv = state_vectors(orbit, epoch_utc)
    pos, vel, _ = sv.interpolate(np.asarray(t, np.float64), max_extrapolation_s=1.0)
    return pos, vel


def zero_doppler_points(orbit: Orbit | None, epoch_utc: str, t, rho, wavelength: float, side: str = "right",
                        height=0.0) -> np.ndarray:
    """Target positions (broadcast shape + (3,)) in ECEF (Earth frames) or LOCAL metres."""
    from orbit.errors import GeometryError
    from orbit.geometry import geolocate

    sv = state_vectors(orbit, epoch_utc)
    t, rho, height = np.broadcast_arrays(np.asarray(t, np.float64), np.asarray(rho, np.float64),
                                         np.asarray(height, np.float64))
    if sv.frame != "LOCAL":
        try:
            return geolocate(sv, t, rho, wavelength, 0.0, height, side)
        except GeometryError as e:
            raise SarcliError(f"geolocation failed: {e}") from None
    p, v, _ = sv.interpolate(t, max_extrapolation_s=1.0)
    vh = np.hypot(v[..., 0], v[..., 1])
    u = np.stack([v[..., 0] / vh, v[..., 1] / vh, np.zeros_like(vh)], -1)
    right = np.stack([u[..., 1], -u[..., 0], np.zeros_like(vh)], -1)
    if side == "left":
        right = -right
    dz = height - p[..., 2]
    b = -dz * v[..., 2] / vh
    a2 = rho**2 - b**2 - dz**2
    if np.any(a2 < 0):
        raise SarcliError("slant range shorter than the platform height: pixel does not reach the ground")
    a = np.sqrt(a2)
    return p + a[..., None] * right + b[..., None] * u + dz[..., None] * np.array([0.0, 0.0, 1.0])
