"""Weighted 2-D polynomial fit z(x, y) = sum_{i<=dx, j<=dy} c_ij x^i y^j with outlier flags.

x, y are normalized coordinates (``Poly2D`` stores the offsets and scales, so evaluation takes physical
range in m and azimuth time in s). Outside the fitted domain the polynomial is held constant at the
domain edge (coordinates are clipped): a cubic extrapolated a few swath widths away swings by hundreds
of Hz, a clipped one cannot. A physical range law multiplies the polynomial by x^p (``x_power``, the
unclipped physical range): the effective-velocity Doppler rate fr = -2 Vr^2/(lam R) is the constant
c = -2 Vr^2/lam times R^-1, valid at every range. Outliers: after a weighted least-squares fit, blocks whose residual
exceeds ``k_sigma`` robust standard deviations (1.4826 * weighted MAD, floored at ``floor``) are
flagged and the fit is repeated without them, until no new block is flagged. Flagged blocks are kept in
the tables (with their flag), never silently used.
"""

from __future__ import annotations

import numpy as np

from sarcli.model.poly import Poly2D


def poly2d_design(x: np.ndarray, y: np.ndarray, degree: tuple[int, int]) -> np.ndarray:
    """Design matrix, columns x^i y^j for i in 0..dx, j in 0..dy (i outer)."""
    x = np.asarray(x, float).ravel()
    y = np.asarray(y, float).ravel()
    cols = [x**i * y**j for i in range(degree[0] + 1) for j in range(degree[1] + 1)]
    return np.stack(cols, axis=1)


def _norm(a: np.ndarray) -> tuple[float, float]:
    lo, hi = float(np.min(a)), float(np.max(a))
    return 0.5 * (lo + hi), max(0.5 * (hi - lo), 1e-12)


def fit_poly2d(x: np.ndarray, y: np.ndarray, z: np.ndarray, w: np.ndarray, degree: tuple[int, int] = (2, 1),
               k_sigma: float = 4.0, floor: float = 0.0, max_iter: int = 10,
               points_per_coef: int = 1) -> tuple[Poly2D, np.ndarray]:
    """Weighted LSQ fit with iterative outlier rejection. Returns (poly, outlier_flags).

    Degrees are reduced automatically so that every axis has at least ``points_per_coef`` distinct
    coordinates per coefficient (noisy block estimates: 2, so 3 range blocks give a constant and
    never an interpolating parabola that swings at the swath edges; noise-free model grids: 1).
    Blocks with zero/NaN weight or NaN z are ignored (not flagged).
    """
    x = np.asarray(x, float).ravel()
    y = np.asarray(y, float).ravel()
    z = np.asarray(z, float).ravel()
    w = np.asarray(w, float).ravel()
    use = np.isfinite(z) & np.isfinite(w) & (w > 0)
    x0, xs = _norm(x)
    y0, ys = _norm(y)
    dx = min(degree[0], max(len(np.unique(x[use])) // points_per_coef - 1, 0))
    dy = min(degree[1], max(len(np.unique(y[use])) // points_per_coef - 1, 0))
    flags = np.zeros(z.shape, bool)
    if not np.any(use):
        return Poly2D(np.full((1, 1), np.nan), x0, xs, y0, ys), flags
    A = poly2d_design((x - x0) / xs, (y - y0) / ys, (dx, dy))
    zz = np.where(use, z, 0.0)
    coef = np.zeros(A.shape[1])
    for _ in range(max_iter):
        m = use & ~flags
        sw = np.sqrt(w[m])
        coef, *_ = np.linalg.lstsq(A[m] * sw[:, None], zz[m] * sw, rcond=None)
        res = zz - A @ coef
        if m.sum() <= A.shape[1] + 2:
            break
        sigma = max(1.4826 * _weighted_median(np.abs(res[m]), w[m]), floor)
        new = use & (np.abs(res) > k_sigma * sigma)
        if np.array_equal(new, flags):
            break
        flags = new
    return Poly2D(coef.reshape(dx + 1, dy + 1), x0, xs, y0, ys), flags


def _weighted_median(a: np.ndarray, w: np.ndarray) -> float:
    o = np.argsort(a)
    cw = np.cumsum(w[o])
    return float(a[o][np.searchsorted(cw, 0.5 * cw[-1])])
