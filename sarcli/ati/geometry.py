"""Flat-Earth range history of a ground moving target and its inversion ([Ryu2017, §II]).

Frame (the simulator's LOCAL frame): x cross-track ground range (+x on the right of the flight
direction), y along-track, z up. Slow time ``eta`` (s) is counted from the reference time at which
the platform is at ``(0, 0, H)`` and the target at ``(x0, y0, 0)``:

    platform  r1(eta) = (0, Vp*eta, H)
    target    r2(eta) = (x0 + vx*eta, y0 + vy*eta, 0)         ([Ryu2017, eq. 3] fixed: target on the ground)

With ``u = vy - Vp`` (relative along-track velocity) and ``V2 = vx**2 + u**2``:

    R(eta)**2 = R0**2 + 2*R0*vR*eta + V2*eta**2                (exactly quadratic)
    R0 = sqrt(x0**2 + y0**2 + H**2),   vR = (vx*x0 + u*y0)/R0
    aR = d2R/deta2 at 0 = (V2 - vR**2)/R0                       (exact; [Ryu2017, eq. 4] prints
                                                                 (vx**2+u**2)/(2*R0): drops vR**2 and
                                                                 mixes in the 1/2 of eq. 2)

so ``R(eta) = R0 + vR*eta + aR*eta**2/2 + O(eta**3)``; in this module ``aR`` is always the full
second derivative. Split ([Ryu2017, eq. 5-7]) ``R = Rs + Rm`` with ``Rs`` the range history of a
*stationary* point at (x0, y0) (what a stationary-scene RDA matches) and ``Rm`` the rest:

    vs = -y0*Vp/R0,            as = (Vp**2 - vs**2)/R0
    vm = vR - vs = (vx*x0 + vy*y0)/R0
    am = aR - as = (vx**2 + vy**2 - 2*vy*Vp - vR**2 + vs**2)/R0  ([Ryu2017, eq. 7] drops -vR**2 + vs**2)

``vm`` displaces the mover in azimuth by about ``-R0*vm/Vp``; ``am`` defocuses it. The
"conventional" compensation replaces ``vm`` by ``vx*x0/R0`` (neglects ``vy*y0/R0``).

ATI phase (DRA: one transmitter, two receivers ``d`` apart along-track). The bistatic echo of
receiver k at along-track offset ``dk`` equals a monostatic echo from the phase centre ``dk/2``
(to first order), so the two images see the scene ``d/(2*Vp)`` s apart. After co-registration a
target with line-of-sight range rate ``vr_los`` (positive = receding) gives

    phi_ATI = arg(Z_fore * conj(Z_aft)) = +(4*pi/lam) * vr_los * d/(2*Vp)

with our phase convention exp(-j*4*pi*R/lam) (fore = the receiver ahead along-track). A ground
velocity vx maps to ``vr_los = vx * x0/R0`` (x0/R0 = sin of the look angle; [Ryu2017, eq. 10-11]
write ``cos(theta)`` for an angle measured from the horizontal and use ``d`` instead of ``d/2``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sarcli.errors import SarcliError


@dataclass(frozen=True)
class Mover:
    """Ground mover at the reference time: position (m) and velocity (m/s) in the LOCAL frame."""

    x0: float
    y0: float
    vx: float
    vy: float


@dataclass(frozen=True)
class Platform:
    """Straight, level flight: height H (m) and speed Vp (m/s) along +y; wavelength lam (m)."""

    height: float
    speed: float
    wavelength: float


def range_history(eta: np.ndarray, m: Mover, p: Platform) -> np.ndarray:
    """Exact one-way slant range R(eta) (m), float64."""
    eta = np.asarray(eta, dtype=np.float64)
    return np.sqrt((m.x0 + m.vx * eta) ** 2 + (m.y0 + (m.vy - p.speed) * eta) ** 2 + p.height ** 2)


def stationary_history(eta: np.ndarray, x0: float, y0: float, p: Platform) -> np.ndarray:
    """Range history Rs(eta) of a stationary point at (x0, y0, 0) (m)."""
    return range_history(eta, Mover(x0, y0, 0.0, 0.0), p)


@dataclass(frozen=True)
class RangeCoefficients:
    """Taylor coefficients of R(eta) at eta = 0 and the Rs/Rm split (SI units)."""

    r0: float
    vr: float
    ar: float
    vs: float
    as_: float
    vm: float
    am: float


def coefficients(m: Mover, p: Platform) -> RangeCoefficients:
    """Exact R0, vR, aR (full second derivative) and the stationary/mover split at eta = 0."""
    u = m.vy - p.speed
    r0 = math.sqrt(m.x0 ** 2 + m.y0 ** 2 + p.height ** 2)
    vr = (m.vx * m.x0 + u * m.y0) / r0
    ar = (m.vx ** 2 + u ** 2 - vr ** 2) / r0
    vs = -m.y0 * p.speed / r0
    as_ = (p.speed ** 2 - vs ** 2) / r0
    return RangeCoefficients(r0, vr, ar, vs, as_, vr - vs, ar - as_)


def azimuth_displacement(m: Mover, p: Platform) -> float:
    """First-order azimuth shift (m) of the mover in a stationary-focused image: -R0*vm/Vp."""
    c = coefficients(m, p)
    return -c.r0 * c.vm / p.speed


def ati_phase(vr_los: np.ndarray | float, baseline_m: float, p: Platform) -> np.ndarray | float:
    """ATI phase (rad, not wrapped) of a line-of-sight range rate (m/s) for a DRA baseline d."""
    return 4.0 * np.pi / p.wavelength * np.asarray(vr_los) * (0.5 * baseline_m / p.speed)


def los_rate_from_phase(phi: np.ndarray | float, baseline_m: float, p: Platform) -> np.ndarray | float:
    """Inverse of :func:`ati_phase`: line-of-sight range rate (m/s) from the ATI phase (rad)."""
    if baseline_m == 0:
        raise SarcliError("ATI baseline d is zero: the two receivers coincide")
    return np.asarray(phi) * p.wavelength * p.speed / (4.0 * np.pi * 0.5 * baseline_m)


def blind_speed(baseline_m: float, p: Platform) -> float:
    """Line-of-sight speed (m/s) at which the ATI phase wraps by 2*pi (velocity ambiguity)."""
    return abs(float(los_rate_from_phase(2.0 * np.pi, baseline_m, p)))


def ground_vx_from_los(vr_los: float, r0: float, height: float) -> float:
    """Ground-range velocity vx (m/s) from the LOS rate, vx = vr_los * R0/x0 (x0 = sqrt(R0^2-H^2))."""
    g = r0 * r0 - height * height
    if g <= 0:
        raise SarcliError(f"slant range {r0:.1f} m is not longer than the platform height {height:.1f} m")
    return vr_los * r0 / math.sqrt(g)
