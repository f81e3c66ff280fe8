"""Trapezoidal single-axis motion (GRBL's planner for one isolated move): time and position.

A move of length d (mm) from rest to rest, with cruise speed v (mm/s) and acceleration a (mm/s^2),
accelerates for t_a = v/a over d_a = v^2/(2a). If d >= 2 d_a = v^2/a it cruises, total time
T = d/v + v/a; otherwise it is a triangle with peak speed sqrt(a d) and T = 2 sqrt(d/a).
"""

from __future__ import annotations

import math


def move_time(distance_mm: float, speed_mm_s: float, accel_mm_s2: float) -> float:
    """Duration (s) of a rest-to-rest move."""
    d = abs(distance_mm)
    if d == 0.0:
        return 0.0
    v, a = speed_mm_s, accel_mm_s2
    if d >= v * v / a:
        return d / v + v / a
    return 2.0 * math.sqrt(d / a)


def position_at(t: float, x0: float, x1: float, speed_mm_s: float, accel_mm_s2: float) -> float:
    """Position (mm) ``t`` seconds after a move from ``x0`` to ``x1`` started."""
    d = abs(x1 - x0)
    if d == 0.0 or t <= 0.0:
        return x0
    sign = 1.0 if x1 > x0 else -1.0
    v, a = speed_mm_s, accel_mm_s2
    total = move_time(d, v, a)
    if t >= total:
        return x1
    vp = min(v, math.sqrt(a * d))  # peak speed
    ta = vp / a
    if t < ta:
        s = 0.5 * a * t * t
    elif t < total - ta:
        s = 0.5 * a * ta * ta + vp * (t - ta)
    else:
        tr = total - t
        s = d - 0.5 * a * tr * tr
    return x0 + sign * s
