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

Two kernels: :func:`backproject` (complex128, cos/sin per sample: the reference) and
:func:`backproject32` (the default: ranges, Doppler and window position in float64, the phasor by the
float32 recurrence over the lines of :mod:`sarcli.focus.phasor`, interpolation and sums in float32 on
complex64 lines; within the bound derived there of the complex128 kernel, tested).
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft
from numba import njit, prange

from sarcli.errors import ConfigError
from sarcli.focus.phasor import ANCHOR_EVERY, EPS_MAX, advance_phasor, anchor_phasor
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


@njit(parallel=True, cache=True, fastmath=FLOAT32_FLAGS, error_model="numpy")
def backproject32(pairs, r_first, dr, wavelength, pos, vel, pix, r_ref, fdc, ba, wtab, every, first_line, tile, out):
    """Float32 twin of :func:`backproject` (same window, interpolation and phase conventions): ``pairs``
    the lines as :func:`lerp_pairs`, out (M,) complex64. Ranges, Doppler and window position in float64;
    the phasor ``exp(+j k4 (R_n - R0))`` advanced over the lines by the recurrence of
    :mod:`sarcli.focus.phasor` (a float64 anchor on the block's first line, before which a virtual line
    at ``2 P_0 - P_1`` stands, and on every line whose index ``first_line + n`` is a multiple of ``every``:
    a pixel whose band starts ``every`` lines into two blocks gets the same bits from both); the band and
    range tests and the window position as there but with reciprocals for two of the divisions (a sample
    within ~1e-16 of a band edge may fall the other way); interpolation, window and sums in float32.
    Tiles of ``tile`` consecutive pixels (copied to contiguous arrays) run in parallel, each integrating
    the lines in order: bit-identical whatever the tiling or the number of threads. Per line: a
    vectorized phasor pass, a vectorized pass for the Doppler, window position and range index (the rest
    skipped where no pixel of the tile sees the line in its band), a scalar pass reading the pairs and the
    window table, a vectorized pass weighting and accumulating."""
    na, nr = pairs.shape
    n_pix = pix.shape[0]
    k4 = 4.0 * np.pi / wavelength
    two_over_lam = 2.0 / wavelength
    inv_ba = 1.0 / ba
    inv_dr = 1.0 / dr
    top = nr - 1.0
    nw = wtab.shape[0]
    zero = np.float32(0.0)
    for t in prange((n_pix + tile - 1) // tile):
        m0 = t * tile
        nm = min(tile, n_pix - m0)
        qx = np.empty(nm)
        qy = np.empty(nm)
        qz = np.empty(nm)
        qr = np.empty(nm)
        qf = np.empty(nm)
        for c in range(nm):  # the tile's pixels as contiguous arrays: the passes below vectorize
            qx[c] = pix[m0 + c, 0]
            qy[c] = pix[m0 + c, 1]
            qz[c] = pix[m0 + c, 2]
            qr[c] = r_ref[m0 + c]
            qf[c] = fdc[m0 + c]
        rr = np.empty(nm)
        rho = np.empty(nm)
        dlt = np.empty(nm)
        pre = np.empty(nm, np.float32)
        pim = np.empty(nm, np.float32)
        dre = np.empty(nm, np.float32)
        dim = np.empty(nm, np.float32)
        acc_re = np.zeros(nm, np.float32)
        acc_im = np.zeros(nm, np.float32)
        jj = np.empty(nm, np.uint64)
        ff = np.empty(nm, np.float32)
        kk = np.empty(nm, np.uint64)
        aw = np.empty(nm)
        w0 = np.empty(nm)
        w1 = np.empty(nm)
        okk = np.empty(nm, np.float32)
        ww = np.empty(nm, np.float32)
        val = np.empty(nm, np.complex128)
        q = val.view(np.float32)
        for n in range(na):
            p0 = pos[n, 0]
            p1 = pos[n, 1]
            p2 = pos[n, 2]
            if n == 0 or (first_line + n) % every == 0:  # anchor: R and R - R_prev in float64
                if n > 0:
                    b0, b1, b2 = pos[n - 1, 0], pos[n - 1, 1], pos[n - 1, 2]
                elif na > 1:
                    b0, b1, b2 = 2.0 * p0 - pos[1, 0], 2.0 * p1 - pos[1, 1], 2.0 * p2 - pos[1, 2]
                else:
                    b0, b1, b2 = p0, p1, p2
                for c in range(nm):
                    dx = qx[c] - p0
                    dy = qy[c] - p1
                    dz = qz[c] - p2
                    ex = qx[c] - b0
                    ey = qy[c] - b1
                    ez = qz[c] - b2
                    r = np.sqrt(dx * dx + dy * dy + dz * dz)
                    rr[c] = r
                    rh = r - qr[c]
                    anchor_phasor(k4, rh, rh - (np.sqrt(ex * ex + ey * ey + ez * ez) - qr[c]), c, pre, pim, dre,
                                  dim, rho, dlt)
            else:  # D <- D exp(j eps), P <- P D
                for c in range(nm):
                    dx = qx[c] - p0
                    dy = qy[c] - p1
                    dz = qz[c] - p2
                    r = np.sqrt(dx * dx + dy * dy + dz * dz)
                    rr[c] = r
                    advance_phasor(k4, r - qr[c], c, pre, pim, dre, dim, rho, dlt)
            seen = 0
            v0 = vel[n, 0]
            v1 = vel[n, 1]
            v2 = vel[n, 2]
            for c in range(nm):
                dx = qx[c] - p0
                dy = qy[c] - p1
                dz = qz[c] - p2
                r = rr[c]
                u = ((v0 * dx + v1 * dy + v2 * dz) * two_over_lam / r - qf[c]) * inv_ba
                p = (r - r_first) * inv_dr
                ok = (u >= -0.5) & (u <= 0.5) & (p >= 0.0) & (p < top)
                pc = p if ok else 0.0
                j = np.uint64(pc)
                jj[c] = j
                ff[c] = np.float32(pc - j)
                # window_table lookup (table_lookup's arithmetic), the table read in the scalar pass
                tw = ((u if ok else 0.0) + 0.5) * (nw - 1)
                k = min(np.uint64(tw), np.uint64(nw - 2))
                kk[c] = k
                aw[c] = tw - k
                okk[c] = np.float32(1.0) if ok else zero
                seen += 1 if ok else 0
            if seen == 0:
                continue
            line = pairs[n]
            for c in range(nm):
                val[c] = line[jj[c]]
                w0[c] = wtab[kk[c]]
                w1[c] = wtab[kk[c] + np.uint64(1)]
            for c in range(nm):
                ww[c] = np.float32(w0[c] * (1.0 - aw[c]) + w1[c] * aw[c]) * okk[c]
            for c in range(nm):
                f = ff[c]
                vr = q[4 * c] + f * q[4 * c + 2]
                vi = q[4 * c + 1] + f * q[4 * c + 3]
                acc_re[c] += ww[c] * (vr * pre[c] - vi * pim[c])
                acc_im[c] += ww[c] * (vr * pim[c] + vi * pre[c])
        for c in range(nm):
            out[m0 + c] = complex(acc_re[c], acc_im[c])


def line_anchor_interval(k4: float, pos: np.ndarray, pix: np.ndarray, every: int = ANCHOR_EVERY) -> int:
    """Lines between float64 anchors for :func:`backproject32`: the recurrence runs over the lines, so the
    second difference of R_n is bounded by ``|P_{n+1} - 2 P_n + P_{n-1}| + max|P_{n+1} - P_n|^2 / R_min``
    (:mod:`sarcli.focus.phasor`, the vector form of its bound: |grad R| = 1, |Hessian R| <= 1/R), with
    ``R_min`` >= the distance from the pixels to the track's centre minus the track's radius about it."""
    if pos.shape[0] < 3 or pix.shape[0] == 0:
        return every
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    curve = float(np.linalg.norm(np.diff(pos, 2, axis=0), axis=1).max())
    centre = pos.mean(axis=0)
    r_min = float(np.linalg.norm(pix - centre, axis=1).min() - np.linalg.norm(pos - centre, axis=1).max())
    if not r_min > 0:
        return 1
    return every if k4 * (curve + float(step.max()) ** 2 / r_min) <= EPS_MAX else 1


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


#: pixels per tile of :func:`backproject32`
LINE_TILE = 256


def backproject_grid(rc: np.ndarray, r_first: float, dr: float, wavelength: float, pos: np.ndarray,
                     vel: np.ndarray, pix: np.ndarray, r_ref: np.ndarray, fdc: np.ndarray, ba: float,
                     window_spec: str, upsample: int = 8, precision: str = "single",
                     first_line: int = 0, device: str = "cpu") -> np.ndarray:
    """Backproject range-compressed lines onto pixels ``pix`` (M, 3) -> (M,): complex64 by the float32
    kernel :func:`backproject32` (``precision="single"``) or complex128 by :func:`backproject` ("double");
    ``device="cuda"``: complex64 from the GPU kernel (:func:`sarcli.gpu.bp_cuda.backproject_stripmap`,
    float64 geometry, float32 accumulation; ``precision`` is the CPU's).
    ``first_line``: the index of ``rc``'s first line in the whole acquisition (anchors the recurrence
    on the same lines whichever block a pixel is focused in)."""
    up = upsample_range(np.asarray(rc), upsample) if upsample > 1 else np.asarray(rc)
    if device == "cuda":
        from sarcli.gpu import bp_cuda
        from sarcli.gpu.device import require_cuda

        return bp_cuda.backproject_stripmap(require_cuda(), up, float(r_first), dr / upsample, float(wavelength), pos,
                                            vel, pix, r_ref, fdc, float(ba), window_table(window_spec))
    args = (float(r_first), dr / upsample, float(wavelength), np.ascontiguousarray(pos, np.float64),
            np.ascontiguousarray(vel, np.float64), np.ascontiguousarray(pix, np.float64),
            np.ascontiguousarray(r_ref, np.float64), np.ascontiguousarray(fdc, np.float64), float(ba),
            window_table(window_spec))
    if precision == "single":
        out = np.zeros(pix.shape[0], np.complex64)
        every = line_anchor_interval(4 * np.pi / wavelength, args[3], args[5])
        backproject32(lerp_pairs(up), *args, every, int(first_line), LINE_TILE, out)
        return out
    if precision != "double":
        raise ConfigError(f"precision must be 'single' or 'double', got {precision!r}")
    out = np.zeros(pix.shape[0], np.complex128)
    backproject(up, *args, out)
    return out
