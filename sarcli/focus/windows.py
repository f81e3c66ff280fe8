"""Spectral weighting windows for range and azimuth compression.

A window is evaluated on the normalized frequency ``u = (f - f_centre) / B`` in [-1/2, 1/2] (zero
outside): ``rect`` (1), ``hamming:a`` (a + (1-a) cos(2 pi u), a = 0.54 by default) and ``kaiser:beta``
(I0(beta sqrt(1 - (2u)^2)) / I0(beta), beta = 2.5 by default, the value Cumming & Wong use).
The spec strings are what the CLI accepts (``--range-window kaiser:2.5``).

Theory for the impulse response of a window (used by the tests and ``sarcli quality`` reports):
the continuous IRF is the inverse Fourier transform of the window over [-B/2, B/2]; for ``rect`` it is
sinc(B x): IRW = 0.886/B, PSLR = -13.26 dB.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sarcli.errors import SarcliError

WINDOW_KINDS = ("rect", "hamming", "kaiser")
_DEFAULT_PARAM = {"rect": 0.0, "hamming": 0.54, "kaiser": 2.5}


def parse_window(spec: str) -> tuple[str, float]:
    """``"kaiser:2.5"`` -> ("kaiser", 2.5); ``"rect"`` -> ("rect", 0.0). One-line error otherwise."""
    name, _, arg = str(spec).strip().lower().partition(":")
    if name in ("rectangular", "none", "boxcar"):
        name = "rect"
    if name not in WINDOW_KINDS:
        raise SarcliError(f"unknown window {spec!r}: use rect, hamming[:a] or kaiser[:beta]")
    if not arg:
        return name, _DEFAULT_PARAM[name]
    try:
        p = float(arg)
    except ValueError:
        raise SarcliError(f"window parameter in {spec!r} is not a number") from None
    if name == "hamming" and not 0.5 <= p <= 1.0:
        raise SarcliError(f"hamming coefficient must be in [0.5, 1], got {p}")
    if name == "kaiser" and not 0.0 <= p <= 40.0:
        raise SarcliError(f"kaiser beta must be in [0, 40], got {p}")
    return name, p


def window(spec: str | tuple[str, float], u: np.ndarray) -> np.ndarray:
    """Window weights (float64) at normalized frequencies ``u``; 0 for |u| > 1/2."""
    name, p = parse_window(spec) if isinstance(spec, str) else spec
    u = np.asarray(u, dtype=np.float64)
    inside = np.abs(u) <= 0.5
    if name == "rect":
        w = np.ones_like(u)
    elif name == "hamming":
        w = p + (1.0 - p) * np.cos(2.0 * np.pi * u)
    else:
        arg = np.sqrt(np.clip(1.0 - (2.0 * u) ** 2, 0.0, None))
        w = np.i0(p * arg) / np.i0(p)
    return np.where(inside, w, 0.0)


def window_table(spec: str | tuple[str, float], n: int = 4097) -> np.ndarray:
    """The window tabulated at ``n`` points over u in [-1/2, 1/2] (for numba kernels: linear lookup)."""
    return window(spec, np.linspace(-0.5, 0.5, n))


@njit(inline="always", cache=True)
def table_lookup(wtab, u):
    """Linear interpolation of a :func:`window_table` at u in [-1/2, 1/2] (numba kernels)."""
    n = wtab.shape[0]
    t = (u + 0.5) * (n - 1)
    j = int(t)
    if j > n - 2:
        j = n - 2
    a = t - j
    return wtab[j] * (1.0 - a) + wtab[j + 1] * a
