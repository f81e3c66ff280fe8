"""Weighted least squares with covariance, noise and weights for phase data, error propagation.

Phase noise model: a sample ``s = A*exp(j*psi) + n`` with complex noise of power ``sigma2``
(E|n|^2) has, for A^2 >> sigma2, phase variance ``sigma2/(2*A^2)``. The weights of a phase fit
are therefore ``w = 2*A^2/sigma2`` with ``A^2`` estimated as ``max(|s|^2 - sigma2, 0)``; samples
below a power gate (noise only, e.g. after the mover has left the scene) get weight 0.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sarcli.errors import SarcliError


@dataclass(frozen=True)
class PolyFit:
    """Coefficients (ascending powers), their covariance and the reduced chi-square of the fit."""

    coef: np.ndarray
    cov: np.ndarray
    chi2_red: float
    n_used: int


def _wls(t: np.ndarray, y: np.ndarray, w: np.ndarray, deg: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    use = w > 0
    n = int(use.sum())
    if n <= deg + 1:
        raise SarcliError(f"polynomial fit needs more than {deg + 1} usable samples, got {n}")
    x = np.vander(t[use], deg + 1, increasing=True)
    sw = np.sqrt(w[use])
    q, r = np.linalg.qr(x * sw[:, None])
    coef = np.linalg.solve(r, q.T @ (y[use] * sw))
    rinv = np.linalg.inv(r)
    resid = np.zeros_like(y)
    resid[use] = (y[use] - x @ coef) * sw
    return coef, rinv @ rinv.T, resid


def wls_poly(t: np.ndarray, y: np.ndarray, w: np.ndarray, deg: int = 2, clip: float | None = None) -> PolyFit:
    """Weighted LS polynomial fit ``y ~ sum_k c_k t^k`` with weights ``w = 1/var(y)``.

    The covariance is ``(X^T W X)^-1`` scaled by ``max(1, chi2_red)``: when the residuals are larger
    than the weights promise (model misfit, an unwrapping slip) the uncertainty grows honestly.
    ``clip``: refit (up to 3 times) without samples whose normalized residual exceeds
    ``clip*sqrt(max(1, chi2_red))`` (noise-only samples, isolated cycle slips).
    """
    t = np.asarray(t, np.float64)
    y = np.asarray(y, np.float64)
    w = np.asarray(w, np.float64).copy()
    for _ in range(4 if clip else 1):
        coef, cov, resid = _wls(t, y, w, deg)
        n = int(np.count_nonzero(w > 0))
        chi2_red = float(resid @ resid) / (n - deg - 1)
        bad = np.abs(resid) > (clip or np.inf) * np.sqrt(max(1.0, chi2_red))
        if not bad.any():
            break
        w[bad] = 0.0
    return PolyFit(coef, cov * max(1.0, chi2_red), chi2_red, n)


def noise_power(s: np.ndarray) -> float:
    """Complex noise power E|n|^2 from first differences (robust to a slowly varying signal).

    After the dominant chirp is removed a mover's signal changes little between samples, so
    ``|s[i+1]-s[i]|^2`` is exponential with mean 2*sigma2; its median is 2*sigma2*ln 2.
    """
    d = np.diff(np.asarray(s, dtype=np.complex128))
    if d.size == 0:
        raise SarcliError("noise estimate needs at least two samples")
    return float(np.median(np.abs(d) ** 2) / (2.0 * np.log(2.0)))


def phase_weights(s: np.ndarray, sigma2: float, smooth: int | None = None, gate_sigmas: float = 4.0
                  ) -> np.ndarray:
    """Inverse phase variances ``2*A^2/sigma2`` with ``A^2 = <|s|^2> - sigma2`` (``smooth``-sample
    moving average, default max(31, n/8): a mover entering/leaving is blurred over 1/8 of the
    aperture); 0 where ``<|s|^2>`` is within ``gate_sigmas`` standard errors of the noise power (no
    signal there, e.g. the mover has left the scene)."""
    p = np.abs(np.asarray(s)) ** 2
    if sigma2 <= 0:
        return np.where(p > 0, 1e12, 0.0)
    m = max(31, p.size // 8) if smooth is None else int(smooth)
    m = max(1, min(m, p.size // 4))
    ms = min(m, 31)
    w = 2.0 * np.maximum(_movavg(p, ms) - sigma2, 0.0) / sigma2
    w[_movavg(p, m) < sigma2 * (1.0 + gate_sigmas / np.sqrt(m))] = 0.0
    return w


def _movavg(p: np.ndarray, m: int) -> np.ndarray:
    k = np.ones(m)
    return np.convolve(p, k, mode="same") / np.convolve(np.ones_like(p), k, mode="same")


def propagate(fn: Callable[[np.ndarray], np.ndarray], x: np.ndarray, cov: np.ndarray,
              rel_step: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """``(fn(x), J C J^T)`` with a central-difference Jacobian (steps scaled by sqrt(diag C))."""
    x = np.asarray(x, np.float64)
    y0 = np.asarray(fn(x), np.float64)
    jac = np.zeros((y0.size, x.size))
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    for i in range(x.size):
        h = max(sd[i] * 1e-3, rel_step * max(abs(x[i]), 1e-9))
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        jac[:, i] = (np.asarray(fn(xp)) - np.asarray(fn(xm))) / (2.0 * h)
    return y0, jac @ cov @ jac.T
