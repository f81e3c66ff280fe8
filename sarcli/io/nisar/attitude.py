"""NISAR attitude quaternions and sarcli's attitude convention (pitch and yaw of the beam-centre plane).

NISAR convention (ISCE3 ``isce3.core.Attitude``; L0B ``lowRateTelemetry/attitude``, RSLC
``metadata/attitude``): ``quaternions`` (n, 4) = (q0, q1, q2, q3), scalar first, unit norm; each one
rotates vectors from the antenna's radar coordinate system (RCS) to ECEF:
``v_ecef = M(q) v_rcs`` with the usual matrix of a unit quaternion (w, x, y, z) ::

    M = [[1 - 2(y^2 + z^2), 2(xy - wz),       2(xz + wy)],
         [2(xy + wz),       1 - 2(x^2 + z^2), 2(yz - wx)],
         [2(xz - wy),       2(yz + wx),       1 - 2(x^2 + y^2)]]

RCS axes (ISCE3 ``get_rcs2body``: body frame forward-right-down, RCS -> body = R(side) Ry(el) Rx(az)):
``z`` is the antenna boresight, ``y`` the antenna's along-track axis (pointing BACKWARD for a right-
looking radar, forward for a left-looking one), ``x = y X z`` the elevation axis. The elevation plane
of the antenna (the plane of the beam centre in azimuth) is therefore the RCS x-z plane, normal ``y``.

sarcli convention (``orbit.pointing``, used by ``sarcli.doppler.geometry``): the flight frame Q of the
ECI state (Xf along track, Yf right, Zf geodetic nadir) rotated by R = Rz(yaw) Ry(pitch); the
beam-centre plane is normal to the control along-track axis ``w = Q R e_x = Q (cy cp, sy cp, -sp)``.
So the quaternion gives the model's attitude exactly, as far as the beam-centre plane (and hence the
geometric Doppler centroid) is concerned::

    w = -s M e_y (s = +1 right-, -1 left-looking; forward along track), w_f = Q^T w (ECI)
    pitch = -asin(w_f,z),  yaw = atan2(w_f,y, w_f,x)

Roll turns the beam inside that plane; sarcli's beam model absorbs it in the look angle (the simulator
stores roll = 0), so ``roll`` carries the telemetry's Euler roll when the file has one, for inspection
only. The inverse (:func:`quaternions_from_model`) needs the boresight's look angle, which the model does
not hold: the writer gives it (the mid-swath look angle).
"""

from __future__ import annotations

import numpy as np

from orbit.frames import ecef_to_eci, eci_to_ecef
from orbit.pointing import control_rotation, flight_frame, look_vector_control, side_sign
from orbit.statevectors import StateVectors
from sarcli.errors import FormatError
from sarcli.model.raw import Attitude

UNIT_TOLERANCE = 1e-3  # |q| must be 1 within this (telemetry rounding); it is then normalized


