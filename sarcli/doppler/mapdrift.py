"""Data-driven Doppler rate by map-drift autofocus between two azimuth looks.

Model (one range segment, beam-centre time eta = 0): the azimuth signal of a scatterer is
s(eta) = exp(j*2*pi*fdc*eta + j*pi*fr*eta^2). By stationary phase its spectrum has the phase
-pi*(f - fdc)^2/fr. Compressing with the filter exp(+j*pi*(f - fdc)^2/fr0) leaves the residual phase
-pi*(f - fdc)^2*(1/fr - 1/fr0), i.e. the group delay eta(f) = (f - fdc)*(1/fr - 1/fr0): a look centred
at Doppler f_k is displaced by (f_k - fdc)*(1/fr - 1/fr0). Two looks at f_1 < f_2 therefore drift by

    d_eta = eta_2 - eta_1 = (f_2 - f_1) * (1/fr - 1/fr0)   ->   1/fr = 1/fr0 + d_eta / (f_2 - f_1).

f_1, f_2 are the energy-weighted mean Doppler frequencies of the looks (the antenna pattern weights
the spectrum: with the band centres instead the update under-corrects by ~30 %).
d_eta is the peak of the azimuth cross-correlation of the two look intensities summed over range
(parabolic sub-sample interpolation). The estimate is iterated (fr0 <- fr) until it moves by less
than ``tol`` (relative), or until the last three iterates lie within 10 ``tol`` (they then oscillate
on the speckle noise floor of the drift measurement; their mean is returned).

The 2-D arithmetic runs in complex64 (the phase terms reduced in float64 first, ``_unit_phasor``):
the rates move by ~1e-9 relative against a complex128 run, far below the drift's speckle noise.

Before compression the range migration is removed in the range-Doppler domain with the hyperbolic
model R(f) = R0 / D(f), D = sqrt(1 - (lam*f/(2*Vr))^2), Vr^2 = -fr0*lam*R0/2 (re-derived each
iteration), referred to the beam-centre Doppler fdc (a constant range shift per Doppler row, exact by
an FFT phase ramp; the variation of the migration across the segment is ignored). The ABSOLUTE
centroid (ambiguity included) is needed for this: with a wrong ambiguity the migration is wrong.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from sarcli.errors import SarcliError
from sarcli.threads import budget


@dataclass
class MapDriftResult:
    """Doppler rate (Hz/s) with its iteration history and the last drift (s)."""

    fr_hz_per_s: float
    iterations: int
    history: list[float]
    drift_s: float
    converged: bool


def _drift_lines(i1: np.ndarray, i2: np.ndarray) -> float:
    """Shift (lines, sub-sample) of intensity image i2 relative to i1 along axis 0, range-summed.

    The circular cross-correlation of the mean-removed columns, summed over range, is
    xc(l) = sum_k IFFT_m(B_k conj(A_k))(l) = IFFT(sum_k B_k conj(A_k))(l) (the transform is linear): one
    1-D inverse transform of the range-summed cross spectrum, with its DC bin zeroed (that is the mean
    removal). Real intensities: one-sided spectra (rfft), float64 sums."""
    n = i1.shape[0]
    cross = np.sum(sfft.rfft(i2, axis=0, workers=budget()) * np.conj(sfft.rfft(i1, axis=0, workers=budget())),
                   axis=1, dtype=np.complex128)
    cross[0] = 0.0
    xc = sfft.irfft(cross, n)
    k = int(np.argmax(xc))
    y0, y1, y2 = xc[(k - 1) % n], xc[k], xc[(k + 1) % n]
    den = y0 - 2 * y1 + y2
    d = 0.5 * (y0 - y2) / den if den != 0 else 0.0
    s = k + d
    return s - n if s > n / 2 else s


def _intensity(z: np.ndarray) -> np.ndarray:
    """|z|^2 of a complex64 array, float32."""
    return z.real * z.real + z.imag * z.imag


def _unit_phasor(turns: np.ndarray) -> np.ndarray:
    """exp(j 2 pi turns) in complex64. The phase in turns (float64) is first reduced to [-1/2, 1/2] in
    float64 (error ~|turns| 1e-16), so float32 holds it to half an ulp of 0.5 (1.5e-8 turns, 1e-7 rad)
    however many turns it had; 2 pi times it in float32 (<= 2e-7 rad) and float32 cos and sin (a few
    ulp) put each phasor within 5e-7 of exp(j 2 pi turns) (tested). numpy's complex64 exp is ~25x
    slower than the two float32 functions."""
    frac = turns - np.rint(turns)
    phase = frac.astype(np.float32)
    phase *= np.float32(2.0 * np.pi)
    out = np.empty(phase.shape, np.complex64)
    np.cos(phase, out=out.real)
    np.sin(phase, out=out.imag)
    return out


def map_drift(rc: np.ndarray, prf: float, wavelength: float, range_m: float, range_spacing_m: float,
              fdc_hz: float, fr0: float, look_fraction: float = 0.8, max_iter: int = 8,
              tol: float = 1e-4) -> MapDriftResult:
    """Doppler rate of the range-compressed segment ``rc`` (lines, samples) at slant range ``range_m``.

    ``fdc_hz`` absolute centroid; ``fr0`` starting rate (< 0); ``look_fraction`` of the PRF band used
    by the two looks (the band edges carry aliased energy).
    """
    if not (fr0 < 0 and np.isfinite(fr0)):
        raise SarcliError(f"map-drift needs a negative finite starting Doppler rate, got {fr0}")
    n_lines, n_rg = rc.shape
    if n_lines < 64:
        raise SarcliError(f"map-drift needs at least 64 azimuth lines, got {n_lines}")
    f_bb = sfft.fftfreq(n_lines, 1.0 / prf)
    f_abs = fdc_hz + (np.mod(f_bb - fdc_hz + 0.5 * prf, prf) - 0.5 * prf)  # Doppler of each bin
    df = f_abs - fdc_hz
    half = 0.5 * look_fraction * prf
    sel1 = (df >= -half) & (df < 0)
    sel2 = (df >= 0) & (df < half)
    S = sfft.fft(np.asarray(rc, np.complex64), axis=0, workers=budget())
    power = np.mean(np.abs(S) ** 2, axis=1)  # azimuth spectrum: the looks' energy-weighted centres
    f1, f2 = (float(np.sum(df[m] * power[m]) / np.sum(power[m])) for m in (sel1, sel2))
    S = sfft.fft(S, axis=1, workers=budget())  # 2-D spectrum (f_eta rows, f_range columns)
    k_rg = sfft.fftfreq(n_rg)  # cycles per sample
    fr = float(fr0)
    history = [fr]
    drift = np.nan
    converged = False
    iterations = 0
    for iterations in range(1, max_iter + 1):  # noqa: B007 (the count is reported)
        vr2 = -fr * wavelength * range_m / 2.0
        arg = 1.0 - (wavelength * f_abs / 2.0) ** 2 / vr2
        arg_c = 1.0 - (wavelength * fdc_hz / 2.0) ** 2 / vr2
        if np.any(arg <= 0) or arg_c <= 0:
            raise SarcliError("map-drift: Doppler band beyond the hyperbolic range model (check the "
                              "ambiguity and the starting rate)")
        shift = range_m * (1.0 / np.sqrt(arg) - 1.0 / np.sqrt(arg_c)) / range_spacing_m  # samples
        X = S * _unit_phasor(shift[:, None] * k_rg[None, :] + (0.5 * df**2 / fr)[:, None])
        X = sfft.ifft(X, axis=1, workers=budget(), overwrite_x=True)
        looks = [_intensity(sfft.ifft(np.where(sel[:, None], X, 0), axis=0, workers=budget(), overwrite_x=True))
                 for sel in (sel1, sel2)]
        drift = _drift_lines(looks[0], looks[1]) / prf
        new = 1.0 / (1.0 / fr + drift / (f2 - f1))
        history.append(new)
        rel = abs(new - fr) / abs(fr)
        fr = new
        if not (fr < 0 and np.isfinite(fr)):
            break
        if rel < tol:
            converged = True
            break
        last = np.array(history[-3:])
        if iterations >= 3 and np.ptp(last) < 10 * tol * abs(fr):  # oscillating on the speckle noise floor
            fr = float(last.mean())
            converged = True
            break
    return MapDriftResult(fr, iterations, history, float(drift), converged)
