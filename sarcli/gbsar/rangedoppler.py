"""Range-Doppler (RD) focusing of seed 000 (eq. 13-21) with the N_xfft rule of Table 1.

About the target's own azimuth xc the phase history is the azimuth chirp of eq. 18
(``u_Dc = 0``, ``u_R = -2/(lam R0)``); it is shift-invariant in x at fixed R0, so RD correlates each
range row with the reference of eq. 19, limited to the beam footprint ``|x| <= lam R0/(2 L_x)``:

    h_R0(x) = exp(-j 4 pi (sqrt(R0^2 + x^2) - R0)/lam)          (exact hyperbola, not its chirp expansion)
    g(x, R0) = sum_i w_i P_i(R_i) h_R0*(x_i - x) / sum_i w_i = IFFT_u[ FFT_x(w P)(u) * conj(FFT_x h_R0)(u) ]

The exact sampled reference is transformed instead of the stationary-phase chirp spectrum, because
the azimuth time-bandwidth product ``2 X^2/(lam R0)`` is ~1 at far range (the stationary-phase
formula, with its pi/4, would not hold). Range cell migration ``R_i - R0`` is corrected in the
azimuth-wavenumber domain with the stationary-phase map ``u = -2 sin(theta)/lam``,
``R = R0/cos(theta)`` (linear interpolation of the baseband range spectrum, oversampled 2x by
default). Pixels: ``dx`` in azimuth at every range (no geometric correction), phase ``-4 pi R0/lam``.
To cover DF's azimuth width ``lam Rc/(2 dx)`` at range Rc the FFT needs ``N_xfft = 2^m >= lam Rc/(2 dx^2) + 1``
samples (zero padding): memory ``N_Rfft x N_xfft x 8`` bytes, the paper's 128 MB outdoors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft

from sarcli.errors import SarcliError
from sarcli.gbsar.backprojection import stop_weights
from sarcli.gbsar.deramp import uniform_step
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.system import next_pow2


@dataclass
class RDImage:
    """RD image ``data`` (n_r, N_xfft) on ranges R0 (m) and azimuths ``x0 + m dx`` (scene frame)."""

    data: np.ndarray
    ranges_m: np.ndarray
    azimuth_first_m: float
    dx_m: float
    n_xfft: int

    @property
    def azimuths_m(self) -> np.ndarray:
        return self.azimuth_first_m + self.dx_m * np.arange(self.n_xfft)


def rd_n_xfft(wavelength_m: float, rc_m: float, dx_m: float, n_x: int) -> int:
    """Table 1: ``N_xfft = 2^m >= max(N_x, lam Rc/(2 dx^2) + 1)``."""
    return next_pow2(max(n_x, wavelength_m * rc_m / (2 * dx_m ** 2) + 1))


def focus_rd(prof: RangeProfiles, antenna_length_m: float, n_xfft: int | None = None,
             azimuth_window: str = "hamming", max_range_m: float | None = None,
             block_rows: int = 256) -> RDImage:
    """RD image of the range rows up to ``max_range_m`` (default: all), processed in row blocks."""
    dx = uniform_step(prof.positions_m)
    n_x = prof.positions_m.size
    lam = prof.wavelength_m
    r = prof.ranges_m
    n_rows = r.size if max_range_m is None else int(np.searchsorted(r, max_range_m, side="right"))
    if n_rows < 1:
        raise SarcliError("no range rows to focus with RD")
    n = rd_n_xfft(lam, r[n_rows - 1], dx, n_x) if n_xfft is None else int(n_xfft)
    if n < n_x:
        raise SarcliError(f"N_xfft = {n} is smaller than the {n_x} rail stops")
    pad = (n - n_x) // 2
    w = stop_weights(prof, azimuth_window)
    a = np.zeros((n, r.size), np.complex64)
    a[pad:pad + n_x] = prof.data * (w / w.sum())[:, None].astype(np.float32)
    spec = scipy.fft.fft(a, axis=0, overwrite_x=True)  # (n_u, n_r): the N_Rfft x N_xfft array of Table 1
    u = scipy.fft.fftfreq(n, dx)
    sin_t = -lam * u / 2
    cos_t = np.sqrt(np.clip(1.0 - sin_t ** 2, 0.0, None))
    offs = np.where(np.arange(n) < n - n // 2, np.arange(n), np.arange(n) - n) * dx  # circular lags
    out = np.zeros((n_rows, n), np.complex64)
    for b0 in range(0, n_rows, block_rows):
        rows = np.arange(b0, min(b0 + block_rows, n_rows))
        r0 = r[rows]
        # range cell migration correction: take row R0/cos(theta(u)) of the spectrum
        with np.errstate(divide="ignore"):
            fr = np.where(cos_t[:, None] > 0, r0[None, :] / cos_t[:, None], np.inf) / prof.dr_m
        i0 = np.floor(fr)
        ok = i0 < r.size - 1
        i0 = np.where(ok, i0, 0).astype(np.int64)
        t = np.where(ok, fr - i0, 0.0).astype(np.float32)
        cols = np.arange(n)[:, None]
        blk = np.where(ok, spec[cols, i0] * (1 - t) + spec[cols, np.minimum(i0 + 1, r.size - 1)] * t, 0)
        # exact reference of eq. 19 over the beam footprint, transformed per row
        half = lam * r0 / (2 * antenna_length_m)
        rr = np.sqrt(r0[None, :] ** 2 + offs[:, None] ** 2)
        h = np.where(np.abs(offs[:, None]) <= half[None, :], np.exp(-4j * np.pi * (rr - r0[None, :]) / lam), 0)
        hs = scipy.fft.fft(h.astype(np.complex64), axis=0)
        g = scipy.fft.ifft(blk.astype(np.complex64) * np.conj(hs), axis=0)
        out[rows] = g.T
    x_first = prof.positions_m[0] - pad * dx
    return RDImage(data=out, ranges_m=r[:n_rows].copy(), azimuth_first_m=float(x_first), dx_m=dx, n_xfft=n)