def quaternion_matrices(q: np.ndarray, where: str = "quaternions") -> np.ndarray:
    """(n, 3, 3) rotation matrices of unit quaternions (n, 4), scalar first (module docstring)."""
    q = np.asarray(q, np.float64)
    if q.ndim != 2 or q.shape[1] != 4:
        raise FormatError(f"{where}: quaternions must be (n, 4), got shape {q.shape}")
    if not np.all(np.isfinite(q)):
        raise FormatError(f"{where}: quaternions contain NaN or inf")
    norm = np.linalg.norm(q, axis=1)
    bad = np.abs(norm - 1.0) > UNIT_TOLERANCE
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise FormatError(f"{where}: quaternion {k} has norm {norm[k]:.6g}, not 1: not a rotation")
    w, x, y, z = (q / norm[:, None]).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def matrices_to_quaternions(m: np.ndarray) -> np.ndarray:
    """Unit quaternions (n, 4), scalar first and w >= 0, of rotation matrices (n, 3, 3) (Shepperd's
    method: the largest of 4w^2, 4x^2, 4y^2, 4z^2 = 1 + trace terms is used as the pivot)."""
    m = np.asarray(m, np.float64)
    tr = m[:, 0, 0] + m[:, 1, 1] + m[:, 2, 2]
    piv = np.stack([1 + tr, 1 + 2 * m[:, 0, 0] - tr, 1 + 2 * m[:, 1, 1] - tr, 1 + 2 * m[:, 2, 2] - tr], -1)
    k = np.argmax(piv, axis=1)
    q = np.empty((m.shape[0], 4))
    for i in range(m.shape[0]):
        a = m[i]
        s = 2.0 * np.sqrt(piv[i, k[i]])  # = 4 * (the pivot component)
        if k[i] == 0:
            q[i] = (s / 4, (a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s)
        elif k[i] == 1:
            q[i] = ((a[2, 1] - a[1, 2]) / s, s / 4, (a[0, 1] + a[1, 0]) / s, (a[0, 2] + a[2, 0]) / s)
        elif k[i] == 2:
            q[i] = ((a[0, 2] - a[2, 0]) / s, (a[0, 1] + a[1, 0]) / s, s / 4, (a[1, 2] + a[2, 1]) / s)
        else:
            q[i] = ((a[1, 0] - a[0, 1]) / s, (a[0, 2] + a[2, 0]) / s, (a[1, 2] + a[2, 1]) / s, s / 4)
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def model_attitude(time: np.ndarray, quaternions: np.ndarray, sv: StateVectors, side: str,
                   roll: np.ndarray | None = None, where: str = "attitude") -> Attitude:
    """sarcli :class:`Attitude` (pitch, yaw exact for the beam-centre plane; module docstring) at the
    quaternion times (s after ``sv.epoch_utc``, inside the orbit span). ``roll``: the telemetry's
    Euler roll (rad) when known, else zeros. Refuses a beam on the other side than ``side``."""
    t = np.asarray(time, np.float64)
    m = quaternion_matrices(quaternions, where)
    s = side_sign(side)
    sv_eci = sv.to_eci()
    r, v, _ = sv_eci.interpolate(t)
    w_ecef = -s * m[:, :, 1]
    w = ecef_to_eci(sv.epoch_utc, t, w_ecef)
    b = ecef_to_eci(sv.epoch_utc, t, m[:, :, 2])
    q = flight_frame(r, v)
    wf = np.einsum("nji,nj->ni", q, w)
    bf = np.einsum("nji,nj->ni", q, b)
    if np.any(wf[:, 0] <= 0) or np.any(s * bf[:, 1] <= 0):
        other = "left" if s > 0 else "right"
        raise FormatError(f"{where}: the attitude points the antenna to the {other} of the ground track, or its "
                          f"along-track axis backward, but the product says {side}-looking")
    pitch = -np.arcsin(np.clip(wf[:, 2], -1.0, 1.0))
    yaw = np.arctan2(wf[:, 1], wf[:, 0])
    rl = np.zeros(t.size) if roll is None else np.asarray(roll, np.float64)
    return Attitude(t.copy(), pitch, rl.copy(), yaw)


def quaternions_from_model(attitude: Attitude, sv: StateVectors, side: str, look_angle_rad: float) -> np.ndarray:
    """NISAR quaternions (n, 4) at the attitude times for the model attitude and a boresight at
    ``look_angle_rad`` from the geodetic nadir in the beam-centre plane (inverse of
    :func:`model_attitude` for pitch and yaw). RCS axes: z = boresight, y = -s w, x = y X z."""
    t = np.asarray(attitude.time, np.float64)
    sv_eci = sv.to_eci()
    r, v, _ = sv_eci.interpolate(t)
    qr = flight_frame(r, v) @ control_rotation(np.asarray(attitude.pitch, np.float64),
                                               np.asarray(attitude.yaw, np.float64))
    s = side_sign(side)
    w = qr[..., :, 0]
    b = np.einsum("nij,j->ni", qr, look_vector_control(look_angle_rad, side))
    y = eci_to_ecef(sv.epoch_utc, t, -s * w)
    z = eci_to_ecef(sv.epoch_utc, t, b)
    x = np.cross(y, z)
    return matrices_to_quaternions(np.stack([x, y, z], axis=-1))


def antenna_axes_ecef(time_q: np.ndarray, quaternions: np.ndarray, t: np.ndarray,
                      where: str = "attitude") -> np.ndarray:
    """(len(t), 3, 3) RCS -> ECEF matrices at times ``t``: spherical linear interpolation between the
    neighbouring quaternions (held at the ends), with the sign of each quaternion chosen to follow its
    predecessor (q and -q are the same rotation)."""
    tq = np.asarray(time_q, np.float64)
    q = np.asarray(quaternions, np.float64)
    quaternion_matrices(q, where)  # validation
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    for i in range(1, q.shape[0]):
        if np.dot(q[i], q[i - 1]) < 0:
            q[i] = -q[i]
    t = np.clip(np.asarray(t, np.float64), tq[0], tq[-1])
    if tq.size == 1:
        return quaternion_matrices(np.repeat(q, t.size, axis=0), where)
    k = np.clip(np.searchsorted(tq, t, side="right") - 1, 0, tq.size - 2)
    u = (t - tq[k]) / (tq[k + 1] - tq[k])
    a, b = q[k], q[k + 1]
    cos_o = np.clip(np.sum(a * b, axis=1), -1.0, 1.0)
    omega = np.arccos(cos_o)
    small = omega < 1e-9
    so = np.where(small, 1.0, np.sin(omega))
    ca = np.where(small, 1.0 - u, np.sin((1.0 - u) * omega) / so)
    cb = np.where(small, u, np.sin(u * omega) / so)
    return quaternion_matrices(ca[:, None] * a + cb[:, None] * b, where)
