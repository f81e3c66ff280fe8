"""Amplitudes in decibels, one pass: the kernel behind :func:`sarcli.io.images.amplitude_db` (a full
scene's dB band is 166 Mpixel: numpy's float64 copy, log and two masks over it took 2.3 s)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, parallel=True)
def magnitude_db(a: np.ndarray, floor_db: float, use_floor: bool) -> np.ndarray:
    """20 log10(a) (float32) of a flat array of magnitudes (their absolute values), computed in float64: 0 gives
    ``floor_db`` (``use_floor``) or NaN; with ``use_floor`` every finite value is at least ``floor_db``;
    NaN stays NaN."""
    out = np.empty(a.size, np.float32)
    for k in prange(a.size):
        x = abs(np.float64(a[k]))
        if x == 0.0:
            out[k] = floor_db if use_floor else np.nan
            continue
        v = 20.0 * np.log10(x)
        if use_floor and v < floor_db:
            v = floor_db
        out[k] = v
    return out
