"""Atmospheric phase screen (APS) of a GB-SAR scan, fitted on stable points.

Physics. With a refractivity N (ppm) along the path, the two-way phase of a scatterer at range R is
``-4 pi R (1 + 1e-6 N)/lam`` (the project's convention ``exp(-j 4 pi R/lam)``), so a change dN between
two scans adds ``-4 pi 1e-6 dN R/lam``: a phase linear in range, i.e. an apparent LOS displacement
``1e-6 dN R`` whatever the wavelength ([Noferini2005], [IanniniMontiGuarnieri2011]: at 1 km, 1 ppm is
1 mm). A vertical refractivity gradient G (ppm/m) adds along the straight path from the antenna at
height h to a pixel at height z the mean ``G (z - h)/2``, a term in ``R (z - h)`` [Iglesias2014]. The
model, in radians, is therefore

    phi_aps(R, z) = a + b R [+ c R (z - h)]

(a: the phase of the reference, common to every pixel; the height term only with a DEM). The
range coefficient is a refractivity change ``dN = -b lam / (4 pi 1e-6)`` (ppm).

Estimation. ``fit`` solves the model by iteratively reweighted least squares with Huber weights
``min(1, k s/|r|)``, ``s = 1.4826 MAD`` of the residuals [Huber1964]: the moving or noisy points that
slipped into the stable set get small weights. ``fit_wrapped`` does it on a wrapped phase (an
increment between consecutive scans): a coarse search of the range slope maximising the coherent sum
``|sum exp(j (w - b R))|`` (exact for the constant), then the same IRLS on the wrapped residuals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def wrap(x: np.ndarray) -> np.ndarray:
    """Phase wrapped to [-pi, pi)."""
    return (np.asarray(x) + np.pi) % (2 * np.pi) - np.pi


@dataclass
class ApsModel:
    """Coefficients in physical units: ``a`` (rad), ``b`` (rad/m), ``c`` (rad/m^2, 0 without heights)."""

    a: float = 0.0
    b: float = 0.0
    c: float = 0.0
    kind: str = "none"  # none | constant | range | range-height
    n_points: int = 0

    def evaluate(self, ranges: np.ndarray, dz: np.ndarray | None) -> np.ndarray:
        """The model (rad) at ranges R and height differences z - h (same shapes; ``dz`` None: 0)."""
        out = self.a + self.b * np.asarray(ranges, np.float64)
        if dz is not None and self.c:
            out = out + self.c * np.asarray(ranges, np.float64) * dz
        return out

    def refractivity_ppm(self, wavelength_m: float) -> float:
        """The range coefficient as a refractivity change (ppm): ``dN = -b lam / (4 pi 1e-6)``."""
        return float(-self.b * wavelength_m / (4 * np.pi * 1e-6))


def _basis(r: np.ndarray, dz: np.ndarray | None, kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normalised design matrix (n, p) with its column centres and scales (conditioning)."""
    cols = [np.ones_like(r)]
    if kind in ("range", "range-height"):
        cols.append(r)
    if kind == "range-height":
        cols.append(r * dz)
    m = np.column_stack(cols)
    centre = np.zeros(m.shape[1])
    scale = np.ones(m.shape[1])
    for j in range(1, m.shape[1]):
        centre[j] = float(np.mean(m[:, j]))
        scale[j] = float(np.std(m[:, j])) or 1.0
        m[:, j] = (m[:, j] - centre[j]) / scale[j]
    return m, centre, scale


def _physical(coef: np.ndarray, centre: np.ndarray, scale: np.ndarray, kind: str, n: int) -> ApsModel:
    slopes = coef[1:] / scale[1:]
    a = float(coef[0] - np.sum(slopes * centre[1:]))
    b = float(slopes[0]) if slopes.size > 0 else 0.0
    c = float(slopes[1]) if slopes.size > 1 else 0.0
    return ApsModel(a=a, b=b, c=c, kind=kind, n_points=n)


def _irls(m: np.ndarray, y: np.ndarray, k: float, residual, iterations: int = 20) -> np.ndarray:
    """Huber IRLS of ``y ~ m @ coef`` where ``residual(coef)`` gives the residuals (wrapped or not)."""
    coef = np.linalg.lstsq(m, y, rcond=None)[0]
    for _ in range(iterations):
        r = residual(coef)
        s = 1.4826 * float(np.median(np.abs(r - np.median(r))))
        if s <= 0:
            break
        w = np.minimum(1.0, k * s / np.maximum(np.abs(r), 1e-300))
        sw = np.sqrt(w)
        step = np.linalg.lstsq(m * sw[:, None], sw * r, rcond=None)[0]
        coef = coef + step
        if np.all(np.abs(step) < 1e-10 * (1 + np.abs(coef))):
            break
    return coef


def choose_kind(n_points: int, min_points: int, has_heights: bool) -> str:
    if n_points == 0:
        return "none"
    if n_points < min_points:
        return "constant"
    return "range-height" if has_heights else "range"


def fit(phase: np.ndarray, ranges: np.ndarray, dz: np.ndarray | None, kind: str, huber_k: float = 1.345) -> ApsModel:
    """Robust fit of the model ``kind`` to an unwrapped phase (rad) at stable points (1-D arrays)."""
    y = np.asarray(phase, np.float64)
    if kind == "none" or y.size == 0:
        return ApsModel(n_points=int(y.size))
    r = np.asarray(ranges, np.float64)
    m, centre, scale = _basis(r, None if dz is None else np.asarray(dz, np.float64), kind)
    coef = _irls(m, y, huber_k, lambda c: y - m @ c)
    return _physical(coef, centre, scale, kind, y.size)


def fit_wrapped(phase: np.ndarray, ranges: np.ndarray, dz: np.ndarray | None, kind: str, wavelength_m: float,
                huber_k: float = 1.345, max_refractivity_ppm: float = 100.0) -> ApsModel:
    """Robust fit of the model to a *wrapped* phase (an increment between scans) at stable points.

    The range slope is first searched over ``|dN| <= max_refractivity_ppm`` on a grid of a quarter of
    the slope resolution ``2 pi / span(R)``, maximising the coherent sum; then Huber IRLS on the
    wrapped residuals refines every coefficient.
    """
    w = np.asarray(phase, np.float64)
    if kind == "none" or w.size == 0:
        return ApsModel(n_points=int(w.size))
    z = np.exp(1j * w)
    r = np.asarray(ranges, np.float64)
    b0 = 0.0
    if kind != "constant":
        span = float(np.ptp(r)) or 1.0
        b_max = 4 * np.pi * 1e-6 * max_refractivity_ppm / wavelength_m
        step = np.pi / (2 * span)
        grid = np.arange(-np.ceil(b_max / step), np.ceil(b_max / step) + 1) * step
        power = np.abs(np.exp(-1j * np.outer(grid, r - r.mean())) @ z)
        b0 = float(grid[int(np.argmax(power))])
    a0 = float(np.angle(np.sum(z * np.exp(-1j * b0 * r))))
    m, centre, scale = _basis(r, None if dz is None else np.asarray(dz, np.float64), kind)
    first = np.zeros(m.shape[1])
    first[0] = a0 + b0 * (centre[1] if m.shape[1] > 1 else 0.0)
    if m.shape[1] > 1:
        first[1] = b0 * scale[1]
    coef = first + _irls(m, wrap(w - m @ first), huber_k, lambda c: wrap(w - m @ (first + c)))
    return _physical(coef, centre, scale, kind, w.size)
