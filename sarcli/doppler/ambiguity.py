"""PRF ambiguity of the Doppler centroid ([Koh2003, eq. 7-8], with margins and the half-integer case).

The data give the centroid modulo the PRF: fdc = fdc_bb + n * PRF. [Koh2003, eq. 7] rounds each block
independently, n = round((fdc_pred - fdc_bb) / PRF). Two things go wrong with that near a rounding
boundary: neighbouring blocks can flip between n and n+1, and ``round`` of an exact half-integer is
undefined (numpy rounds to even). Here instead

1. the baseband centroids are *unwrapped* over the block grid against a smooth reference (iterated
   weighted polynomial fit on the circle), so that fdc_u = fdc_bb + k_i * PRF is continuous and the
   integers k_i are fixed by the data alone;
2. ONE integer n0 for the whole scene is chosen from the weighted mean of
   x_i = (fdc_pred_i - fdc_u_i) / PRF: n0 = floor(x + 1/2), so block ambiguities n_i = n0 + k_i can
   never disagree with their neighbours because of the prediction;
3. the margin is 1/2 - |x - n0| in PRF units (0 means exactly half-way); when it is below
   ``half_tolerance`` the case is *declared* ambiguous (``resolved = False``) instead of silently
   picking a side, and the caller may break the tie with another source (data-only estimate).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.doppler.cde import wrap_frequency
from sarcli.doppler.polyfit import fit_poly2d


@dataclass
class AmbiguityResult:
    """Scene ambiguity n0, per-block ambiguity, margins (PRF units) and whether it was resolved."""

    n0: int
    block_ambiguity: np.ndarray
    margin: float
    block_margin: np.ndarray
    offset_prf: float
    resolved: bool


def unwrap_blocks(fdc_bb: np.ndarray, weight: np.ndarray, prf: float, x: np.ndarray, y: np.ndarray,
                  degree: tuple[int, int] = (1, 1), iterations: int = 4) -> np.ndarray:
    """Continuous centroid over the block grid: fdc_bb + k * PRF with integers k chosen per block so
    that the result follows a weighted smooth (polynomial in normalized x, y) reference surface.

    ``x``, ``y`` are the block coordinates (any units, same shape as ``fdc_bb``). The first reference is
    the circular weighted mean (phase of sum w*exp(j*2*pi*fdc/PRF)); every iteration refits the
    polynomial to the currently unwrapped values and re-wraps each block around it.
    Blocks of zero weight are unwrapped around the reference too (they are not used to fit it).
    """
    f = np.asarray(fdc_bb, float)
    w = np.where(np.isfinite(f), np.asarray(weight, float), 0.0)
    fz = np.where(np.isfinite(f), f, 0.0)
    if not np.any(w > 0):
        return f.copy()
    ph = np.exp(2j * np.pi * fz / prf)
    ref = np.full(f.shape, prf * np.angle(np.sum(w * ph)) / (2 * np.pi))
    for _ in range(iterations):
        fu = ref + wrap_frequency(fz - ref, prf)
        poly, _ = fit_poly2d(x, y, fu, w, degree, k_sigma=6.0, floor=0.01 * prf)
        ref = poly(x, y).reshape(f.shape)
    fu = ref + wrap_frequency(fz - ref, prf)
    return np.where(np.isfinite(f), fu, np.nan)


def resolve(fdc_bb: np.ndarray, fdc_unwrapped: np.ndarray, fdc_pred: np.ndarray | float, weight: np.ndarray,
            prf: float, half_tolerance: float = 0.02) -> AmbiguityResult:
    """Scene and per-block ambiguity from a predicted absolute centroid (orbit model or data-only).

    ``fdc_pred`` may be a scalar or per block. ``half_tolerance`` (PRF units): margins below it are
    reported as unresolved (the half-integer case).
    """
    fbb = np.asarray(fdc_bb, float)
    fu = np.asarray(fdc_unwrapped, float)
    pred = np.broadcast_to(np.asarray(fdc_pred, float), fbb.shape)
    w = np.where(np.isfinite(fu) & np.isfinite(pred), np.asarray(weight, float), 0.0)
    if not np.any(w > 0):
        w = np.where(np.isfinite(fu) & np.isfinite(pred), 1.0, 0.0)
    xi = (pred - fu) / prf
    x = float(np.sum(np.where(w > 0, w * xi, 0.0)) / np.sum(w))
    n0 = int(np.floor(x + 0.5))
    margin = 0.5 - abs(x - n0)
    k = np.where(np.isfinite(fu) & np.isfinite(fbb), np.rint((fu - fbb) / prf), 0.0)
    nb = (n0 + k).astype(np.int64)
    xb = (pred - fbb) / prf
    block_margin = 0.5 - np.abs(xb - nb)
    return AmbiguityResult(n0, nb, margin, block_margin, x, bool(margin >= half_tolerance))


def coverage_factor(dof: float) -> float:
    """t_{0.975, dof} / z_{0.975}: the factor that turns a standard error estimated with ``dof`` degrees of
    freedom into the standard deviation of a Gaussian with the same 95 % interval, so that "within 2
    sigma" keeps its meaning for an error estimated from a few groups (8 groups: 1.21; inf: 1).
    The quantiles from scipy.special's inverse CDFs (Student-t ``stdtrit``, normal ``ndtri``: what
    scipy.stats' ``t.ppf`` and ``norm.ppf`` evaluate, without importing scipy.stats, 0.3 s)."""
    from scipy.special import ndtri, stdtrit

    if not dof > 0:
        return float("inf")
    return float(stdtrit(dof, 0.975) / ndtri(0.975))


def rounding_confidence(offset: float, sigma: float, dof: float | None = None) -> float:
    """P(round(X) = round(offset)) where the error of the estimate ``offset`` has standard error
    ``sigma``: Gaussian, or Student-t with ``dof`` degrees of freedom when sigma itself was estimated
    from few samples (small-sample honesty: 3 blocks never give a Gaussian-sized confidence). 0..1."""
    from scipy.special import ndtr, stdtr  # the normal and Student-t CDFs (scipy.stats costs 0.3 s to import)

    if not np.isfinite(offset) or not np.isfinite(sigma):
        return 0.0
    n = np.floor(offset + 0.5)
    if sigma <= 0:
        return 1.0
    if dof is None:
        return float(ndtr((n + 0.5 - offset) / sigma) - ndtr((n - 0.5 - offset) / sigma))
    nu = max(float(dof), 1e-3)
    return float(stdtr(nu, (n + 0.5 - offset) / sigma) - stdtr(nu, (n - 0.5 - offset) / sigma))
