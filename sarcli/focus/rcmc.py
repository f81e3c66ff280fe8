"""RCMC and azimuth matched filter in the range-Doppler domain (one fused numba kernel).

Input ``S[k, n]``: range-compressed data after the azimuth FFT (azimuth-frequency bin k with signed FFT
frequency ``f_bin[k]``, range sample n at slant range ``r_first + n dr``). For every output range bin
i (closest range ``R0_i``, effective velocity ``V_i``, centroid ``fdc_i``) and bin k:

1. absolute azimuth frequency ``f = fdc_i + wrap(f_bin[k] - fdc_i)`` with wrap into [-PRF/2, PRF/2)
   (the Doppler spectrum of that range bin is centred on its own centroid, several PRFs away if need be);
2. processed band: weight ``W((f - fdc_i) / Ba)`` (zero outside the band Ba);
3. RCMC: the target sits at range ``R0_i / D(f)``, D = sqrt(1 - (lam f / 2V_i)^2)
   (see :mod:`sarcli.focus.kinematics`): ``S`` is interpolated there along range;
4. azimuth matched filter ``exp(+j 4 pi R0_i (D(f) - 1) / lam + j pi/4)``: it cancels the azimuth
   phase ``-4 pi R0 D / lam`` and keeps ``-4 pi R0 / lam`` (the SLC phase convention: a scatterer at R0
   has phase -4 pi R0 / lam at its peak); the +pi/4 cancels the -pi/4 that the stationary-phase
   spectrum of a chirp with negative rate carries (C&W's filter omits it: their peaks are off by
   pi/4, which matters for interferometry and for RD vs backprojection), and
   ``exp(-j 2 pi f_bin shift / PRF)`` moves the focused target ``shift`` lines later (an integer,
   so the wrapped and absolute frequencies give the same phase), and ``exp(-j 2 pi f dt_i)`` moves it
   by the (fractional) time ``dt_i`` (s) with the ABSOLUTE frequency, which keeps the carrier phase:
   the orbit correction of the hyperbolic model's zero-Doppler time (:mod:`sarcli.focus.rda`);
   ``exp(j ph0_i)`` is the matching constant phase correction (its closest range).

``D - 1`` is computed as ``-x / (1 + D)`` (x = (lam f / 2V)^2) so the 1e5-rad phase keeps full float64
precision. The kernel runs in the precision of ``S``/``out`` (complex64 or complex128) with float64
geometry and phase.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sarcli.focus.interp import interpolate_numpy
from sarcli.focus.windows import table_lookup, window

SPAN = 32


@njit(inline="always", fastmath=True)
def _geometry(fb, i, r_first, dr, r0, v, fdc, dt, ph0, wavelength, prf, ba, psh):
    """(u, p, phase) of output bin i in the row of FFT frequency fb (see the module docstring)."""
    off = fb - fdc[i]
    off -= prf * np.floor(off / prf + 0.5)
    f = fdc[i] + off
    x = (wavelength * f / (2.0 * v[i])) ** 2
    d = np.sqrt(1.0 - x)
    dm1 = -x / (1.0 + d)
    p = (r0[i] - r_first - r0[i] * dm1 / d) / dr
    ph = 4.0 * np.pi * r0[i] * dm1 / wavelength + psh + 0.25 * np.pi - 2.0 * np.pi * f * dt[i] + ph0[i]
    return off / ba, p, ph


@njit(inline="always", fastmath=True)
def _sample(row, p, kind, zero):
    """Nearest (kind 0) or linear (kind 1) interpolation of ``row`` at p (zeros outside)."""
    nr = row.shape[0]
    val = zero
    if kind == 0:
        n = int(np.floor(p + 0.5))
        if 0 <= n < nr:
            val = row[n]
    else:
        n = int(np.floor(p))
        mu = p - n
        if 0 <= n < nr:
            val += row[n] * (1.0 - mu)
        if 0 <= n + 1 < nr:
            val += row[n + 1] * mu
    return val


@njit(nogil=True, cache=True, fastmath=True)
def rcmc_azimuth(s, f_bin, r_first, dr, r0, v, fdc, dt, ph0, wavelength, prf, ba, wtab, kind, table, shift, out):
    """Fused RCMC + azimuth matched filter; writes ``out`` (n_az, len(r0)); ``out`` may be ``s``.

    Serial and GIL-free: the RDA runs it on chunks of rows in a thread pool (one kernel call per
    chunk and thread, no barrier between threads).

    Speed: the range position and the phase are computed exactly every SPAN bins and linearly in
    between (a phasor recurrence instead of a sine and cosine per sample; both vary smoothly with
    range: the neglected curvature is below 2e-3 rad and 1e-4 sample over a span for Radarsat-1),
    except across a span where the Doppler wrap jumps, which is computed sample by sample.
    """
    na = s.shape[0]
    nout = r0.shape[0]
    nph = table.shape[0] - 1
    taps = table.shape[1]
    k0 = taps // 2 - 1
    # in place is allowed: when out overlaps s, each row is copied before it is overwritten
    s_lo = s.ctypes.data
    s_hi = s_lo + (s.shape[0] - 1) * s.strides[0] + (s.shape[1] - 1) * s.strides[1] + s.itemsize
    o_lo = out.ctypes.data
    o_hi = o_lo + (out.shape[0] - 1) * out.strides[0] + (out.shape[1] - 1) * out.strides[1] + out.itemsize
    alias = o_lo < s_hi and s_lo < o_hi
    zero = np.zeros(1, s.dtype)[0]
    nrow = s.shape[1]
    for k in range(na):
        row = s[k, :]
        if alias:
            row = row.copy()
        fb = f_bin[k]
        psh = -2.0 * np.pi * fb * shift / prf
        i0 = 0
        while i0 < nout:
            i1 = min(i0 + SPAN, nout - 1)
            u0, p0, q0 = _geometry(fb, i0, r_first, dr, r0, v, fdc, dt, ph0, wavelength, prf, ba, psh)
            u1, p1, q1 = _geometry(fb, i1, r_first, dr, r0, v, fdc, dt, ph0, wavelength, prf, ba, psh)
            n = i1 - i0
            smooth = n > 0 and abs(u1 - u0) * ba < 0.5 * prf
            if smooth:
                dp = (p1 - p0) / n
                rot = complex(np.cos((q1 - q0) / n), np.sin((q1 - q0) / n))
                cur = complex(np.cos(q0), np.sin(q0))
            stop = i1 if i1 < nout - 1 else nout
            for i in range(i0, stop):
                if smooth:
                    u = u0 + (u1 - u0) * (i - i0) / n
                    p = p0 + dp * (i - i0)
                    ph_c = cur
                    cur *= rot
                else:
                    u, p, q = _geometry(fb, i, r_first, dr, r0, v, fdc, dt, ph0, wavelength, prf, ba, psh)
                    ph_c = complex(np.cos(q), np.sin(q))
                if u < -0.5 or u > 0.5:
                    out[k, i] = 0.0
                    continue
                if kind == 2:  # written out here: numba's inlining of _sample made this loop 2x slower
                    j = int(np.floor(p))
                    jp = int((p - j) * nph + 0.5)
                    b = j - k0
                    val = zero
                    if b >= 0 and b + taps <= nrow:
                        for t in range(taps):
                            val += row[b + t] * table[jp, t]
                    else:
                        for t in range(taps):
                            if 0 <= b + t < nrow:
                                val += row[b + t] * table[jp, t]
                else:
                    val = _sample(row, p, kind, zero)
                out[k, i] = val * (table_lookup(wtab, u) * ph_c)
            i0 = stop


def rcmc_azimuth_numpy(s, f_bin, r_first, dr, r0, v, fdc, dt, ph0, wavelength, prf, ba, window_spec, interpolator,
                       shift):
    """Plain-numpy reference of :func:`rcmc_azimuth` (exact window and interpolation weights)."""
    off = f_bin[:, None] - fdc[None, :]
    off = off - prf * np.floor(off / prf + 0.5)
    w = window(window_spec, off / ba)
    f = fdc[None, :] + off
    d = np.sqrt(1.0 - (wavelength * f / (2.0 * v[None, :])) ** 2)
    p = (r0[None, :] / d - r_first) / dr
    val = interpolate_numpy(s, p, interpolator)
    ph = (4.0 * np.pi * r0[None, :] * (d - 1.0) / wavelength - 2.0 * np.pi * f_bin[:, None] * shift / prf
          + 0.25 * np.pi - 2.0 * np.pi * f * dt[None, :] + ph0[None, :])
    return val * w * np.exp(1j * ph)
