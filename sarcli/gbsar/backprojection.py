"""Time-domain backprojection (BP): the exact GB-SAR focusing reference, on any set of pixels.

A pixel at azimuth x and range R0 from the rail line (image plane through the rail at the mean
antenna height) is at distance ``R_i = sqrt((x - x_i)^2 + R0^2 + (h_i - h_mean)^2)`` from stop i. With
the baseband range profiles P_i of :mod:`sarcli.gbsar.rangecomp` (``P_i(R) = a exp(-j 4 pi R/lam) W``),

    g(x, R0) = exp(-j 4 pi R0/lam) * sum_i w_i P_i(R_i) exp(+j 4 pi R_i/lam) / sum_i w_i

so a scatterer focuses to its reflectivity (times the window's coherent gain) with the phase
``-4 pi R0/lam`` of seed 000's RD image (eq. 21) at every range: no approximation but the linear
interpolation of the (oversampled) profile and the centre wavelength in the carrier term, which is
exact because the profile is referenced to f_c. ``w_i`` is the azimuth window over the rail times
the stop validity.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from sarcli.gbsar.rangecomp import RangeProfiles, window


@njit(cache=True, parallel=True)
def bp_kernel(prof, dr, xs, dz, wts, px, pr, kc, out):
    """Backproject ``prof`` (n_stops, n_r) complex64 (ranges n*dr) onto pixels (px, pr) -> out (n_p,)."""
    n_s, n_r = prof.shape
    wsum = 0.0
    for i in range(n_s):
        wsum += wts[i]
    scale = 1.0 / wsum if wsum > 0 else 0.0
    for p in prange(px.shape[0]):
        acc = 0j
        r0sq = pr[p] * pr[p]
        for i in range(n_s):
            if wts[i] == 0.0:
                continue
            d = px[p] - xs[i]
            r = np.sqrt(d * d + r0sq + dz[i] * dz[i])
            f = r / dr
            j = int(f)
            if j >= n_r - 1:
                continue
            t = f - j
            v = prof[i, j] * (1.0 - t) + prof[i, j + 1] * t
            acc += wts[i] * v * np.exp(1j * kc * r)
        out[p] = acc * np.exp(-1j * kc * pr[p]) * scale


def bp_reference(prof: np.ndarray, dr: float, xs, dz, wts, px, pr, kc) -> np.ndarray:
    """Plain-numpy reference of :func:`bp_kernel`."""
    rgrid = np.arange(prof.shape[1]) * dr
    acc = np.zeros(px.shape, np.complex128)
    for i in range(prof.shape[0]):
        if wts[i] == 0:
            continue
        r = np.sqrt((px - xs[i]) ** 2 + pr ** 2 + dz[i] ** 2)
        inside = r < rgrid[-1]
        v = np.interp(r, rgrid, prof[i].real) + 1j * np.interp(r, rgrid, prof[i].imag)
        acc += np.where(inside, wts[i] * v * np.exp(1j * kc * r), 0)
    return acc * np.exp(-1j * kc * pr) / np.sum(wts)


def stop_weights(prof: RangeProfiles, azimuth_window: str) -> np.ndarray:
    """Azimuth window over the rail stops times stop validity (float64, n_stops)."""
    return window(azimuth_window, prof.positions_m.size) * prof.weights


def backproject(prof: RangeProfiles, px: np.ndarray, pr: np.ndarray, azimuth_window: str = "hamming") -> np.ndarray:
    """BP onto pixels at azimuth ``px`` and range ``pr`` (any equal shapes) -> complex64 of that shape."""
    px = np.asarray(px, np.float64)
    shape = px.shape
    flat_x = np.ascontiguousarray(px.ravel())
    flat_r = np.ascontiguousarray(np.broadcast_to(np.asarray(pr, np.float64), shape).ravel())
    out = np.zeros(flat_x.size, np.complex64)
    dz = prof.heights_m - prof.heights_m.mean()
    kc = 4 * np.pi / prof.wavelength_m
    bp_kernel(np.ascontiguousarray(prof.data), prof.dr_m, prof.positions_m, dz,
              stop_weights(prof, azimuth_window), flat_x, flat_r, kc, out)
    return out.reshape(shape)
