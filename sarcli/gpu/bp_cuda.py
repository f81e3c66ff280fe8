"""Backprojection kernels for CUDA (numba.cuda): stripmap, GB-SAR rail and phase-history grid.

These are the only kernels of sarcli that only a card (or numba's CUDA simulator, ``NUMBA_ENABLE_CUDASIM=1``)
can run. Each is the arithmetic of its CPU kernel, one thread per output pixel, a loop over the pulses (stops):

- :func:`backproject_stripmap` = :func:`sarcli.focus.backprojection.backproject` (stripmap focuser
  ``backprojection``): ``I = sum_n W((f_n - fdc)/Ba) rc_n(R_n) exp(+j 4 pi (R_n - R0)/lam)``;
- :func:`backproject_rail` = :func:`sarcli.gbsar.backprojection.bp_kernel` (GB-SAR ``bp`` on the rail's
  polar/range grids, beam-limited apertures, taper normalised by its sum);
- :func:`backproject_grid` = :func:`sarcli.gbsar.backprojection.bp_grid_kernel` (any 3-D track onto a
  horizontal grid: GOTCHA, ``gbsar focus --grid``).

Precision, and the bound the tests use. Geometry (ranges R = |X - P| of 1e1 .. 1e6 m that must resolve
lam/1000) and the phase ``k (R - R0)`` (up to ~1e5 rad) are float64; the phase is reduced to [-pi, pi) in
float64, so the float32 cosine and sine that follow err by at most ~2 eps32 = 2.4e-7 each. The echo sample is
interpolated linearly in float32 from complex64 data (error <= 2 eps32 |v|), and the sum over the n pulses of a
pixel is accumulated in float32: |error| <= gamma_n sum_i |w_i v_i| with gamma_n = n eps32 / (1 - n eps32)
[Higham2002, eq. 4.4]. Per term the error is thus below 6 eps32 |w v| and the whole pixel's below
(n + 6) eps32 sum_i |w_i v_i| (:func:`float32_bound`): 469 pulses (GOTCHA) give 5.7e-5 of the sum of
magnitudes, far below the 1e-3 of a point target's peak that would move a PSLR in its second decimal. The
window/taper tables and their linear lookup are the CPU kernels' own (same values).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import cuda, float32

from sarcli.gpu.device import Cuda

EPS32 = float(np.finfo(np.float32).eps)
THREADS = 128  # threads per block (one pixel each)


def float32_bound(n_terms: int | np.ndarray, sum_abs: np.ndarray) -> np.ndarray:
    """Bound on |GPU - exact| of a pixel that sums ``n_terms`` terms of total magnitude ``sum_abs``
    (module docstring): (n + 6) eps32 / (1 - n eps32) * sum_abs."""
    n = np.asarray(n_terms, np.float64)
    return (n + 6.0) * EPS32 / (1.0 - n * EPS32) * np.asarray(sum_abs, np.float64)


@cuda.jit(device=True, inline=True)
def _cis32(ph):
    """(cos, sin) in float32 of a float64 phase reduced to [-pi, pi) in float64 first."""
    r = ph - 2.0 * math.pi * math.floor(ph / (2.0 * math.pi) + 0.5)
    r32 = float32(r)
    return math.cos(r32), math.sin(r32)


@cuda.jit(device=True, inline=True)
def _table(tab, u):
    """Linear lookup of a window table sampled on u in [-1/2, 1/2] (as sarcli.focus.windows.table_lookup)."""
    n = tab.shape[0]
    t = (u + 0.5) * (n - 1)
    j = int(t)
    if j > n - 2:
        j = n - 2
    a = t - j
    return tab[j] * (1.0 - a) + tab[j + 1] * a


@cuda.jit
def stripmap_kernel(rc_re, rc_im, r_first, dr, wavelength, pos, vel, pix, r_ref, fdc, ba, wtab, out_re, out_im):
    m = cuda.grid(1)
    if m >= pix.shape[0]:
        return
    na, nr = rc_re.shape
    k4 = 4.0 * math.pi / wavelength
    acc_re = float32(0.0)
    acc_im = float32(0.0)
    for n in range(na):
        dx = pix[m, 0] - pos[n, 0]
        dy = pix[m, 1] - pos[n, 1]
        dz = pix[m, 2] - pos[n, 2]
        r = math.sqrt(dx * dx + dy * dy + dz * dz)
        f = 2.0 * (vel[n, 0] * dx + vel[n, 1] * dy + vel[n, 2] * dz) / (wavelength * r)
        u = (f - fdc[m]) / ba
        if u < -0.5 or u > 0.5:
            continue
        p = (r - r_first) / dr
        i = int(math.floor(p))
        if i < 0 or i + 1 >= nr:
            continue
        w = float32(_table(wtab, u))
        mu = float32(p - i)
        vr = rc_re[n, i] * (float32(1.0) - mu) + rc_re[n, i + 1] * mu
        vi = rc_im[n, i] * (float32(1.0) - mu) + rc_im[n, i + 1] * mu
        c, s = _cis32(k4 * (r - r_ref[m]))
        acc_re += w * (vr * c - vi * s)
        acc_im += w * (vr * s + vi * c)
    out_re[m] = acc_re
    out_im[m] = acc_im


@cuda.jit
def rail_kernel(p_re, p_im, dr, xs, dz, valid, px, pr, kc, half_beam, table, w_min, out_re, out_im):
    p = cuda.grid(1)
    if p >= px.shape[0]:
        return
    n_s, n_r = p_re.shape
    a = max(xs[0], px[p] - half_beam * pr[p])
    b = min(xs[n_s - 1], px[p] + half_beam * pr[p])
    span = b - a
    acc_re = float32(0.0)
    acc_im = float32(0.0)
    wsum = 0.0
    r0sq = pr[p] * pr[p]
    nt = table.shape[0]
    for i in range(n_s):
        if valid[i] == 0.0 or xs[i] < a or xs[i] > b:
            continue
        w = 1.0
        if span > 0:
            q = (xs[i] - a) / span * (nt - 1)
            k = min(int(q), nt - 2)
            w = table[k] + (q - k) * (table[k + 1] - table[k])
        d = px[p] - xs[i]
        r = math.sqrt(d * d + r0sq + dz[i] * dz[i])
        f = r / dr
        j = int(f)
        if j >= n_r - 1:
            continue
        t = float32(f - j)
        vr = p_re[i, j] * (float32(1.0) - t) + p_re[i, j + 1] * t
        vi = p_im[i, j] * (float32(1.0) - t) + p_im[i, j + 1] * t
        c, s = _cis32(kc * (r - pr[p]))
        w32 = float32(w)
        acc_re += w32 * (vr * c - vi * s)
        acc_im += w32 * (vr * s + vi * c)
        wsum += w
    nominal = min(xs[n_s - 1] - xs[0], 2.0 * half_beam * pr[p])
    frac = span / nominal if nominal > 0 else 1.0
    if wsum > w_min:
        out_re[p] = acc_re * frac / wsum
        out_im[p] = acc_im * frac / wsum
    else:
        out_re[p] = 0.0
        out_im[p] = 0.0


@cuda.jit
def grid_kernel(p_re, p_im, r_first, dr, ant, ref, w, xs, ys, z, kc, out_re, out_im, used):
    k, iy = cuda.grid(2)
    if k >= xs.shape[0] or iy >= ys.shape[0]:
        return
    n_s, n_r = p_re.shape
    top = n_r - 1.0
    acc_re = float32(0.0)
    acc_im = float32(0.0)
    acc_w = 0.0
    for i in range(n_s):
        wi = w[i]
        if wi == 0.0:
            continue
        dx = xs[k] - ant[i, 0]
        dy = ys[iy] - ant[i, 1]
        dzz = z - ant[i, 2]
        rho = math.sqrt(dx * dx + dy * dy + dzz * dzz) - ref[i]
        u = (rho - r_first) / dr
        if u >= 0.0 and u < top:
            j = int(u)
            t = float32(u - j)
            vr = p_re[i, j] + t * (p_re[i, j + 1] - p_re[i, j])
            vi = p_im[i, j] + t * (p_im[i, j + 1] - p_im[i, j])
            c, s = _cis32(kc * rho)
            w32 = float32(wi)
            acc_re += w32 * (vr * c - vi * s)
            acc_im += w32 * (vr * s + vi * c)
            acc_w += wi
    out_re[iy, k] = acc_re
    out_im[iy, k] = acc_im
    used[iy, k] = acc_w


def _f64(dev: Cuda, a: Any) -> Any:
    return dev.asarray(np.ascontiguousarray(a, np.float64))


def _split32(dev: Cuda, a: np.ndarray) -> tuple[Any, Any]:
    a = np.asarray(a)
    return (dev.asarray(np.ascontiguousarray(a.real, np.float32)),
            dev.asarray(np.ascontiguousarray(a.imag, np.float32)))


def _blocks(n: int) -> int:
    return max(1, (n + THREADS - 1) // THREADS)


def backproject_stripmap(dev: Cuda, rc: np.ndarray, r_first: float, dr: float, wavelength: float, pos: np.ndarray,
                         vel: np.ndarray, pix: np.ndarray, r_ref: np.ndarray, fdc: np.ndarray, ba: float,
                         wtab: np.ndarray) -> np.ndarray:
    """The stripmap BP of :func:`sarcli.focus.backprojection.backproject` on ``dev``: (M,) complex64."""
    m = pix.shape[0]
    re, im = _split32(dev, rc)
    out_re = dev.xp.zeros(m, dev.xp.float32)
    out_im = dev.xp.zeros(m, dev.xp.float32)
    stripmap_kernel[_blocks(m), THREADS](re, im, float(r_first), float(dr), float(wavelength), _f64(dev, pos),
                                          _f64(dev, vel), _f64(dev, pix), _f64(dev, r_ref), _f64(dev, fdc),
                                          float(ba), _f64(dev, wtab), out_re, out_im)
    return (dev.to_host(out_re) + 1j * dev.to_host(out_im)).astype(np.complex64)


def backproject_rail(dev: Cuda, prof: np.ndarray, dr: float, xs: np.ndarray, dz: np.ndarray, valid: np.ndarray,
                     px: np.ndarray, pr: np.ndarray, kc: float, half_beam: float, table: np.ndarray,
                     w_min: float) -> np.ndarray:
    """The GB-SAR rail BP of :func:`sarcli.gbsar.backprojection.bp_kernel` on ``dev``: (n_p,) complex64."""
    n = px.shape[0]
    re, im = _split32(dev, prof)
    out_re = dev.xp.zeros(n, dev.xp.float32)
    out_im = dev.xp.zeros(n, dev.xp.float32)
    rail_kernel[_blocks(n), THREADS](re, im, float(dr), _f64(dev, xs), _f64(dev, dz), _f64(dev, valid),
                                      _f64(dev, px), _f64(dev, pr), float(kc), float(half_beam), _f64(dev, table),
                                      float(w_min), out_re, out_im)
    return (dev.to_host(out_re) + 1j * dev.to_host(out_im)).astype(np.complex64)


def backproject_grid(dev: Cuda, prof: np.ndarray, r_first: float, dr: float, ant: np.ndarray, ref: np.ndarray,
                     w: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float,
                     kc: float) -> tuple[np.ndarray, np.ndarray]:
    """The grid BP of :func:`sarcli.gbsar.backprojection.bp_grid_kernel` on ``dev``: (image (n_y, n_x)
    complex64, summed weights (n_y, n_x) float64)."""
    ny, nx = len(ys), len(xs)
    re, im = _split32(dev, prof)
    out_re = dev.xp.zeros((ny, nx), dev.xp.float32)
    out_im = dev.xp.zeros((ny, nx), dev.xp.float32)
    used = dev.xp.zeros((ny, nx), dev.xp.float64)
    tx, ty = 32, THREADS // 32
    grid = ((nx + tx - 1) // tx, (ny + ty - 1) // ty)
    grid_kernel[grid, (tx, ty)](re, im, float(r_first), float(dr), _f64(dev, ant), _f64(dev, ref), _f64(dev, w),
                                 _f64(dev, xs), _f64(dev, ys), float(z), float(kc), out_re, out_im, used)
    return (dev.to_host(out_re) + 1j * dev.to_host(out_im)).astype(np.complex64), dev.to_host(used)
