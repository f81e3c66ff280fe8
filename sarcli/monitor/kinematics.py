"""Velocity and acceleration from the last few displacement maps, and the inverse-velocity forecast.

Velocity: least-squares slope of ``d(t)`` over the window; acceleration: twice the quadratic
coefficient of ``d = c0 + c1 tau + c2 tau^2`` (tau = t - mean t) over its window. Both are linear in
the displacements, ``sum_i q_i d_i``: the weights ``q`` depend on the times only and are computed
once per scan for the whole map (O(window x pixels), whatever the number of scans stored).
A windowed slope estimates the velocity at the window's mean time, so the inverse-velocity samples
are placed there.

Inverse velocity [Fukuzono1985], [Voight1988]: before a failure the velocity grows as
``1/v = A (t_f - t)^(1/(alpha-1))``; with alpha = 2 (the common case) 1/v falls linearly to 0 at the
failure time t_f. A straight line fitted to 1/v(t) over the accelerating phase gives
``t_f = -q/m`` (``1/v = m t + q``, m < 0).
"""

from __future__ import annotations

import numpy as np


def slope_weights(t: np.ndarray) -> np.ndarray:
    """Weights q with ``sum q_i d_i`` = least-squares slope of d over times t (needs >= 2 distinct)."""
    t = np.asarray(t, np.float64)
    tau = t - t.mean()
    den = float(np.sum(tau * tau))
    return tau / den if den > 0 else np.zeros_like(t)


def acceleration_weights(t: np.ndarray) -> np.ndarray:
    """Weights q with ``sum q_i d_i`` = 2 c2 of the least-squares quadratic (needs >= 3 distinct times)."""
    t = np.asarray(t, np.float64)
    if t.size < 3:
        return np.zeros_like(t)
    tau = t - t.mean()
    a = np.column_stack([np.ones_like(tau), tau, tau * tau])
    if np.linalg.matrix_rank(a) < 3:
        return np.zeros_like(t)
    return 2.0 * np.linalg.pinv(a)[2]


def weighted_sum(weights: np.ndarray, maps: np.ndarray) -> np.ndarray:
    """``sum_i w_i maps[i]`` in float64, returned as float32 (maps: (n, ...) float32)."""
    out = np.zeros(maps.shape[1:], np.float64)
    for w, m in zip(weights, maps, strict=True):
        if w:
            out += w * m
    return out.astype(np.float32)


def inverse_velocity_forecast(t_h: np.ndarray, v: np.ndarray) -> tuple[float, float, float] | None:
    """(t_f in h, slope m of 1/v in h/mm per h, r^2 of the line) from velocity samples ``v`` (mm/h,
    same sign) at ``t_h``; None when 1/v does not decrease."""
    t = np.asarray(t_h, np.float64)
    iv = 1.0 / np.abs(np.asarray(v, np.float64))
    if t.size < 3 or not np.all(np.isfinite(iv)):
        return None
    ss = float(np.sum((iv - iv.mean()) ** 2))
    if not ss > 1e-12 * float(np.sum(iv * iv)):  # 1/v constant to rounding: no trend at all
        return None
    m, q = np.polyfit(t, iv, 1)
    if not m < 0:
        return None
    r2 = 1.0 - float(np.sum((iv - (m * t + q)) ** 2)) / ss
    return float(-q / m), float(m), r2
