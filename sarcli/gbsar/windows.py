"""Tapers over the frequencies of a sweep and the stops of a rail, in the window syntax of stripmap focus.

A spec is ``rect | hamming[:a] | kaiser[:beta]`` (:func:`sarcli.focus.windows.parse_window`; ``none``
is ``rect``), plus ``hann`` = ``hamming:0.5``. The window ``w(u)`` of :mod:`sarcli.focus.windows` is
defined on ``u`` in [-1/2, 1/2] (``hamming:a``: ``a + (1 - a) cos(2 pi u)``; ``kaiser:beta``:
``I0(beta sqrt(1 - 4u^2)) / I0(beta)``).

Discrete taper of ``n`` samples (frequencies, stops; :func:`taper`): ``w_k = w(u_k)`` with

    u_k = (k - (n - 1)/2) / D,   D = n - 1   if w(1/2) > 0,
                                 D = n + 1   if w(1/2) = 0 (hann),

i.e. the window's ends fall on the end samples, unless the window vanishes there: then it is
stretched by one sample on each side so that no sample is given weight 0 (a zero-weight stop would
be a stop thrown away). ``hamming`` is then ``np.hamming(n)`` (``0.54 - 0.46 cos(2 pi k/(n-1))``) and
``hann`` is ``np.hanning(n + 2)[1:-1]``, the tapers GB-SAR focusing used before the window syntax
was shared (to float64 rounding; tested).

Continuous taper over a pixel's own synthetic aperture ``[a, b]`` (backprojection;
:func:`taper_table`): ``w(t - 1/2)`` at ``t = (x - a)/(b - a)`` in [0, 1], tabulated for the numba
kernel.
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import ConfigError
from sarcli.focus.windows import parse_window, window, window_table

ALIASES = {"hann": ("hamming", 0.5)}
_NAMES = ("rect", "none", "rectangular", "boxcar", "hamming", "kaiser", "hann")
TABLE_N = 4097  # taper lookup table of the BP kernel; linear interpolation error < 1e-7


def parse_taper(spec: str | tuple[str, float]) -> tuple[str, float]:
    """``"hann"`` -> ("hamming", 0.5), ``"none"`` -> ("rect", 0.0), ``"kaiser:3"`` -> ("kaiser", 3.0);
    a (name, parameter) pair passes through. One-line :class:`ConfigError` for an unknown name."""
    if isinstance(spec, tuple):
        return spec
    text = str(spec).strip().lower()
    if text in ALIASES:
        return ALIASES[text]
    if text.partition(":")[0] not in _NAMES:
        raise ConfigError(f"unknown window {spec!r}: use rect (or none), hamming[:a], hann or kaiser[:beta]")
    return parse_window(text)


def taper(spec: str | tuple[str, float], n: int) -> np.ndarray:
    """The discrete taper (float64, ``n``) of the module docstring; all ones for n = 1."""
    w = parse_taper(spec)
    if n <= 1:
        return np.ones(max(n, 0))
    d = n - 1 if window(w, np.array([0.5]))[0] > 0 else n + 1
    return window(w, (np.arange(n) - (n - 1) / 2) / d)


def taper_table(spec: str | tuple[str, float]) -> np.ndarray:
    """The continuous taper sampled at ``TABLE_N`` points over t in [0, 1] (u = t - 1/2)."""
    return window_table(parse_taper(spec), TABLE_N)


def taper_at(spec: str | tuple[str, float], t: np.ndarray) -> np.ndarray:
    """The continuous taper at t in [0, 1] (plain numpy; the reference of the tabulated one)."""
    return window(parse_taper(spec), np.asarray(t, np.float64) - 0.5)
