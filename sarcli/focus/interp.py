"""Range interpolators for RCMC: nearest, linear and Kaiser-windowed sinc with 4, 8 or 16 taps.

Windowed sinc: a sample at fractional position ``p = i + mu`` (i = floor(p), 0 <= mu < 1) is
``sum_k x[i + k] h(k - mu)`` for k = -(L/2 - 1) .. L/2 with ``h(x) = sinc(x) * w(x)``,
``w(x) = I0(beta sqrt(1 - (x / (L/2))^2)) / I0(beta)`` and the weights normalized to sum to 1
(unit DC gain, which removes the gain ripple a truncated sinc has between integer shifts).
The numba kernels read the weights from a table of ``N_PHASES + 1`` fractional shifts (nearest
shift, i.e. at most 1/(2 N_PHASES) sample of position error, 2.4e-4 sample for 2048 phases).
Samples outside the input are zero. Beta per length (4: 2.5, 8: 4.0, 16: 6.0) minimizes the
interpolation error of a signal oversampled by 1.2 (bench/bench_focus.py reports the error).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from sarcli.errors import SarcliError

N_PHASES = 2048
INTERPOLATORS = ("nearest", "linear", "sinc4", "sinc8", "sinc16")
_BETA = {4: 2.5, 8: 4.0, 16: 6.0}


def parse_interpolator(name: str) -> tuple[int, int]:
    """``"sinc8"`` -> (2, 8); ``"linear"`` -> (1, 2); ``"nearest"`` -> (0, 1): (kind code, taps)."""
    name = str(name).strip().lower()
    if name == "nearest":
        return 0, 1
    if name == "linear":
        return 1, 2
    if name.startswith("sinc") and name[4:] in ("4", "8", "16"):
        return 2, int(name[4:])
    raise SarcliError(f"unknown interpolator {name!r}: use one of {', '.join(INTERPOLATORS)}")


def sinc_weights(taps: int, mu: np.ndarray) -> np.ndarray:
    """Normalized windowed-sinc weights for fractional shifts ``mu`` (shape (..., taps))."""
    mu = np.asarray(mu, dtype=np.float64)
    k = np.arange(-(taps // 2 - 1), taps // 2 + 1, dtype=np.float64)
    x = k - mu[..., None]
    half = taps / 2.0
    w = np.i0(_BETA[taps] * np.sqrt(np.clip(1.0 - (x / half) ** 2, 0.0, None))) / np.i0(_BETA[taps])
    h = np.sinc(x) * w
    return h / h.sum(axis=-1, keepdims=True)


@cache
def _sinc_table_cached(taps: int) -> np.ndarray:
    return sinc_weights(taps, np.arange(N_PHASES + 1) / N_PHASES)


def sinc_table(taps: int) -> np.ndarray:
    """Weights for mu = j / N_PHASES, j = 0..N_PHASES: (N_PHASES + 1, taps) float64 (a fresh copy of a
    table computed once per length: 1.4 ms saved per focus call)."""
    return _sinc_table_cached(taps).copy()


def table_for(name: str) -> tuple[int, np.ndarray]:
    """(kind code, weight table) for the kernels; nearest/linear get a dummy (1, 1) table."""
    kind, taps = parse_interpolator(name)
    return kind, (sinc_table(taps) if kind == 2 else np.zeros((1, 1)))


def interpolate_numpy(x: np.ndarray, p: np.ndarray, name: str) -> np.ndarray:
    """Plain-numpy reference: rows of ``x`` (..., n) sampled at positions ``p`` (..., m); exact weights."""
    kind, taps = parse_interpolator(name)
    x = np.asarray(x)
    n = x.shape[-1]
    p = np.asarray(p, dtype=np.float64)
    xp = np.concatenate([np.zeros(x.shape[:-1] + (16,), x.dtype), x, np.zeros(x.shape[:-1] + (16,), x.dtype)],
                        axis=-1)

    def take(idx):
        ok = (idx >= 0) & (idx < n)
        idx = np.clip(idx, -16, n + 15) + 16
        return np.where(ok, np.take_along_axis(xp, idx.astype(np.int64), axis=-1), 0)

    if kind == 0:
        return take(np.floor(p + 0.5).astype(np.int64))
    i = np.floor(p).astype(np.int64)
    mu = p - i
    if kind == 1:
        return take(i) * (1.0 - mu) + take(i + 1) * mu
    w = sinc_weights(taps, mu)
    out = np.zeros(p.shape, dtype=np.result_type(x.dtype, np.complex64))
    for j, k in enumerate(range(-(taps // 2 - 1), taps // 2 + 1)):
        out = out + take(i + k) * w[..., j]
    return out
