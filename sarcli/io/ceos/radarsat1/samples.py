"""Radarsat-1 RAW 4-bit samples: one byte per component (I then Q), code in the low nibble.

The low nibble is a 4-bit two's-complement code s in [-8, 7]; the high nibble is zero fill.
The reconstruction level is the odd integer 2s + 1 in [-15, 15] ([M]; equivalently s + 0.5 scaled
by 2, as [I] and [A] do with (s XOR 8) - 7.5). No 127.5 bias (doc trap 3). Replica bytes use the
same coding.

``decode_lines`` is the numba kernel used by the reader; ``decode_reference`` is the plain-numpy
reference its tests compare against.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def decode_lines(buf: np.ndarray, offsets: np.ndarray, rows: np.ndarray, n_samples: int, out: np.ndarray) -> int:
    """Decode ``n_samples`` I/Q byte pairs starting at each ``offsets[k]`` of ``buf`` into ``out[rows[k]]``.

    Returns the number of bytes whose high nibble was not zero (not RSAT 4-bit-in-8 data).
    """
    bad = 0
    for k in range(offsets.shape[0]):
        o = offsets[k]
        r = rows[k]
        for j in range(n_samples):
            bi = buf[o + 2 * j]
            bq = buf[o + 2 * j + 1]
            bad += (bi >> 4) != 0
            bad += (bq >> 4) != 0
            si = np.int32(bi & 15)
            sq = np.int32(bq & 15)
            if si >= 8:
                si -= 16
            if sq >= 8:
                sq -= 16
            out[r, j] = complex(2 * si + 1, 2 * sq + 1)
    return bad


def decode_reference(raw: np.ndarray) -> np.ndarray:
    """Plain-numpy decoding of a (..., 2N) uint8 I/Q byte array into (..., N) complex64 levels."""
    s = (raw.astype(np.int16) & 15)
    s = np.where(s >= 8, s - 16, s)
    lev = (2 * s + 1).astype(np.float32)
    return (lev[..., 0::2] + 1j * lev[..., 1::2]).astype(np.complex64)


@njit(cache=True, nogil=True)
def _all_odd_levels(v: np.ndarray) -> bool:
    for x in v:
        if not (abs(x) <= 15.0 and x == np.floor(x) and (int(x) & 1) == 1):
            return False
    return True


def is_four_bit(x: np.ndarray) -> bool:
    """True if every real and imaginary part is an odd integer level in [-15, 15] (NaN fails)."""
    x = np.ascontiguousarray(x)
    if x.dtype.kind != "c":
        return False
    return bool(_all_odd_levels(x.view(x.real.dtype).ravel()))


def is_four_bit_reference(x: np.ndarray) -> bool:
    """Plain-numpy reference of :func:`is_four_bit` (for the tests)."""
    x = np.asarray(x)
    with np.errstate(invalid="ignore"):
        return x.dtype.kind == "c" and all(
            bool(np.all((np.abs(v) <= 15) & (np.mod(v, 2) == 1))) for v in (x.real, x.imag))


def encode(x: np.ndarray) -> np.ndarray:
    """(..., N) odd levels -> (..., 2N) uint8 bytes (I, Q interleaved; code s = (level - 1) / 2)."""
    out = np.empty(x.shape[:-1] + (2 * x.shape[-1],), dtype=np.uint8)
    out[..., 0::2] = ((np.real(x).astype(np.int16) - 1) // 2) & 15
    out[..., 1::2] = ((np.imag(x).astype(np.int16) - 1) // 2) & 15
    return out


def quantize_replica(replica: np.ndarray, n: int) -> np.ndarray:
    """A replica as 4-bit odd levels of length ``n``: peak |I|,|Q| scaled to 15, nearest odd level.

    Samples beyond the given replica are code 0 (level +1: the mid-rise quantizer has no zero).
    """
    r = np.asarray(replica, dtype=np.complex128)[:n]
    peak = max(np.max(np.abs(r.real)), np.max(np.abs(r.imag)), 1e-300)
    r = r * (15.0 / peak)

    def odd(v: np.ndarray) -> np.ndarray:
        return np.clip(2.0 * np.floor(v / 2.0) + 1.0, -15, 15)

    out = np.full(n, 1 + 1j, dtype=np.complex64)
    out[: r.size] = odd(r.real) + 1j * odd(r.imag)
    return out
