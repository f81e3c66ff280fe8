"""Polarimetric normalized difference of [LeeGBSAR-I-2007, §3.1]: separates trees, wet grass and buildings."""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError


def normalized_difference(hh: np.ndarray, vv: np.ndarray, window: int = 1) -> np.ndarray:
    """Polarimetric normalized difference ``(|HH|^2 - |VV|^2) / (|HH|^2 + |VV|^2)`` in [-1, 1] ([LeeGBSAR-I-2007]),
    powers averaged over a ``window`` x ``window`` boxcar first; NaN where both are zero."""
    from scipy.ndimage import uniform_filter

    if window < 1:
        raise SarcliError("the polarimetric window must be >= 1 pixel")
    ph = uniform_filter(np.abs(hh).astype(np.float64) ** 2, window)
    pv = uniform_filter(np.abs(vv).astype(np.float64) ** 2, window)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(ph + pv > 0, (ph - pv) / (ph + pv), np.nan).astype(np.float32)
