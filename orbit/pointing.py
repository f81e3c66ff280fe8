"""Flight and control frames and the radar beam direction ([Koh2003, §2, eq. 1-3]).

All functions work in whatever Cartesian frame the satellite position ``r`` and velocity ``v`` are
given in (ECI as in [Koh2003], or ECEF); the result is in that same frame. Arrays broadcast over
leading axes; vectors are (..., 3), matrices (..., 3, 3). Angles in radians.

Flight frame (Xf, Yf, Zf), origin at the satellite:
    Zf = -n(r)            the geodetic nadir: minus the WGS-84 ellipsoid normal through the satellite
    Yf = Zf x v / |Zf x v|   (points to the RIGHT of the ground track)
    Xf = Yf x Zf             (along track, forward; equals v/|v| when v is horizontal)
[Koh2003, eq. 2] builds n(r) as s/|s| with s = (rx, ry, rz + dz), dz = rho*(tan(phi_gd) - tan(phi_gc)),
rho = sqrt(rx^2 + ry^2): the ellipsoid normal through r meets the Z axis at z = rz - rho*tan(phi_gd), so
s = (rx, ry, rho*tan(phi_gd)) is parallel to (cos(lon) cos(phi_gd), sin(lon) cos(phi_gd), sin(phi_gd)).
We evaluate that last form (identical, and finite at the poles where tan diverges); phi_gd comes from
pyproj. [Koh2003, eq. 2] prints Zf = s/|s| with minus signs in its components: the minus is right.
Q = [Xf Yf Zf] (columns) maps flight-frame coordinates to the frame of r; the printed [Koh2003, eq. 2]
matrix has placeholder typos and is not used.

Control frame: the flight frame rotated by the attitude, R = Rz(yaw) Ry(pitch) (roll is absorbed in
the look angle), active rotations about the flight axes:
    Rz(y) = [[cos y, -sin y, 0], [sin y, cos y, 0], [0, 0, 1]],
    Ry(p) = [[cos p, 0, sin p], [0, 1, 0], [-sin p, 0, cos p]],
    exact:        R = [[cy cp, -sy, cy sp], [sy cp, cy, sy sp], [-sp, 0, cp]]
    small-angle:  R ~ [[1, -y, p], [y, 1, 0], [-p, 0, 1]]          ([Koh2003, eq. 1]; first order in p, y)
Positive pitch turns the beam forward (+Xf), positive yaw turns a right-looking beam backward.

Beam direction in the control frame for look angle gamma (from nadir): Lc = (0, s sin(gamma),
cos(gamma)) with s = +1 right-looking, -1 left-looking; in the frame of r: L = Q R Lc ([Koh2003, eq. 3]).
The along-track (look-plane normal) axis is w = Q R e_x, the FIRST COLUMN of Q R ([Koh2003, §3.1]'s "first
row" would be the control axes' x components, a transposition typo).
"""

from __future__ import annotations

import numpy as np

from orbit.errors import GeometryError
from orbit.geodetic import ecef_to_geodetic


def side_sign(side: str) -> float:
    """+1 for a right-looking radar, -1 for left-looking."""
    s = str(side).lower()
    if s not in ("right", "left"):
        raise GeometryError(f"look side must be 'right' or 'left', got {side!r}")
    return 1.0 if s == "right" else -1.0


def _unit(x: np.ndarray, what: str) -> np.ndarray:
    n = np.linalg.norm(x, axis=-1, keepdims=True)
    if np.any(n == 0) or not np.all(np.isfinite(n)):
        raise GeometryError(f"{what} is zero or not finite")
    return x / n


def ellipsoid_normal(r: np.ndarray) -> np.ndarray:
    """Outward WGS-84 ellipsoid normal (unit) through the point(s) r (..., 3); geodetic latitude via pyproj.

    Valid in ECI too: the normal depends only on (sqrt(x^2+y^2), z) and the azimuth of r about Z.
    """
    r = np.asarray(r, np.float64)
    lat, _, _ = ecef_to_geodetic(r)
    phi = np.radians(lat)
    lam = np.arctan2(r[..., 1], r[..., 0])
    return np.stack([np.cos(phi) * np.cos(lam), np.cos(phi) * np.sin(lam), np.sin(phi)], axis=-1)


def flight_frame(r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Q (..., 3, 3): columns Xf, Yf, Zf (along track, right, geodetic nadir) in the frame of r, v."""
    r = np.asarray(r, np.float64)
    v = np.asarray(v, np.float64)
    zf = -ellipsoid_normal(r)
    yf = _unit(np.cross(zf, v), "velocity (parallel to nadir?)")
    xf = np.cross(yf, zf)
    return np.stack([xf, yf, zf], axis=-1)


def control_rotation(pitch, yaw, exact: bool = True) -> np.ndarray:
    """R (..., 3, 3) from the control to the flight frame: Rz(yaw) Ry(pitch), or [Koh2003]'s small-angle form."""
    p = np.asarray(pitch, np.float64)
    y = np.asarray(yaw, np.float64)
    p, y = np.broadcast_arrays(p, y)
    o, z = np.ones_like(p), np.zeros_like(p)
    if exact:
        cp, sp, cy, sy = np.cos(p), np.sin(p), np.cos(y), np.sin(y)
        rows = [[cy * cp, -sy, cy * sp], [sy * cp, cy, sy * sp], [-sp, z, cp]]
    else:
        rows = [[o, -y, p], [y, o, z], [-p, z, o]]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def look_vector_control(look, side: str = "right") -> np.ndarray:
    """Lc (..., 3): beam unit vector in the control frame for look angle(s) from nadir."""
    g = np.asarray(look, np.float64)
    return np.stack([np.zeros_like(g), side_sign(side) * np.sin(g), np.cos(g)], axis=-1)


def beam_vector(r, v, look, pitch=0.0, yaw=0.0, side: str = "right", exact: bool = True) -> np.ndarray:
    """L = Q R Lc (..., 3): unit beam-pointing vector in the frame of r, v ([Koh2003, eq. 3]).

    For an ECI state this is the ECI beam vector of [Koh2003, eq. 3]; rotate it to ECEF like a position
    (``orbit.frames.eci_to_ecef`` without velocity), or pass an ECEF state to get it in ECEF directly
    (note: the flight frame then follows the ECEF velocity, which differs from the ECI one by w x r).
    """
    QR = flight_frame(r, v) @ control_rotation(pitch, yaw, exact)
    return np.einsum("...ij,...j->...i", QR, look_vector_control(look, side))


def along_track_axis(r, v, pitch=0.0, yaw=0.0, exact: bool = True) -> np.ndarray:
    """w = Q R e_x (..., 3): the control frame's along-track axis, normal of the look plane of [Koh2003, §3.1]."""
    return (flight_frame(r, v) @ control_rotation(pitch, yaw, exact))[..., :, 0]


def small_angle_pointing_error(look, pitch, yaw) -> np.ndarray:
    """Angle (rad) between the exact and small-angle beam directions in the control frame.

    Both use the same Lc; the small-angle matrix is not orthonormal, so its output is normalized
    before the angle is taken (acos of the dot product evaluated as 2*asin(|a-b|/2), exact for tiny angles).
    """
    lc = look_vector_control(look)
    a = np.einsum("...ij,...j->...i", control_rotation(pitch, yaw, True), lc)
    b = np.einsum("...ij,...j->...i", control_rotation(pitch, yaw, False), lc)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    return 2.0 * np.arcsin(np.clip(np.linalg.norm(a - b, axis=-1) / 2.0, 0.0, 1.0))
