"""Range compression filter (replica or nominal chirp, spectral window) and secondary range compression.

Timing convention (see ``/work/brief/notes/focus-to-sim-ceos-doppler.md``): the echo of a point at
one-way range R is a pulse centred at two-way time 2R/c, and the reference pulse (replica, or the
nominal chirp ``exp(+j pi K t^2)``, |t| <= T/2) has its centre at index (n-1)/2. The matched filter

    H(f) = conj( FFT(ref)(f) * exp(+j 2 pi f (n-1)/(2 fs)) ) * W(f / (a B)) / sum|ref|^2

(the linear phase moves the time origin to the pulse centre) therefore puts the compressed peak of
that point on the range sample of 2R/c, and a unit-amplitude chirp compresses to a peak of about 1.
``f`` is the signed FFT frequency (baseband chirp centred on 0 Hz), ``B = |K| T`` the chirp band
(clipped to fs), ``a`` <= 1 the processed fraction of it, W the window of :mod:`sarcli.focus.windows`.

Secondary range compression (Cumming & Wong eq. 6.22, option 3, derived in our notation): the exact
2-D spectrum of a range-compressed point has phase ``-(4 pi R0 / c) sqrt((f0 + f_tau)^2 - c^2 f_eta^2/(4V^2))``;
its second-order term in f_tau is ``+pi f_tau^2 / K_src`` with

    1 / K_src(R0, f_eta) = c R0 f_eta^2 / (2 V^2 f0^3 D^3(f_eta)),

so the SRC filter is ``exp(-j pi f_tau^2 / K_src(R_ref, f_eta))``, applied in the 2-D frequency domain
at the reference range R_ref (mid-swath); the residual at other ranges is a measured knob (bench).
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft
from numba import njit

from sarcli.errors import SarcliError
from sarcli.focus.windows import window
from sarcli.model.constants import C_LIGHT as C
from sarcli.model.raw import Radar
from sarcli.threads import fft_workers


def reference_pulse(radar: Radar, replica: np.ndarray | None = None) -> np.ndarray:
    """The reference pulse (complex128): the replica when given, else the nominal chirp.

    A replica longer than the pulse (round(T fs) samples) is a stored record whose pulse starts at
    index 0 and is followed by padding or receiver noise (CEOS, see ceos-to-focus note): only its
    first round(T fs) samples are the pulse.
    """
    if replica is not None and np.size(replica) > 1:
        ref = np.asarray(replica, np.complex128).ravel()
        n_eff = int(round(radar.pulse_length_s * radar.range_sampling_rate_hz))
        if 1 < n_eff < ref.size:
            ref = ref[:n_eff]
        if not np.all(np.isfinite(ref)) or not np.any(ref != 0):
            raise SarcliError("chirp replica is all zero or not finite: use the nominal chirp (--no-replica)")
        return ref
    fs = radar.range_sampling_rate_hz
    n = int(round(radar.pulse_length_s * fs))
    if n < 2:
        raise SarcliError(f"pulse length {radar.pulse_length_s} s is shorter than two range samples")
    t = (np.arange(n) - 0.5 * (n - 1)) / fs
    return np.exp(1j * np.pi * radar.chirp_rate_hz_per_s * t * t)


def chirp_band(radar: Radar) -> float:
    """Processed range bandwidth B = |K| T, clipped to the sampling rate (Hz)."""
    return min(abs(radar.chirp_rate_hz_per_s) * radar.pulse_length_s, radar.range_sampling_rate_hz)


def range_filter(radar: Radar, n_fft: int, window_spec: str, replica: np.ndarray | None = None,
                 band_fraction: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(H, f_tau): matched filter spectrum (complex128, length n_fft) and the signed frequencies (Hz).

    ``band_fraction`` < 1 processes only the central part of the chirp band (the window spans
    band_fraction * B): it trades resolution for freedom from the Fresnel ripple at the band edges.
    """
    if not 0.0 < band_fraction <= 1.0:
        raise SarcliError(f"range band fraction must be in (0, 1], got {band_fraction}")
    ref = reference_pulse(radar, replica)
    fs = radar.range_sampling_rate_hz
    if ref.size > n_fft:
        raise SarcliError(f"FFT length {n_fft} is shorter than the reference pulse ({ref.size} samples)")
    f = np.fft.fftfreq(n_fft, 1.0 / fs)
    spec = np.fft.fft(ref, n_fft) * np.exp(2j * np.pi * f * 0.5 * (ref.size - 1) / fs)
    h = np.conj(spec) * window(window_spec, f / (band_fraction * chirp_band(radar))) / np.sum(np.abs(ref) ** 2)
    return h, f


