"""Range compression of a GB-SAR scan ([LeeGBSAR-II-2007, eq. 1-3, Fig. 1]): window, zero-pad, inverse FFT.

For a sweep ``f_k = f_c + (k - k_c) df`` (k = 0..N_R-1, ``k_c = (N_R-1)/2``) the profile at range r is

    P(r) = sum_k w_k S21_k exp(+j*4*pi*(f_k - f_c)*r/c) / sum_k w_k

A scatterer at range R (S21_k = a exp(-j 4 pi f_k R/c)) gives ``P(r) = a exp(-j 4 pi f_c R/c) W(R - r)``
with W real, symmetric and W(0) = 1: the profile is baseband in r (it can be interpolated) and its
phase at the peak is the paper's ``-4 pi R/lam``. On the bins ``r_n = n c/(2 N df)`` of an
``N``-point inverse FFT, ``exp(j 4 pi (k - k_c) df r_n / c) = exp(j 2 pi (k - k_c) n / N)``, so P is
the IFFT of the windowed sweep times ``exp(-j 2 pi k_c n/N)``. Only ``r <= R_max = c/(4 df)`` is kept
(the paper's positive-time half; a scatterer beyond R_max appears at ``r - c/(2 df)``, i.e. it
wraps). Stops flagged in the scan or holding any NaN are zeroed and given weight 0 (reported).

In a medium of relative permittivity eps (a ground-penetrating rail scan) the waves travel at
``v = c/sqrt(eps)`` and a scatterer at geometric range R gives ``S21_k = a exp(-j 4 pi f_k R/v)``
[Daniels2004, ch. 2]: every formula above holds with c replaced by v, so the profile's bins are
``v/(2 N df)`` geometric metres in the medium, R_max = v/(4 df), and lam = v/f_c.
A sweep referenced to a range r_ref (``S21_k = a exp(-j 4 pi f_k (R - r_ref)/v)``, de-ramped phase
histories) compresses to ``P(r) = a exp(-j 4 pi (R - r_ref)/lam) W(R - r_ref - r)``: the same profile
in the relative range r = R - r_ref, which is negative as often as positive; ``centred=True`` keeps the
bins ``(n - N/2) dr``, n = 0..N-1, i.e. [-R_max, R_max) (the IFFT index n - N/2 taken modulo N, with
the baseband factor ``exp(-j 2 pi k_c (n - N/2)/N)`` of its own relative range).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft

from sarcli.errors import SarcliError
from sarcli.gbsar.system import next_pow2
from sarcli.gbsar.windows import taper
from sarcli.model.constants import C_LIGHT
from sarcli.model.gbsar import Scan


@dataclass
class RangeProfiles:
    """Range-compressed stops: ``data`` (n_stops, n_r) complex64 on ranges ``first_range_m + n * dr``
    (n = 0..n_r-1), geometric metres in a medium where waves travel at ``wave_speed_m_s``."""

    data: np.ndarray
    dr_m: float
    center_frequency_hz: float
    frequency_step_hz: float
    n_freq: int
    positions_m: np.ndarray
    heights_m: np.ndarray
    weights: np.ndarray  # (n_stops,) 1 = valid stop, 0 = skipped
    skipped: list[int]
    first_range_m: float = 0.0
    wave_speed_m_s: float = C_LIGHT

    @property
    def ranges_m(self) -> np.ndarray:
        return self.first_range_m + np.arange(self.data.shape[1]) * self.dr_m

    @property
    def wavelength_m(self) -> float:
        return self.wave_speed_m_s / self.center_frequency_hz

    @property
    def r_max_m(self) -> float:
        return self.wave_speed_m_s / (4 * self.frequency_step_hz)


def check_sweep(frequency: np.ndarray) -> float:
    """Frequency step of a uniform sweep; one-line errors for a single frequency or uneven steps."""
    f = np.asarray(frequency, np.float64)
    if f.size < 2:
        raise SarcliError("a single-frequency scan has no range resolution; focusing needs >= 2 frequencies")
    d = np.diff(f)
    if not np.all(np.abs(d - d[0]) <= 1e-6 * abs(d[0])):
        raise SarcliError("the frequency sweep is not uniformly spaced; range compression needs a uniform sweep")
    return float((f[-1] - f[0]) / (f.size - 1))


def wave_speed(permittivity: float) -> float:
    """Speed of light in a medium of relative permittivity ``eps`` >= 1: ``c / sqrt(eps)`` (m/s)."""
    if not (math.isfinite(permittivity) and permittivity >= 1.0):
        raise SarcliError(f"the relative permittivity must be a finite number >= 1, got {permittivity:g}")
    return C_LIGHT / math.sqrt(permittivity)


def range_compress(scan: Scan, pol: str, window_name: str = "hamming", oversample: int = 1,
                   max_range_m: float | None = None, permittivity: float = 1.0,
                   centred: bool = False) -> RangeProfiles:
    """Range-compress one polarization: N = oversample * 2^ceil(log2 N_R) FFT bins (N_Rfft of Table 1
    for oversample = 1), ranges up to ``min(max_range_m, R_max)`` (or, ``centred``, all N bins on
    [-R_max, R_max), ``max_range_m`` unused); ``window_name`` is a taper spec
    (:mod:`sarcli.gbsar.windows`) over the frequencies; ``permittivity`` of the medium (module docstring)."""
    if oversample < 1:
        raise SarcliError("range oversampling must be >= 1")
    df = check_sweep(scan.frequency)
    v = wave_speed(permittivity)
    s = np.asarray(scan.pol(pol))
    n_stops, n_r = s.shape
    flags = np.asarray(scan.stop_flags if scan.stop_flags is not None else np.zeros(n_stops), np.uint8)
    bad = (flags != 0) | ~np.all(np.isfinite(s), axis=1)
    n_fft = next_pow2(n_r) * int(oversample)
    dr = v / (2 * n_fft * df)
    w = taper(window_name, n_r)
    x = s.astype(np.complex64) * (w / w.sum()).astype(np.float32)[None, :]  # complex64: the data's precision
    x[bad] = 0.0
    p = scipy.fft.ifft(x, n=n_fft, axis=1)
    if centred:
        m = np.arange(n_fft) - n_fft // 2  # bin n holds the relative range m dr, m = n - N/2
        p = np.fft.fftshift(p, axes=1)
    else:
        r_top = v / (4 * df) if max_range_m is None else min(float(max_range_m), v / (4 * df))
        m = np.arange(min(int(np.floor(r_top / dr + 1e-9)) + 1, n_fft // 2 + 1))
        p = p[:, :m.size]
    kc = (n_r - 1) / 2
    p *= (n_fft * np.exp(-2j * np.pi * kc * m / n_fft)).astype(np.complex64)[None, :]
    fc = 0.5 * (scan.frequency[0] + scan.frequency[-1])
    return RangeProfiles(data=np.ascontiguousarray(p), dr_m=dr, center_frequency_hz=float(fc),
                         frequency_step_hz=df, n_freq=n_r, positions_m=np.asarray(scan.rail_position, np.float64),
                         heights_m=np.asarray(scan.rail_height, np.float64), weights=(~bad).astype(np.float64),
                         skipped=[int(i) for i in np.flatnonzero(bad)], first_range_m=float(m[0] * dr),
                         wave_speed_m_s=v)


def stop_weights(prof: RangeProfiles, azimuth_window: str) -> np.ndarray:
    """Azimuth taper over the rail stops times stop validity (float64, n_stops)."""
    return taper(azimuth_window, prof.positions_m.size) * prof.weights
