"""One block of the Range-Doppler focuser against an array namespace ``xp`` (CuPy on the card, numpy in CI).

:meth:`sarcli.focus.rda.RangeDoppler.focus_block` with ``device="cuda"`` calls :func:`focus_rows` for steps 1-5
of :mod:`sarcli.focus.rda` (range FFT, azimuth FFT, range filter x SRC x Fourier upsampling, range IFFT, RCMC
and azimuth matched filter, azimuth IFFT) and does step 6 (the per-line corrections, a small share of the work)
on the CPU as always, so the plan, the blocks and hence the block invariance are the CPU's. The code is written
once with ``xp``: on the card ``xp`` is CuPy (cuFFT, element-wise kernels); the tests run the very same
functions with ``xp = numpy`` and compare them with the numba CPU kernels. The azimuth-frequency rows are
processed in tiles of ``ROWS`` (each row is independent: the tile size changes the memory, and the image only by
the FFT library's batching of rows, float32 round-off: tests/gpu/test_rd_xp.py).

The RCMC/azimuth filter here evaluates the geometry (range position and phase) exactly at every sample with the
CPU kernel's own tables (window: linear lookup in a 4097-point table; sinc: the nearest of 2048 phases), where
:func:`sarcli.focus.rcmc.rcmc_azimuth` interpolates position and phase linearly over spans of 32 range bins.
So the two images differ by that span interpolation (below 2e-3 rad and 1e-4 sample for Radarsat-1,
:mod:`sarcli.focus.rcmc`) and by float32 round-off in a different order of operations (FFTs: O(eps32 log2 N)
relative to the block's energy; the interpolation sums: taps x eps32): :func:`difference_bound`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.fft as sfft

from sarcli.focus.rangecomp import C
from sarcli.gpu.device import Cuda

ROWS = 512  # azimuth-frequency rows per tile of the filter/upsampling/RCMC pass
SPAN_PHASE_RAD = 2e-3  # the CPU kernel's span interpolation: phase (sarcli.focus.rcmc docstring)
SPAN_POSITION_SAMPLES = 1e-4  # ... and range position


def difference_bound(n_fft_az: int, n_fft_r: int, taps: int, precision: str) -> float:
    """Bound on |GPU - CPU| / (peak of a point target's image) for a block (module docstring):
    the CPU kernel's span interpolation (phase error, plus a band-limited signal's change over the position
    error: at most pi x position, in units of the peak) plus float32 round-off of the FFTs and sums,
    (2 log2(N L) + taps + 8) eps. In double precision only the span interpolation remains."""
    eps = float(np.finfo(np.float32 if precision == "single" else np.float64).eps)
    fft_and_sums = (2.0 * math.log2(n_fft_az * n_fft_r) + taps + 8.0) * eps
    return SPAN_PHASE_RAD + math.pi * SPAN_POSITION_SAMPLES + fft_and_sums


def range_filter_rows(xp: Any, y: Any, h: Any, f_tau: Any, inv_k: Any, n_out: int) -> Any:
    """Range matched filter x SRC phase ``exp(-j pi f_tau^2 inv_k[row])`` of spectrum rows ``y`` (rows x L),
    zero padded in the middle to ``n_out`` columns (Fourier interpolation): as
    :func:`sarcli.focus.rangecomp.apply_range_filter_2d`."""
    filt = y * (h[None, :] * xp.exp(-1j * math.pi * inv_k[:, None] * (f_tau * f_tau)[None, :])).astype(y.dtype)
    n = y.shape[1]
    half = (n + 1) // 2
    out = xp.zeros((y.shape[0], n_out), y.dtype)
    out[:, :half] = filt[:, :half]
    out[:, n_out - (n - half):] = filt[:, half:]
    return out


def lookup(xp: Any, tab: Any, u: Any) -> Any:
    """Linear lookup of a window table on u in [-1/2, 1/2] (:func:`sarcli.focus.windows.table_lookup`)."""
    n = tab.shape[0]
    t = (u + 0.5) * (n - 1)
    j = xp.minimum(xp.floor(t).astype(xp.int64), n - 2)
    a = t - j
    return tab[j] * (1.0 - a) + tab[j + 1] * a


def sample_rows(xp: Any, s: Any, p: Any, kind: int, table: Any) -> Any:
    """Rows ``s`` (rows x n) read at positions ``p`` (rows x m, samples), zeros outside: nearest (kind 0),
    linear (1) or the windowed-sinc ``table`` at the nearest of its phases (2), as the numba kernels
    (:func:`sarcli.focus.rcmc.rcmc_azimuth`) read them."""
    taps = 1 if kind == 0 else (2 if kind == 1 else table.shape[1])
    pad = taps + 1
    rows, nrow = s.shape
    padded = xp.zeros((rows, nrow + 2 * pad), s.dtype)
    padded[:, pad:pad + nrow] = s

    def take(idx: Any) -> Any:
        return xp.take_along_axis(padded, xp.clip(idx + pad, 0, nrow + 2 * pad - 1), axis=1)

    if kind == 0:
        return take(xp.floor(p + 0.5).astype(xp.int64))
    j = xp.floor(p).astype(xp.int64)
    if kind == 1:
        mu = (p - j).astype(table.dtype)
        return take(j) * (1.0 - mu) + take(j + 1) * mu
    jp = ((p - j) * (table.shape[0] - 1) + 0.5).astype(xp.int64)
    b = j - (taps // 2 - 1)
    val = xp.zeros(p.shape, s.dtype)
    for t in range(taps):
        val += take(b + t) * table[jp, t]
    return val


def rcmc_azimuth_rows(xp: Any, s: Any, f_bin: Any, r_first: float, dr: float, r0: Any, v: Any, fdc: Any, dt: Any,
                      ph0: Any, wavelength: float, prf: float, ba: float, wtab: Any, kind: int, table: Any,
                      shift: int) -> Any:
    """RCMC + azimuth matched filter of rows ``s`` (rows x upsampled range) onto the columns of ``r0``:
    :func:`sarcli.focus.rcmc.rcmc_azimuth` with the geometry exact at every sample (module docstring)."""
    fb = f_bin[:, None]
    off = fb - fdc[None, :]
    off = off - prf * xp.floor(off / prf + 0.5)
    f = fdc[None, :] + off
    x = (wavelength * f / (2.0 * v[None, :])) ** 2
    d = xp.sqrt(1.0 - x)
    dm1 = -x / (1.0 + d)
    p = (r0[None, :] - r_first - r0[None, :] * dm1 / d) / dr
    ph = (4.0 * math.pi * r0[None, :] * dm1 / wavelength - 2.0 * math.pi * fb * shift / prf + 0.25 * math.pi
          - 2.0 * math.pi * f * dt[None, :] + ph0[None, :])
    u = off / ba
    inside = xp.abs(u) <= 0.5
    w = xp.where(inside, lookup(xp, wtab, xp.clip(u, -0.5, 0.5)), 0.0)
    val = sample_rows(xp, s, p, kind, table)
    return (val * (w * xp.exp(1j * ph))).astype(s.dtype)


def spectrum(plan: Any, data: np.ndarray, off: int, gain: np.ndarray | None, dev: Cuda) -> Any:
    """The block's 2-D spectrum on ``dev`` (N x L, the plan's precision): raw lines ``data`` (times ``gain`` per
    line) at row ``off``, zeros elsewhere, range FFT then azimuth FFT (:func:`sarcli.focus.rda._range_rows`)."""
    xp = dev.xp
    cdt = plan.h.dtype
    rdt = np.float32 if cdt == np.complex64 else np.float64
    block = np.asarray(data, cdt)
    if gain is not None:
        block = block * gain[:, None].astype(rdt)
    y = xp.zeros((plan.n_fft_az, plan.n_fft_r), cdt)
    y[off:off + block.shape[0], :block.shape[1]] = dev.asarray(block)
    y = xp.fft.fft(y, axis=1)
    return xp.fft.fft(y, axis=0).astype(cdt)


def filter_rcmc_rows(plan: Any, b: int, y: Any, inv_k: np.ndarray, dev: Cuda) -> Any:
    """Range filter x SRC (``inv_k`` per row; zeros: none) x Fourier upsampling, range IFFT, RCMC and azimuth
    matched filter of the active rows of the 2-D spectrum ``y`` on ``dev``, in tiles of ``ROWS``: the
    (N x n_samples) range-Doppler lines (:func:`sarcli.focus.rda._filter_rcmc_rows`)."""
    from sarcli.focus.rda import active_rows

    xp = dev.xp
    k, g, raw = plan.options, plan.grid, plan.raw
    nr = plan.output_shape[1]
    cdt = plan.h.dtype
    rdt = np.float32 if cdt == np.complex64 else np.float64
    factor = k.rcmc_oversample
    q = plan.block[b]
    geo = {key: dev.asarray(np.ascontiguousarray(q[key], np.float64)) for key in ("v", "fdc", "dt", "ph0")}
    f_bin = dev.asarray(plan.f_bin)
    f_tau = dev.asarray(sfft.fftfreq(plan.n_fft_r, 1.0 / raw.radar.range_sampling_rate_hz))
    inv_k = dev.asarray(inv_k)
    h = dev.asarray(plan.h)
    wtab = dev.asarray((plan.wtab * factor).astype(rdt))
    table = dev.asarray(plan.table)
    ranges = dev.asarray(g.ranges)
    dr = C / (2.0 * raw.radar.range_sampling_rate_hz) / factor
    out = xp.zeros((plan.n_fft_az, nr), cdt)
    active = active_rows(plan.f_bin, q["fdc"], g.prf, g.ba)
    edges = np.flatnonzero(np.diff(np.r_[0, active.astype(np.int8), 0]))
    for first, stop in zip(edges[::2], edges[1::2], strict=True):  # runs of active rows, in tiles
        for lo in range(int(first), int(stop), ROWS):
            hi = min(int(stop), lo + ROWS)
            up = range_filter_rows(xp, y[lo:hi], h, f_tau, inv_k[lo:hi], factor * plan.n_fft_r)
            up = xp.fft.ifft(up, axis=1).astype(cdt)
            out[lo:hi] = rcmc_azimuth_rows(xp, up, f_bin[lo:hi], float(g.ranges[0]), dr, ranges, geo["v"], geo["fdc"],
                                           geo["dt"], geo["ph0"], g.wavelength, g.prf, g.ba, wtab, plan.kind, table,
                                           g.shift)
    return out


def focus_rows(plan: Any, b: int, data: np.ndarray, off: int, gain: np.ndarray | None, prm: dict[str, Any],
               dev: Cuda) -> np.ndarray:
    """Steps 1-5 of :mod:`sarcli.focus.rda` for block ``b`` on ``dev``: the (N x n_samples) azimuth-compressed
    lines (host array of the plan's precision), raw lines ``data`` (times ``gain`` per line) at row ``off``,
    ``prm`` the host parameters both paths share (:meth:`sarcli.focus.rda.RangeDoppler.block_parameters`)."""
    y = spectrum(plan, data, off, gain, dev)
    out = filter_rcmc_rows(plan, b, y, prm["inv_k"], dev)
    img = dev.xp.fft.ifft(out, axis=0)
    return np.ascontiguousarray(dev.to_host(img), plan.h.dtype)
