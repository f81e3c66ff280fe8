"""One block of the omega-k focuser against an array namespace ``xp`` (CuPy on the card, numpy in CI).

:meth:`sarcli.focus.omegak.Omegak.focus_block` with ``device="cuda"`` calls :func:`focus_rows` for steps 1-4 of
:mod:`sarcli.focus.omegak` and keeps the per-line corrections on the CPU, as :mod:`sarcli.gpu.rd_xp` does for RD
(whose 2-D spectrum, tiles, table reads and, in the monochromatic mode, range filter/RCMC/azimuth rows this
module reuses). The per-block parameters (absolute Doppler of the rows, range frequencies, the active rows)
come from :func:`sarcli.focus.omegak.block_parameters`, computed once on the host for both paths.

- ``stolt = "full"``: :func:`stolt_rows` (RFM x matched filter, the Stolt read of each row at the mapping's
  input frequency by the plan's kernel and table, Jacobian, reference restore), range IFFT, then
  :func:`column_corrections` (azimuth window, POSP/line phase, orbit timing, differential velocity phase and,
  where it reaches 1e-3 sample, the band-pass differential range shift), azimuth IFFT;
- ``stolt = "monochromatic"``: the bulk non-linear phase :func:`bulk_phase_rows`, then RD's range filter
  (no SRC), upsampling, RCMC and azimuth rows (:func:`sarcli.gpu.rd_xp.filter_rcmc_rows`), azimuth IFFT.

Difference bound against the numba CPU kernels. The interpolation tables and their phase indices are the
same on both paths (the Stolt table cast to the plan's precision, the 8-tap differential table, the window
table with the same linear lookup), so the reads agree up to round-off. What differs:

- full mode: :func:`sarcli.focus.omegak.stolt_rows` advances the input phase exp(j Phi_in) by a second-order
  phasor recurrence restarted exactly over spans chosen so that the neglected third-order term stays below
  1e-6 rad, and the output phase by a rotation restarted every 64 bins (round-off 64 x eps64, negligible);
  the differential shift's carrier by an 8-step rotation (8 eps64). Here every phase is evaluated exactly:
  ``RECURRENCE_RAD`` = 1e-6 rad, i.e. 1e-6 of the peak;
- monochromatic mode: the bulk phase is exact per sample on both paths; RD's fused kernel interpolates the
  geometry over spans of 32 bins, which :func:`sarcli.gpu.rd_xp.difference_bound` bounds;
- float32 round-off in another order: four FFT passes, O(eps log2(N L)) each relative to the block (2
  log2(N L) eps in the sense of the rd_xp bound), the interpolation sums (taps eps each: the Stolt kernel's
  and, full mode, the 8-tap differential read) and the complex64 stores between the stages (8 eps).

:func:`difference_bound` adds these (relative to a point target's peak); tests/gpu/test_omegak_xp.py uses it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sarcli.focus.rangecomp import C
from sarcli.gpu import rd_xp
from sarcli.gpu.device import Cuda
from sarcli.gpu.rd_xp import ROWS, lookup, sample_rows

RECURRENCE_RAD = 1e-6  # the CPU Stolt kernel's phasor recurrence: neglected third-order term (omegak.stolt_rows)
DIFF_TAPS = 8  # sarcli.focus.omegak.DIFF_INTERPOLATOR


def difference_bound(n_fft_az: int, n_fft_r: int, taps: int, precision: str, stolt: str) -> float:
    """Bound on |GPU - CPU| / (peak of a point target's image) for an omega-k block (module docstring);
    ``taps`` the Stolt kernel's (full) or the RCMC kernel's (monochromatic)."""
    eps = float(np.finfo(np.float32 if precision == "single" else np.float64).eps)
    if stolt == "monochromatic":
        return rd_xp.difference_bound(n_fft_az, n_fft_r, taps, precision) + eps  # + the bulk phase's store
    return RECURRENCE_RAD + (2.0 * math.log2(n_fft_az * n_fft_r) + taps + DIFF_TAPS + 8.0) * eps


def _phase(xp: Any, cycles: Any) -> Any:
    """exp(j 2 pi cycles) with the whole cycles removed first (float64 arguments of 1e5 cycles and more)."""
    return xp.exp(2j * math.pi * (cycles - xp.floor(cycles)))


def stolt_rows(xp: Any, x: Any, h: Any, f_tau: Any, f_eta: Any, v_ref: float, r_ref: float, tau0: float,
               f0: float, fs: float, kind: int, table: Any) -> Any:
    """Full Stolt step of spectrum rows ``x`` (rows x L, FFT order): :func:`sarcli.focus.omegak.stolt_rows`
    with the input and output phases exact at every bin."""
    n = x.shape[1]
    df = fs / n
    half = n // 2
    kr = 4.0 * math.pi * r_ref / C
    order = (xp.arange(n) - half) % n
    f = (xp.arange(n) - half) * df  # frequency-ordered axis
    a2 = (C * f_eta[:, None] / (2.0 * v_ref)) ** 2
    d = xp.sqrt(1.0 - a2 / (f0 * f0))
    ph_in = kr * (2.0 * f0 * f + f * f)[None, :] / (xp.sqrt((f0 + f[None, :]) ** 2 - a2) + f0 * d)
    u = (x[:, order] * h[order][None, :]) * (xp.exp(1j * ph_in) * _phase(xp, -f * tau0)[None, :])
    ck = f0 * (d - 1.0)
    w = f_tau[None, :] - ck
    w = w - fs * xp.floor(w / fs + 0.5)
    fin = (2.0 * f0 * d * w + w * w) / (xp.sqrt((f0 * d + w) ** 2 + a2) + f0)
    val = sample_rows(xp, u, fin / df + half, kind, table)
    return val * ((f0 + ck + w) / (f0 + fin)) * (xp.exp(-1j * kr * w) * _phase(xp, (ck + w) * tau0))


def column_corrections(xp: Any, z: Any, f_bin: Any, r0: Any, v: Any, v_ref: float, fdc: Any, dt: Any, ph0: Any,
                       wavelength: float, prf: float, ba: float, wtab: Any, shift: int, f0: float, dr: float,
                       table: Any, tol: float) -> Any:
    """Step 4 on range-Doppler rows ``z`` (rows x L) onto the ``len(r0)`` output columns:
    :func:`sarcli.focus.omegak.column_corrections` with the carrier of the differential read exact per tap."""
    rows, n = z.shape
    nr = r0.shape[0]
    fb = f_bin[:, None]
    off = fb - fdc[None, :]
    off = off - prf * xp.floor(off / prf + 0.5)
    u = off / ba
    f = fdc[None, :] + off
    xi = (wavelength * f / (2.0 * v[None, :])) ** 2
    xr = (wavelength * f / (2.0 * v_ref)) ** 2
    di = xp.sqrt(1.0 - xi)
    dref = xp.sqrt(1.0 - xr)
    dd = (xr - xi) / (di + dref)
    ph = (4.0 * math.pi * r0[None, :] * dd / wavelength - 2.0 * math.pi * fb * shift / prf + 0.25 * math.pi
          - 2.0 * math.pi * f * dt[None, :] + ph0[None, :])
    delta = -r0[None, :] * dd / (di * dr)
    # the envelope at i + delta: band-pass read around the row's carrier (cycles per sample), remodulated at i
    cyc = -f0 * xr / (1.0 + dref) * 2.0 * dr / C
    i = xp.arange(nr)[None, :]
    p = i + delta
    n0 = xp.floor(p).astype(xp.int64)
    nph = table.shape[0] - 1
    taps = table.shape[1]
    jp = ((p - n0) * nph + 0.5).astype(xp.int64)
    pad = taps + 1
    padded = xp.zeros((rows, n + 2 * pad), z.dtype)
    padded[:, pad:pad + n] = z
    shifted = xp.zeros((rows, nr), np.complex128)
    for t in range(taps):
        m = n0 - (taps // 2 - 1) + t
        zm = xp.take_along_axis(padded, xp.clip(m + pad, 0, n + 2 * pad - 1), axis=1)
        shifted += zm * (table[jp, t] * _phase(xp, cyc * (i - m)))
    val = xp.where(xp.abs(delta) < tol, z[:, :nr], shifted)
    inside = xp.abs(u) <= 0.5
    win = xp.where(inside, lookup(xp, wtab, xp.clip(u, -0.5, 0.5)), 0.0)
    return val * (win * xp.exp(1j * ph))


def bulk_phase_rows(xp: Any, x: Any, f_tau: Any, f_eta: Any, v_ref: float, r_ref: float, f0: float) -> Any:
    """Rows ``x`` times exp(j (4 pi R_ref / c) NL(f_tau)) (:func:`sarcli.focus.omegak.bulk_phase_rows`)."""
    kr = 4.0 * math.pi * r_ref / C
    a2 = (C * f_eta[:, None] / (2.0 * v_ref)) ** 2
    d = xp.sqrt(1.0 - a2 / (f0 * f0))
    f = f_tau[None, :]
    nl = (2.0 * f0 * f + f * f) / (xp.sqrt((f0 + f) ** 2 - a2) + f0 * d) - f / d
    return (x * xp.exp(1j * kr * nl)).astype(x.dtype)


def focus_rows(plan: Any, b: int, data: np.ndarray, off: int, gain: np.ndarray | None, prm: dict[str, Any],
               dev: Cuda) -> np.ndarray:
    """Steps 1-4 of :mod:`sarcli.focus.omegak` for block ``b`` on ``dev``: the (N x n_samples)
    azimuth-compressed lines (host array of the plan's precision), raw lines ``data`` (times ``gain`` per
    line) at row ``off``; ``prm`` from :func:`sarcli.focus.omegak.block_parameters`."""
    from sarcli.focus.interp import table_for
    from sarcli.focus.omegak import DIFF_INTERPOLATOR, SHIFT_TOL_SAMPLES

    xp = dev.xp
    k, g, radar = plan.options, plan.grid, plan.raw.radar
    nr = plan.output_shape[1]
    cdt = plan.h.dtype
    rdt = np.float32 if cdt == np.complex64 else np.float64
    f0, fs = radar.carrier_frequency_hz, radar.range_sampling_rate_hz
    v_ref, r_ref = float(plan.v_ref[b]), float(plan.r_ref[b])
    y = rd_xp.spectrum(plan, data, off, gain, dev)
    f_tau, f_eta = dev.asarray(prm["f_tau"]), dev.asarray(prm["f_eta"])
    if k.stolt == "monochromatic":
        for lo in range(0, plan.n_fft_az, ROWS):  # in tiles: the phase's float64 temporaries stay small
            sl = slice(lo, min(plan.n_fft_az, lo + ROWS))
            y[sl] = bulk_phase_rows(xp, y[sl], f_tau, f_eta[sl], v_ref, r_ref, f0)
        out = rd_xp.filter_rcmc_rows(plan, b, y, np.zeros(plan.n_fft_az), dev)
    else:
        q = plan.block[b]
        on = {key: dev.asarray(np.ascontiguousarray(q[key], np.float64)) for key in ("v", "fdc", "dt", "ph0")}
        f_bin, r0, h = dev.asarray(plan.f_bin), dev.asarray(g.ranges), dev.asarray(plan.h)
        table = dev.asarray(plan.stolt_table.astype(rdt))
        diff_table, wtab = dev.asarray(table_for(DIFF_INTERPOLATOR)[1]), dev.asarray(plan.wtab)
        out = xp.zeros((plan.n_fft_az, nr), cdt)
        edges = np.flatnonzero(np.diff(np.r_[0, prm["active"].astype(np.int8), 0]))
        for first, stop in zip(edges[::2], edges[1::2], strict=True):  # runs of active rows, in tiles
            for lo in range(int(first), int(stop), ROWS):
                sl = slice(lo, min(int(stop), lo + ROWS))
                row = stolt_rows(xp, y[sl], h, f_tau, f_eta[sl], v_ref, r_ref, prm["tau0"], f0, fs, plan.stolt_kind,
                                 table).astype(cdt)
                row = xp.fft.ifft(row, axis=1).astype(cdt)
                out[sl] = column_corrections(xp, row, f_bin[sl], r0, on["v"], v_ref, on["fdc"], on["dt"], on["ph0"],
                                             g.wavelength, g.prf, g.ba, wtab, g.shift, f0, C / (2.0 * fs), diff_table,
                                             SHIFT_TOL_SAMPLES)
    img = xp.fft.ifft(out, axis=0)
    return np.ascontiguousarray(dev.to_host(img), cdt)
