"""One block of the chirp-scaling focuser against an array namespace ``xp`` (CuPy on the card, numpy in CI).

:meth:`sarcli.focus.csa.ChirpScaling.focus_block` with ``device="cuda"`` calls :func:`focus_rows` for steps 1-4
of :mod:`sarcli.focus.csa` (azimuth FFT, chirp scaling, range FFT, range compression x SRC x bulk RCMC phase
with Fourier upsampling, range IFFT, the per-column range read with azimuth compression and residual phase,
azimuth IFFT); the per-line corrections run on the CPU as always (:mod:`sarcli.gpu.rd_xp` does the same for RD,
whose tables, reads and tiles this module shares). Every per-row parameter comes from
:func:`sarcli.focus.csa.block_parameters`, computed once on the host for both paths.

Difference from the CPU path: the numba kernels advance the quadratic phases by phasor recurrences restarted
exactly every 64 samples (drift below 1e-12 rad) and, in the azimuth step, interpolate the phase linearly over
spans of 32 columns where its curvature error stays below ``SPAN_TOL_RAD`` = 1e-3 rad; here every phase is
exact. So the images differ by at most that 1e-3 rad plus float32 round-off in another order
(:func:`difference_bound`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sarcli.gpu.device import Cuda
from sarcli.gpu.rd_xp import ROWS, lookup, sample_rows

SPAN_TOL_RAD = 1e-3  # the CPU azimuth kernel's span interpolation of the phase (sarcli.focus.csa)


def difference_bound(n_fft_az: int, n_fft_r: int, taps: int, precision: str) -> float:
    """Bound on |GPU - CPU| / (peak of a point target's image): the CPU kernel's phase span interpolation plus
    float32 round-off of the FFTs (three passes) and sums, (3 log2(N L) + taps + 8) eps."""
    eps = float(np.finfo(np.float32 if precision == "single" else np.float64).eps)
    return SPAN_TOL_RAD + (3.0 * math.log2(n_fft_az * n_fft_r) + taps + 8.0) * eps


def chirp_scale_rows(xp: Any, x: Any, nr: int, q2: Any, tau_r: Any, tau0: float, dtau: float) -> Any:
    """x[k, m] exp(j q2[k] (tau0 + m dtau - tau_r[k])^2) for m < nr (:func:`sarcli.focus.csa.chirp_scale`)."""
    u = tau0 + xp.arange(nr) * dtau
    u = u[None, :] - tau_r[:, None]
    out = x.copy()
    out[:, :nr] = x[:, :nr] * xp.exp(1j * q2[:, None] * u * u).astype(x.dtype)
    return out


def range_filter_rows(xp: Any, x: Any, f_tau: Any, inv_band: Any, c2: Any, c1: Any, c0: float, gain: Any,
                      wtab: Any, n_out: int) -> Any:
    """x[k, m] W(f inv_band[k]) gain[k] exp(j (c2[k] f^2 + c1[k] f + c0)), f = f_tau[m], zero padded in the
    middle to ``n_out`` columns (:func:`sarcli.focus.csa.csa_range_filter`)."""
    f = f_tau[None, :]
    u = f * inv_band[:, None]
    w = xp.where(xp.abs(u) <= 0.5, lookup(xp, wtab, xp.clip(u, -0.5, 0.5)), 0.0)
    filt = x * (w * gain[:, None] * xp.exp(1j * ((c2[:, None] * f + c1[:, None]) * f + c0))).astype(x.dtype)
    n = x.shape[1]
    half = (n + 1) // 2
    out = xp.zeros((x.shape[0], n_out), x.dtype)
    out[:, :half] = filt[:, :half]
    out[:, n_out - (n - half):] = filt[:, half:]
    return out


def azimuth_rows(xp: Any, up: Any, f_row: Any, f_bin: Any, pos: Any, r0: Any, v: Any, fdc: Any, dt: Any, ph0: Any,
                 km: Any, a: Any, tau_r: Any, wavelength: float, prf: float, ba: float, shift: int, wtab: Any,
                 kind: int, table: Any) -> Any:
    """Step 3-4 per row and column (:func:`sarcli.focus.csa.csa_azimuth`) with the phase exact everywhere."""
    f = f_row[:, None]
    x = (wavelength * f / (2.0 * v[None, :])) ** 2
    d = xp.sqrt(1.0 - x)
    dm1 = -x / (1.0 + d)
    g = math.pi * km * a / (1.0 + a)
    e = 2.0 * r0[None, :] / (299792458.0 * d) - tau_r[:, None]
    psh = -2.0 * math.pi * f_bin * shift / prf + 0.25 * math.pi
    ph = (4.0 * math.pi * r0[None, :] * dm1 / wavelength + psh[:, None] - 2.0 * math.pi * f * dt[None, :]
          + ph0[None, :] - g[:, None] * e * e)
    u = (f - fdc[None, :]) / ba
    w = xp.where(xp.abs(u) <= 0.5, lookup(xp, wtab, xp.clip(u, -0.5, 0.5)), 0.0)
    val = sample_rows(xp, up, xp.broadcast_to(pos[None, :], (up.shape[0], pos.shape[0])), kind, table)
    return (val * (w * xp.exp(1j * ph))).astype(up.dtype)


def focus_rows(plan: Any, b: int, data: np.ndarray, off: int, gain: np.ndarray | None, prm: dict[str, Any],
               dev: Cuda) -> np.ndarray:
    """Steps 1-4 of :mod:`sarcli.focus.csa` for block ``b`` on ``dev``: the (N x n_samples) azimuth-compressed
    lines (host array of the plan's precision)."""
    from sarcli.focus.interp import parse_interpolator

    xp = dev.xp
    k, g = plan.options, plan.grid
    nr = plan.output_shape[1]
    cdt = np.complex64 if k.precision == "single" else np.complex128
    rdt = np.float32 if cdt == np.complex64 else np.float64
    factor = k.range_oversample
    block = np.asarray(data, cdt)
    if gain is not None:
        block = block * gain[:, None].astype(rdt)
    y = xp.zeros((plan.n_fft_az, plan.n_fft_r), cdt)
    y[off:off + block.shape[0], :nr] = dev.asarray(block)
    y[:, :nr] = xp.fft.fft(y[:, :nr], axis=0).astype(cdt)
    q, rp = plan.block[b], prm["rows"]
    on = {name: dev.asarray(np.ascontiguousarray(arr, np.float64)) for name, arr in (
        ("q2", prm["q2"]), ("tau_r", rp["tau_r"]), ("inv_band", prm["inv_band"]), ("c2", prm["c2"]),
        ("c1", prm["c1"]), ("gain", prm["gain"]), ("f", rp["f"]), ("km", rp["km"]), ("a", rp["a"]),
        ("f_bin", plan.f_bin), ("pos", prm["pos"]), ("f_tau", prm["f_tau"]), ("r0", g.ranges), ("v", q["v"]),
        ("fdc", q["fdc"]), ("dt", q["dt"]), ("ph0", q["ph0"]))}
    wtab_r, wtab_a = dev.asarray(plan.wtab_r), dev.asarray(plan.wtab_a)
    table = dev.asarray(plan.table)
    kind = parse_interpolator(k.interpolator)[0]
    out = xp.zeros((plan.n_fft_az, nr), cdt)
    edges = np.flatnonzero(np.diff(np.r_[0, prm["active"].astype(np.int8), 0]))
    for first, stop in zip(edges[::2], edges[1::2], strict=True):  # runs of active rows, in tiles
        for lo in range(int(first), int(stop), ROWS):
            hi = min(int(stop), lo + ROWS)
            sl = slice(lo, hi)
            rows = chirp_scale_rows(xp, y[sl], nr, on["q2"][sl], on["tau_r"][sl], prm["tau0"], prm["dtau"])
            rows = xp.fft.fft(rows, axis=1)
            up = range_filter_rows(xp, rows, on["f_tau"], on["inv_band"][sl], on["c2"][sl], on["c1"][sl], prm["c0"],
                                   on["gain"][sl], wtab_r, factor * plan.n_fft_r)
            up = xp.fft.ifft(up, axis=1).astype(cdt)
            out[sl] = azimuth_rows(xp, up, on["f"][sl], on["f_bin"][sl], on["pos"], on["r0"], on["v"], on["fdc"],
                                   on["dt"], on["ph0"], on["km"][sl], on["a"][sl], on["tau_r"][sl], g.wavelength,
                                   g.prf, g.ba, g.shift, wtab_a, kind, table)
    img = xp.fft.ifft(out, axis=0)
    return np.ascontiguousarray(dev.to_host(img), cdt)
