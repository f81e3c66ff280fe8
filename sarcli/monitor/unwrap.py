"""Temporal unwrapping of the phase between consecutive scans, its plausibility check, and spatial
unwrapping where the temporal check fails.

Between scans k-1 and k a pixel's wrapped interferometric phase is ``w = arg(z_k z_{k-1}^*)``. Its
unwrapped value is taken nearest to a prediction ``p`` (the APS increment plus, at measured points,
the phase of the point's velocity over the interval, ``-4 pi v dt/lam``):
``delta = p + wrap(w - p)`` [Itoh1982] (Itoh's condition, |delta - p| < pi, around the prediction).
The residual ``wrap(w - p)`` is the part the prediction does not explain; beyond a quarter cycle
(pi/2, an implied velocity change of ``lam/(8 dt)``) it is implausible: it is as close to the next
cycle as to this one. When too many reliable points are implausible the scan is not silently
unwrapped in time: the residual is unwrapped *in space* (connected pixels of one moving body differ
by less than half a cycle) with scikit-image's ``unwrap_phase`` [Herraez2002], referenced to the
stable points, and accepted only if the implied velocities stay below a physical maximum; otherwise
the scan is rejected.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.monitor.aps import wrap


@dataclass
class Increment:
    """The unwrapped increment (rad, the full map), how it was obtained and the check's figures."""

    delta: np.ndarray
    method: str  # "temporal" | "spatial"
    implausible_fraction: float
    accepted: bool
    reason: str = ""


def implausible(residual: np.ndarray) -> np.ndarray:
    """Residuals beyond a quarter cycle off the prediction (bool)."""
    return np.abs(residual) > np.pi / 2


def spatial_unwrap(residual: np.ndarray, mask: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Unwrap ``residual`` (rad, 2-D) over ``mask`` (bool) in space [Herraez2002]; the result is shifted by
    the multiple of 2 pi that brings the median over ``reference`` (bool) nearest to 0. NaN outside the
    mask. Separate connected regions are unwrapped independently by scikit-image; each is then put on
    the cycle that makes its median nearest to 0 unless it holds reference pixels."""
    from scipy.ndimage import label
    from skimage.restoration import unwrap_phase

    masked = np.ma.masked_array(np.asarray(residual, np.float64), mask=~mask)
    u = np.asarray(unwrap_phase(masked).filled(np.nan))
    regions, n = label(mask)
    for k in range(1, n + 1):
        reg = regions == k
        ref = reg & reference
        centre = float(np.median(u[ref])) if ref.any() else float(np.median(u[reg]))
        u[reg] -= 2 * np.pi * np.round(centre / (2 * np.pi))
    return u


def unwrap_increment(w: np.ndarray, prediction: np.ndarray, reliable: np.ndarray, reference: np.ndarray,
                     valid: np.ndarray, max_fraction: float, spatial: bool, max_jump_rad: float) -> Increment:
    """Unwrap the wrapped increment ``w`` around ``prediction`` (module docstring).

    ``reliable``: points the check is made on (selected, coherent this scan); ``reference``: stable
    points; ``valid``: pixels with data in both scans (the spatial unwrapping's mask);
    ``max_jump_rad``: the largest plausible residual once unwrapped in space (a physical velocity).
    """
    res = wrap(w - prediction)
    n = int(reliable.sum())
    frac = float(np.mean(implausible(res[reliable]))) if n else 0.0
    if frac <= max_fraction:
        return Increment(prediction + res, "temporal", frac, True)
    if not spatial:
        return Increment(prediction + res, "temporal", frac, False,
                         f"{frac:.0%} of the reliable points jump by more than a quarter cycle")
    u = spatial_unwrap(res, valid, reference & valid)
    u = np.where(valid, u, res)
    frac_sp = float(np.mean(np.abs(u[reliable]) > max_jump_rad)) if n else 0.0
    if frac_sp <= max_fraction:
        return Increment(prediction + u, "spatial", frac, True)
    return Increment(prediction + res, "spatial", frac, False,
                     f"{frac:.0%} of the reliable points jump by more than a quarter cycle, and spatial "
                     f"unwrapping leaves {frac_sp:.0%} beyond the maximum velocity")
