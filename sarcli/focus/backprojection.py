"""Time-domain backprojection (BP): the exact reference for the RDA on point-target scenes.

For every output pixel with 3-D position X and closest-approach range R0:

    I(X) = sum_n W((f_n - fdc) / Ba) * rc_n(R_n) * exp(+j 4 pi (R_n - R0) / lam),
    R_n = |X - P_n|,   f_n = -(2/lam) dR/deta = (2/lam) V_n . (X - P_n) / R_n

with P_n, V_n the antenna position and velocity at line n (any geometry: no hyperbolic or
stop-and-go-free approximation beyond the echo model itself), rc_n the range-compressed line
(upsampled x ``upsample`` by FFT zero padding, then linearly interpolated) and W the azimuth window over
the processed Doppler band Ba around the pixel's centroid, so that the IRF is the one the RDA aims at.
The factor exp(-j 4 pi R0 / lam) gives the SLC phase convention (a scatterer at R0 has phase
-4 pi R0 / lam at its peak). Cost: O(pixels x lines); use it on small grids.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft
from numba import njit, prange

from sarcli.focus.windows import table_lookup, window, window_table
from sarcli.threads import fft_workers

#: fast-math flags of the float32 kernels: no NaN/inf/signed-zero care (lets the selects and the loops
#: vectorize) but no ``contract`` (FMA) and no ``reassoc``: every product is the rounded IEEE product the
#: error bounds of :mod:`sarcli.focus.phasor` assume, the same in the vector body and the scalar tail of a
#: loop, so a pixel's value does not depend on where a tile boundary or a thread split puts it
FLOAT32_FLAGS = {"nnan", "ninf", "nsz"}


def lerp_pairs(lines: np.ndarray) -> np.ndarray:
    """(n, m) complex lines -> (n, m) complex128 *view* of complex64 pairs ``(x_j, x_{j+1} - x_j)``
    (``x_m = x_{m-1}``): the float32 kernels' linear interpolation ``x_j + t (x_{j+1} - x_j)`` reads one
    16-byte element per sample (one scalar load where a vector gather does not pay), the difference
    rounded to float32 exactly as a kernel computing it in place would."""
    x = np.asarray(lines).astype(np.complex64, copy=False)
    pair = np.empty(x.shape + (2,), np.complex64)
    pair[..., 0] = x
    pair[:, :-1, 1] = x[:, 1:] - x[:, :-1]
    pair[:, -1, 1] = 0
    return pair.view(np.complex128)[..., 0]


@njit(parallel=True, cache=True)
def backproject(rc, r_first, dr, wavelength, pos, vel, pix, r_ref, fdc, ba, wtab, out):
    """BP kernel: ``rc`` (n_lines, n_range) on ranges r_first + i dr; pix (M, 3); writes out (M,)."""
    na, nr = rc.shape
    k4 = 4.0 * np.pi / wavelength
    for m in prange(pix.shape[0]):
        acc = 0.0j
        for n in range(na):
            dx = pix[m, 0] - pos[n, 0]
            dy = pix[m, 1] - pos[n, 1]
            dz = pix[m, 2] - pos[n, 2]
            r = np.sqrt(dx * dx + dy * dy + dz * dz)
            f = 2.0 * (vel[n, 0] * dx + vel[n, 1] * dy + vel[n, 2] * dz) / (wavelength * r)
            u = (f - fdc[m]) / ba
            if u < -0.5 or u > 0.5:
                continue
            w = table_lookup(wtab, u)
            p = (r - r_first) / dr
            i = int(np.floor(p))
            if i < 0 or i + 1 >= nr:
                continue
            mu = p - i
            v = rc[n, i] * (1.0 - mu) + rc[n, i + 1] * mu
            ph = k4 * (r - r_ref[m])
            acc += w * v * complex(np.cos(ph), np.sin(ph))
        out[m] = acc


def backproject_numpy(rc, r_first, dr, wavelength, pos, vel, pix, r_ref, fdc, ba, window_spec):
    """Plain-numpy reference of :func:`backproject` (exact window; loops over pixels)."""
    out = np.zeros(pix.shape[0], complex)
    idx = np.arange(rc.shape[0])
    for m in range(pix.shape[0]):
        d = pix[m][None, :] - pos
        r = np.linalg.norm(d, axis=1)
        f = 2.0 * np.sum(vel * d, axis=1) / (wavelength * r)
        w = window(window_spec, (f - fdc[m]) / ba)
        p = (r - r_first) / dr
        i = np.floor(p).astype(int)
        ok = (w > 0) & (i >= 0) & (i + 1 < rc.shape[1])
        mu = p - i
        ii = np.clip(i, 0, rc.shape[1] - 2)
        v = rc[idx, ii] * (1 - mu) + rc[idx, ii + 1] * mu
        out[m] = np.sum(np.where(ok, w * v * np.exp(4j * np.pi * (r - r_ref[m]) / wavelength), 0))
    return out


def upsample_range(rc: np.ndarray, factor: int, workers: int = -1) -> np.ndarray:
    """Fourier interpolation of range lines by an integer factor (baseband spectrum, zero padding)."""
    n = rc.shape[1]
    spec = sfft.fft(rc, axis=1, workers=fft_workers(workers))
    out = np.zeros((rc.shape[0], n * factor), spec.dtype)
    h = (n + 1) // 2
    out[:, :h] = spec[:, :h]
    out[:, n * factor - (n - h):] = spec[:, h:]
    return sfft.ifft(out, axis=1, overwrite_x=True, workers=fft_workers(workers)) * factor


def backproject_grid(rc: np.ndarray, r_first: float, dr: float, wavelength: float, pos: np.ndarray,
                     vel: np.ndarray, pix: np.ndarray, r_ref: np.ndarray, fdc: np.ndarray, ba: float,
                     window_spec: str, upsample: int = 8) -> np.ndarray:
    """Backproject range-compressed lines onto pixels ``pix`` (M, 3): complex128 (M,)."""
    up = upsample_range(np.asarray(rc), upsample) if upsample > 1 else np.asarray(rc)
    out = np.zeros(pix.shape[0], np.complex128)
    backproject(up, float(r_first), dr / upsample, float(wavelength), np.ascontiguousarray(pos, np.float64),
                np.ascontiguousarray(vel, np.float64), np.ascontiguousarray(pix, np.float64),
                np.ascontiguousarray(r_ref, np.float64), np.ascontiguousarray(fdc, np.float64), float(ba),
                window_table(window_spec), out)
    return out