def compress_lines(lines: np.ndarray, h: np.ndarray, n_out: int, workers: int = -1) -> np.ndarray:
    """Range-compress ``lines`` (n, n_samples) with the filter ``h`` (length n_fft): (n, n_out) in h's dtype.

    Linear convolution (n_fft >= n_samples + n_ref - 1); out-of-place, then the range FFT and IFFT in place.
    """
    x = np.zeros((lines.shape[0], h.size), h.dtype)
    x[:, :lines.shape[1]] = lines
    x = sfft.fft(x, axis=1, overwrite_x=True, workers=fft_workers(workers))
    x *= h[None, :]
    x = sfft.ifft(x, axis=1, overwrite_x=True, workers=fft_workers(workers))
    return x[:, :n_out]


def range_compress(echo: np.ndarray, radar: Radar, replica: np.ndarray | None = None, window: str = "rect",
                   workers: int = -1) -> np.ndarray:
    """Range-compressed echo (complex64, same shape): sample k holds the target at the two-way time of
    sample k (the slant range of the raw product's sample k)."""
    echo = np.asarray(echo)
    n_ref = reference_pulse(radar, replica).size
    h, _ = range_filter(radar, sfft.next_fast_len(echo.shape[1] + n_ref - 1), window, replica)
    return compress_lines(echo, h.astype(np.complex64), echo.shape[1], workers)


def inverse_src_rate(f_eta_hz: np.ndarray, r_ref_m: float, v_mps: float, carrier_hz: float) -> np.ndarray:
    """1 / K_src(R_ref, f_eta) (s^2), see the module docstring."""
    lam = C / carrier_hz
    d2 = 1.0 - (lam * np.asarray(f_eta_hz) / (2.0 * v_mps)) ** 2
    return C * r_ref_m * np.asarray(f_eta_hz) ** 2 / (2.0 * v_mps**2 * carrier_hz**3 * d2**1.5)


@njit(nogil=True, cache=True, fastmath=True)
def apply_range_filter_2d(x, h, f_tau, inv_ksrc, out):
    """out[k, j(m)] = x[k, m] * h[m] * exp(-j pi f_tau[m]^2 inv_ksrc[k]) (2-D spectrum, azimuth rows k).

    ``out`` has n_out >= n_f columns: the positive-frequency half m < (n_f + 1) // 2 keeps its column,
    the negative half moves to the end (j = m + n_out - n_f) and the columns between are zeroed, i.e.
    Fourier zero padding: the IFFT of ``out`` is the filtered row interpolated on an n_out / n_f finer
    grid. ``out`` may be ``x`` when n_out == n_f (in place). Serial and GIL-free (the RDA calls it per
    chunk of rows from a thread pool).
    The phase is quadratic in m on each half of the FFT frequency axis (f_tau linear there), so the
    phasor is advanced by a second-order recurrence (two complex multiplies per sample instead of a
    sine and cosine), restarted exactly every 64 samples: drift below 1e-12 rad.
    """
    na, nf = x.shape
    half = (nf + 1) // 2
    gap = out.shape[1] - nf
    for k in range(na):
        for q in range(half, half + gap):
            out[k, q] = 0.0
        a = -np.pi * inv_ksrc[k]
        m = 0
        while m < nf:
            e = min(nf, m + 64)
            ph0 = a * f_tau[m] * f_tau[m]
            cur = complex(np.cos(ph0), np.sin(ph0))
            if e - m > 2 and f_tau[m] < f_tau[e - 1]:
                df = f_tau[m + 1] - f_tau[m]
                d1 = a * (2.0 * f_tau[m] * df + df * df)  # phase step m -> m+1
                step = complex(np.cos(d1), np.sin(d1))
                d2 = 2.0 * a * df * df  # its increment per sample
                curv = complex(np.cos(d2), np.sin(d2))
                for q in range(m, e):
                    out[k, q if q < half else q + gap] = x[k, q] * (h[q] * cur)
                    cur *= step
                    step *= curv
            else:
                for q in range(m, e):
                    ph = a * f_tau[q] * f_tau[q]
                    out[k, q if q < half else q + gap] = x[k, q] * (h[q] * complex(np.cos(ph), np.sin(ph)))
            m = e


def apply_range_filter_2d_numpy(x: np.ndarray, h: np.ndarray, f_tau: np.ndarray, inv_ksrc: np.ndarray,
                                n_out: int) -> np.ndarray:
    """Plain-numpy reference of :func:`apply_range_filter_2d` (returns the n_out-column array)."""
    y = x * (h[None, :] * np.exp(-1j * np.pi * inv_ksrc[:, None] * f_tau[None, :] ** 2))
    half = (x.shape[1] + 1) // 2
    return np.concatenate([y[:, :half], np.zeros((x.shape[0], n_out - x.shape[1]), y.dtype), y[:, half:]], axis=1)
