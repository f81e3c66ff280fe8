"""Antenna axes at every pulse, built on ``orbit.pointing`` (flight/control frames of [Koh2003, §2]).

Zero attitude means a beam PERPENDICULAR TO THE PLATFORM VELOCITY of the simulation frame (the
inertial velocity for ECI scenes), so that an inertial scene seen at zero attitude has a zero
Doppler centroid. The flight frame of [Koh2003, §2.2] has Zf along the GEODETIC nadir, which is not
perpendicular to v when the orbit has a radial velocity (eccentricity) or where the geodetic and
geocentric verticals differ (up to 0.19 deg, i.e. several hundred Hz of Doppler at C band).
We therefore add the reference pitch

    pitch0 = atan2(-v . Zf, v . Xf)        (exactly cancels the Zf component of v in the beam)

and use R = Rz(yaw) Ry(pitch0 + pitch). The product's /attitude stores the total flight-frame
pitch pitch0 + pitch and the yaw, so a processor using ``orbit.pointing`` with the stored attitude
reconstructs exactly the simulated beam. For the linear (flat-Earth) platform Zf = -z, v is
horizontal and pitch0 = 0.

Axes (unit vectors in the simulation frame, columns of Q R applied to control-frame vectors):
along-track ``ux`` = Q R e_x (normal of the beam-centre plane), boresight ``ub`` = Q R Lc with
Lc = (0, s sin g, cos g), elevation axis ``ue`` = Q R (0, s cos g, -sin g) (s = +1 right-looking).
"""

from __future__ import annotations

import numpy as np

from orbit.pointing import control_rotation, flight_frame, side_sign


def _flat_flight_frame(v: np.ndarray) -> np.ndarray:
    """Flight frame for the LOCAL flat-Earth frame: Zf = -z, Yf = Zf x v / |.|, Xf = Yf x Zf."""
    zf = np.broadcast_to(np.array([0.0, 0.0, -1.0]), v.shape)
    yf = np.cross(zf, v)
    yf /= np.linalg.norm(yf, axis=-1, keepdims=True)
    return np.stack([np.cross(yf, zf), yf, zf], axis=-1)


def reference_pitch(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """pitch0 (rad) that turns the flight frame's beam plane perpendicular to v."""
    vf = np.einsum("...ji,...j->...i", q, v)  # v in flight coordinates
    return np.arctan2(-vf[..., 2], vf[..., 0])


def antenna_axes(r: np.ndarray, v: np.ndarray, frame: str, look: float, pitch: float, yaw: float,
                 side: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(ux, ue, ub, total_pitch) for states r, v (..., 3); see the module docstring."""
    q = _flat_flight_frame(v) if frame == "LOCAL" else flight_frame(r, v)
    p_total = reference_pitch(q, v) + pitch
    qr = q @ control_rotation(p_total, np.full_like(p_total, yaw))
    s = side_sign(side)
    ux = qr[..., :, 0]
    ub = qr @ np.array([0.0, s * np.sin(look), np.cos(look)])
    ue = qr @ np.array([0.0, s * np.cos(look), -np.sin(look)])
    return ux, ue, ub, p_total
