"""Time-domain backprojection (BP): the exact GB-SAR focusing reference, on any set of pixels.

A pixel at azimuth x and range R0 from the rail line (image plane through the rail at the mean
antenna height) is at distance ``R_i = sqrt((x - x_i)^2 + R0^2 + (h_i - h_mean)^2)`` from stop i. With
the baseband range profiles P_i of :mod:`sarcli.gbsar.rangecomp` (``P_i(R) = a exp(-j 4 pi R/lam) W``),

    g(x, R0) = exp(-j 4 pi R0/lam) * sum_i w_i P_i(R_i) exp(+j 4 pi R_i/lam) / sum_i w_i

over the stops of the pixel's synthetic aperture (rail within the beam footprint, seed 000 Fig. 2),
``w_i`` the azimuth taper over that aperture, so a scatterer focuses to its (pattern-weighted)
reflectivity (times its aperture fraction at the rail ends) with the phase
``-4 pi R0/lam`` of seed 000's RD image (eq. 21) at every range: no approximation but the linear
interpolation of the (oversampled) profile and the centre wavelength in the carrier term, which is
exact because the profile is referenced to f_c. The kernel evaluates ``exp(+j 4 pi (R_i - R0)/lam)``
in float32 (``R_i - R0`` stays below ~5 m, so the phase error is < 1e-4 rad) and accumulates in
complex64. Flagged stops are left out.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.windows import taper_at, taper_table

_W_MIN = 1e-9  # apertures whose taper weights sum below this (e.g. one stop on a Hann edge) give 0


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy")
def bp_kernel(prof, dr, xs, dz, valid, px, pr, kc, half_beam, table, out):
    """Backproject ``prof`` (n_stops, n_r) complex64 (ranges n*dr) onto pixels (px, pr) -> out (n_p,).

    Each pixel integrates the stops of its synthetic aperture ``[a, b]`` = rail ``[xs[0], xs[-1]]``
    intersected with the beam footprint ``|x - px| <= half_beam * pr`` (seed 000 eq. 22-40), weighted by
    the taper ``table`` (sampled on [0, 1]) over [a, b], normalized by the sum of the weights used and
    scaled by ``(b - a) / min(X, 2 half_beam R0)``: a pixel whose aperture is cut by a rail end
    (regions III/IV) is attenuated by its aperture fraction, as in DF and RD, instead of amplifying
    the leakage of bright targets seen by a few stops at the beam edge.
    """
    n_s, n_r = prof.shape
    for p in prange(px.shape[0]):
        a = max(xs[0], px[p] - half_beam * pr[p])
        b = min(xs[n_s - 1], px[p] + half_beam * pr[p])
        span = b - a
        acc = np.complex64(0j)
        wsum = 0.0
        r0sq = pr[p] * pr[p]
        for i in range(n_s):
            if valid[i] == 0.0 or xs[i] < a or xs[i] > b:
                continue
            w = 1.0
            if span > 0:
                q = (xs[i] - a) / span * (table.size - 1)
                k = min(int(q), table.size - 2)
                w = table[k] + (q - k) * (table[k + 1] - table[k])
            d = px[p] - xs[i]
            r = np.sqrt(d * d + r0sq + dz[i] * dz[i])
            f = r / dr
            j = int(f)
            if j >= n_r - 1:
                continue
            t = np.float32(f - j)
            v = prof[i, j] * (np.float32(1.0) - t) + prof[i, j + 1] * t
            # r - R0 < ~1.2e3 rad / kc: a float32 phase is good to 1e-4 rad, and complex64 math is faster
            ph = np.float32(kc * (r - pr[p]))
            acc += np.float32(w) * v * np.complex64(complex(np.cos(ph), np.sin(ph)))
            wsum += w
        nominal = min(xs[n_s - 1] - xs[0], 2.0 * half_beam * pr[p])
        frac = span / nominal if nominal > 0 else 1.0
        out[p] = acc * frac / wsum if wsum > _W_MIN else 0j


def bp_reference(prof: np.ndarray, dr: float, xs, dz, valid, px, pr, kc, half_beam, taper_spec: str) -> np.ndarray:
    """Plain-numpy reference of :func:`bp_kernel` (the taper evaluated exactly, not tabulated)."""
    rgrid = np.arange(prof.shape[1]) * dr
    a = np.maximum(xs[0], px - half_beam * pr)
    b = np.minimum(xs[-1], px + half_beam * pr)
    span = b - a
    acc = np.zeros(px.shape, np.complex128)
    wsum = np.zeros(px.shape)
    for i in range(prof.shape[0]):
        t = np.where(span > 0, (xs[i] - a) / np.where(span > 0, span, 1.0), 0.0)
        w = taper_at(taper_spec, t)
        r = np.sqrt((px - xs[i]) ** 2 + pr ** 2 + dz[i] ** 2)
        use = (valid[i] != 0) & (xs[i] >= a) & (xs[i] <= b) & (r < rgrid[-1])
        v = np.interp(r, rgrid, prof[i].real) + 1j * np.interp(r, rgrid, prof[i].imag)
        acc += np.where(use, w * v * np.exp(1j * kc * r), 0)
        wsum += np.where(use, w, 0)
    nominal = np.minimum(xs[-1] - xs[0], 2.0 * half_beam * pr)
    frac = np.where(nominal > 0, span / np.where(nominal > 0, nominal, 1.0), 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(wsum > _W_MIN, acc * np.exp(-1j * kc * pr) * frac / wsum, 0)


def backproject(prof: RangeProfiles, px: np.ndarray, pr: np.ndarray, antenna_length_m: float | None,
                azimuth_window: str = "hamming") -> np.ndarray:
    """BP onto pixels at azimuth ``px`` and range ``pr`` (any equal shapes) -> complex64 of that shape.

    ``antenna_length_m`` = L_x limits each pixel's aperture to the beam footprint; None uses the whole rail.
    ``azimuth_window``: a taper spec (:mod:`sarcli.gbsar.windows`) over each pixel's aperture.
    """
    table = taper_table(azimuth_window)
    px = np.asarray(px, np.float64)
    shape = px.shape
    flat_x = np.ascontiguousarray(px.ravel())
    flat_r = np.ascontiguousarray(np.broadcast_to(np.asarray(pr, np.float64), shape).ravel())
    out = np.zeros(flat_x.size, np.complex64)
    dz = prof.heights_m - prof.heights_m.mean()
    kc = 4 * np.pi / prof.wavelength_m
    half = prof.wavelength_m / (2 * antenna_length_m) if antenna_length_m else 1e30
    bp_kernel(np.ascontiguousarray(prof.data), prof.dr_m, prof.positions_m, dz, prof.weights, flat_x, flat_r, kc,
              half, table, out)
    return out.reshape(shape)


def backproject_polar(prof: RangeProfiles, rc: np.ndarray, sines: np.ndarray, antenna_length_m: float | None,
                      azimuth_window: str = "hamming") -> np.ndarray:
    """BP on a polar grid about the rail centre (DF's native grid): rows ``rc`` (distance from the rail
    centre, m), columns ``sines`` (sin of the angle from boresight) -> (n_rc, n_s) complex64.

    The phase convention stays ``-4 pi R0/lam`` (R0 = rc cos(theta)); multiply by
    ``exp(-j 4 pi (rc - R0)/lam)`` for DF's ``-4 pi Rc/lam``."""
    centre = 0.5 * (prof.positions_m[0] + prof.positions_m[-1])
    rc2, s2 = np.meshgrid(np.asarray(rc, np.float64), np.asarray(sines, np.float64), indexing="ij")
    return backproject(prof, centre + rc2 * s2, rc2 * np.sqrt(1.0 - s2 ** 2), antenna_length_m, azimuth_window)
