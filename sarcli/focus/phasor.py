"""Phasors for the backprojection kernels: ``exp(j k R)`` in float64 (:func:`cis`) and advanced by a
float32 second-order recurrence (:func:`cis_step`) re-anchored in float64, with its error bound.

Backprojection multiplies every (pixel, pulse) sample by ``exp(j k rho)`` (k = 4 pi / lam, rho the range
in metres). Evaluating cos/sin per sample dominates a straightforward kernel. Along a line of pixels
``q_0, q_1, ...`` (one pulse) the range ``rho_m = |q_m - a|`` is smooth, so with

    delta_m = rho_m - rho_{m-1},    eps_m = k (delta_m - delta_{m-1})   (the second difference)

the phasors obey ``D_m = D_{m-1} exp(j eps_m)``, ``P_m = P_{m-1} D_m`` (D_m = exp(j k delta_m),
P_m = exp(j k rho_m)): two complex products and a short polynomial of the small angle eps_m per sample
instead of a cosine and a sine of a phase of 1e2..1e8 rad. The ranges stay float64 (|q - a| of 1e4..1e6 m
needs float64 to resolve lam/100), the phasors are float32; every ``M`` samples the kernel re-anchors:
``P = cis(k rho)``, ``D = cis(k delta)`` from the float64 ranges.

**Size of eps.** For rho(s) = sqrt(A + (s - s_a)^2) along a straight line of pixels, |rho'| <= 1 and
0 <= rho'' = A / rho^3 <= 1 / rho, so for steps h_{m-1}, h_m (Taylor to second order)

    |delta_m - delta_{m-1}| <= |h_m - h_{m-1}| + max(h)^2 / rho_min,

``rho_min`` the smallest distance from the antenna to a pixel: :func:`second_difference_bound`. Where
``k`` times this exceeds :data:`EPS_MAX` (coarse grids close to the antenna) the kernels anchor every
sample (M = 1: the float64 phasor, no recurrence).

**Error bound** (u = 2^-24, float32 unit round-off; first order in u, the second-order terms are below
1e-8 for M <= 64):

- :func:`cis_step` for |eps| <= EPS_MAX: Taylor truncation <= EPS_MAX^6/720 (cos; sin: EPS_MAX^7/5040)
  plus the float32 rounding of the two Horner chains and of eps itself: ``eta_e <= 3 u + EPS_MAX^6/720``;
- a float32 complex product, naive formula without fused multiply-add: relative error <= sqrt(5) u
  [BrentPercivalZimmermann2007] (the kernels are compiled without ``contract``, so no FMA changes it);
- an anchor: :func:`cis` (3e-9) rounded to float32 (u per component): ``eta_a = u + 3e-9``.

Then ``|D~_m - D_m| <= eta_a + m (eta_e + sqrt(5) u)`` and, summing the errors of the D's into P,

    |P~_m - P_m| <= (m + 1) eta_a + m (m + 1) / 2 (eta_e + sqrt(5) u) + m sqrt(5) u,   m < M

(:func:`recurrence_bound`): quadratic in the distance m from the last anchor, reset to eta_a at each
anchor, so it never exceeds its value at m = M - 1 (4.1e-5 for M = 16). The float64 ranges add
``4 u_64 k (|q - a| + |r_ref|)`` (rounding of rho at both ends of the telescoping sum
sum_m k delta_m = k (rho_m - rho_anchor); the second differences themselves are exact to u_64 of their
tiny size): :func:`range_phase_bound`, 1.9e-7 rad at 1000 km and lam = 3 cm.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_TWO_PI = 2.0 * np.pi
_INV_TWO_PI = 1.0 / _TWO_PI

#: float32 unit round-off
U32 = 2.0 ** -24
#: float64 unit round-off
U64 = 2.0 ** -53
#: the largest second-difference phase (rad) the float32 step polynomial takes; beyond, anchor every sample
EPS_MAX = 0.125
#: samples between float64 anchors of the recurrence (the kernels' default)
ANCHOR_EVERY = 16
#: error of :func:`cis` (its docstring)
CIS_ERROR = 3e-9

_F1 = np.float32(1.0)
_C2 = np.float32(-0.5)
_C4 = np.float32(1.0 / 24)
_S3 = np.float32(-1.0 / 6)
_S5 = np.float32(1.0 / 120)


@njit(cache=True, inline="always", fastmath=True, error_model="numpy")
def cis(ph):
    """``(cos ph, sin ph)`` for any float64 ``ph``, branch-free so that the grid kernel's loop vectorizes
    (numba has no vector sin/cos without Intel SVML): r = ph mod 2 pi in [-pi, pi], h = r/2, Taylor
    series of sin h to h^13 and cos h to h^14 (|h| <= pi/2: truncation <= (pi/2)^15/15! = 7e-10), then
    the double angle; |error| < 3e-9 (tested against ``np.exp(1j ph)``)."""
    r = ph - _TWO_PI * np.floor(ph * _INV_TWO_PI + 0.5)
    h = 0.5 * r
    h2 = h * h
    s = h * (1.0 + h2 * (-1.0 / 6 + h2 * (1.0 / 120 + h2 * (-1.0 / 5040 + h2 * (
        1.0 / 362880 + h2 * (-1.0 / 39916800 + h2 * (1.0 / 6227020800)))))))
    c = 1.0 + h2 * (-0.5 + h2 * (1.0 / 24 + h2 * (-1.0 / 720 + h2 * (1.0 / 40320 + h2 * (
        -1.0 / 3628800 + h2 * (1.0 / 479001600 + h2 * (-1.0 / 87178291200)))))))
    return c * c - s * s, 2.0 * s * c


@njit(cache=True, inline="always", error_model="numpy")
def cis_step(e):
    """``exp(j e)`` for a float32 |e| <= :data:`EPS_MAX`: (cos, sin) by Taylor to e^4 and e^5, in float32
    (error <= 3 u + EPS_MAX^6/720, module docstring)."""
    e2 = e * e
    return _F1 + e2 * (_C2 + e2 * _C4), e * (_F1 + e2 * (_S3 + e2 * _S5))


@njit(cache=True, inline="always", error_model="numpy")
def anchor_phasor(k, rh, dl, c, pre, pim, dre, dim, rho, dlt):
    """Anchor the recurrence of sample ``c`` at range ``rh`` with last step ``dl`` (m): P = exp(j k rh) and
    D = exp(j k dl) from :func:`cis`, rounded to float32 into ``pre``/``pim`` and ``dre``/``dim``; the
    float64 ``rh`` and ``dl`` kept in ``rho`` and ``dlt`` (the kernels' per-sample state)."""
    c1, s1 = cis(k * rh)
    c2, s2 = cis(k * dl)
    pre[c] = np.float32(c1)
    pim[c] = np.float32(s1)
    dre[c] = np.float32(c2)
    dim[c] = np.float32(s2)
    rho[c] = rh
    dlt[c] = dl


@njit(cache=True, inline="always", error_model="numpy")
def advance_phasor(k, rh, c, pre, pim, dre, dim, rho, dlt):
    """Advance sample ``c``'s recurrence to range ``rh`` (m): delta = rh - rho, eps = k (delta - the last
    delta), D <- D exp(j eps) (:func:`cis_step`), P <- P D, in float32 (module docstring)."""
    dl = rh - rho[c]
    ec, es = cis_step(np.float32(k * (dl - dlt[c])))
    a = dre[c]
    b = dim[c]
    a2 = a * ec - b * es
    b2 = a * es + b * ec
    p = pre[c]
    q = pim[c]
    pre[c] = p * a2 - q * b2
    pim[c] = p * b2 + q * a2
    dre[c] = a2
    dim[c] = b2
    rho[c] = rh
    dlt[c] = dl


def recurrence_bound(m: int | np.ndarray) -> float | np.ndarray:
    """Bound on ``|P~_m - exp(j k rho_m)|`` m samples after an anchor (module docstring), float32 phasors."""
    eta_a = U32 + CIS_ERROR
    eta_e = 3 * U32 + EPS_MAX ** 6 / 720
    m = np.asarray(m, np.float64)
    return (m + 1) * eta_a + 0.5 * m * (m + 1) * (eta_e + math.sqrt(5) * U32) + m * math.sqrt(5) * U32


def range_phase_bound(k: float, r_max: float) -> float:
    """Phase error (rad) from the float64 ranges: ``4 u_64 k r_max``, r_max >= |q - a| + |r_ref|."""
    return 4 * U64 * k * r_max


def second_difference_bound(steps: np.ndarray, rho_min: float) -> float:
    """Bound (m) on ``|delta_m - delta_{m-1}|`` along pixels at coordinates ``s_0 + cumsum(steps)`` of a
    straight line, ranges >= ``rho_min`` > 0 (module docstring)."""
    h = np.abs(np.asarray(steps, np.float64))
    if h.size == 0:
        return 0.0
    jump = float(np.abs(np.diff(h)).max()) if h.size > 1 else 0.0
    return jump + float(h.max()) ** 2 / rho_min


def anchor_interval(k: float, steps: np.ndarray, rho_min: float, every: int = ANCHOR_EVERY) -> int:
    """Samples between anchors: ``every`` where k x :func:`second_difference_bound` <= EPS_MAX, else 1."""
    if not rho_min > 0:
        return 1
    return every if k * second_difference_bound(steps, rho_min) <= EPS_MAX else 1
