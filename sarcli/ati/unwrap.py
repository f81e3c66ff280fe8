"""Phase unwrapping of a mover's slow-time signal ([Ryu2017, Fig. 2], step 5), two methods as a knob.

``itoh``    the textbook 1-D unwrap (numpy.unwrap): add 2*pi wherever consecutive samples jump by
            more than pi. Exact when the noise-free phase changes by < pi per sample and the noise is
            small; one noise spike beyond pi anywhere corrupts everything after it (low SNR).
``dechirp`` model-guided: find the dominant linear-FM component (lag-product FFT for a coarse
            rate, then a fine grid of dechirp+FFT trials; the peak gives rate and frequency),
            remove it, unwrap a moving average of the slowly varying residual, put every sample on
            the nearest cycle, add the model back. Robust at low SNR because the averaged residual
            changes little from sample to sample; costs ~34 FFTs.

Both return the unwrapped phase (rad, float64) of ``s`` sample by sample; the absolute 2*pi offset
is arbitrary (only differences carry range information).
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError

METHODS = ("itoh", "dechirp")


def unwrap_itoh(s: np.ndarray) -> np.ndarray:
    """Itoh's method on the phase of complex samples ``s``."""
    return np.unwrap(np.angle(np.asarray(s, dtype=np.complex128)))


def _peak_freq(x: np.ndarray, dt: float, pad: int = 4) -> tuple[float, float]:
    """(frequency Hz, magnitude) of the largest zero-padded FFT bin of ``x``."""
    nfft = 1 << int(np.ceil(np.log2(pad * x.size)))
    spec = np.abs(np.fft.fft(x, nfft))
    i = int(np.argmax(spec))
    return float(np.fft.fftfreq(nfft, dt)[i]), float(spec[i])


def dominant_chirp(s: np.ndarray, t: np.ndarray) -> tuple[float, float]:
    """(chirp rate k in Hz/s, frequency f in Hz at t = t[0]) of the strongest LFM term.

    Model: ``s ~ exp(j*2*pi*(f*(t-t0) + k*(t-t0)**2/2))``. Coarse rate from the lag product
    ``s[n+L]*conj(s[n])`` (a tone at k*L*dt, L = n/2; resolution 2/T^2), then a fine dechirp
    search (step 1/(4*T^2), +-4/T^2): each trial is dechirped and FFT'd, the largest peak wins.
    """
    s = np.asarray(s, dtype=np.complex128)
    tt = np.asarray(t, dtype=np.float64) - t[0]
    n = s.size
    if n < 4:
        raise SarcliError("chirp estimation needs at least 4 samples")
    dt = float((tt[-1] - tt[0]) / (n - 1))
    dur = n * dt
    lag = n // 2
    f_lag, _ = _peak_freq(s[lag:] * np.conj(s[:n - lag]), dt)
    k0 = f_lag / (lag * dt)
    best = (-1.0, k0, 0.0)
    for k in k0 + np.arange(-16, 17) * 0.25 / dur ** 2:
        f, mag = _peak_freq(s * np.exp(-1j * np.pi * k * tt * tt), dt)
        if mag > best[0]:
            best = (mag, float(k), f)
    return best[1], best[2]


def chirp_phase(t: np.ndarray, chirp: tuple[float, float]) -> np.ndarray:
    """Phase (rad) of the LFM term ``(k, f)`` of :func:`dominant_chirp` at times ``t``."""
    k, f = chirp
    tt = np.asarray(t, dtype=np.float64) - t[0]
    return 2.0 * np.pi * (f * tt + 0.5 * k * tt * tt)


def unwrap_slow(z: np.ndarray, smooth: int = 31) -> np.ndarray:
    """Unwrap a slowly varying phase: Itoh on a ``smooth``-sample moving average of ``z`` (noise
    down by sqrt(smooth)), then every raw sample on the cycle nearest that smooth phase."""
    z = np.asarray(z, dtype=np.complex128)
    m = max(1, min(int(smooth), z.size // 4))
    slow = np.unwrap(np.angle(np.convolve(z, np.ones(m), mode="same")))
    return slow + np.angle(z * np.exp(-1j * slow))


def unwrap_dechirp(s: np.ndarray, t: np.ndarray, chirp: tuple[float, float]) -> np.ndarray:
    """Model-guided unwrapping: remove the LFM term ``chirp``, :func:`unwrap_slow` the residual,
    add the model back."""
    model = chirp_phase(t, chirp)
    return unwrap_slow(np.asarray(s, dtype=np.complex128) * np.exp(-1j * model)) + model


def unwrap(s: np.ndarray, t: np.ndarray, method: str = "dechirp",
           chirp: tuple[float, float] | None = None) -> np.ndarray:
    """Unwrap the phase of ``s`` (samples at times ``t``) with ``method`` in :data:`METHODS`.

    ``dechirp`` needs the dominant LFM term ``chirp = (k, f)`` from :func:`dominant_chirp`.
    """
    if method == "itoh":
        return unwrap_itoh(s)
    if method == "dechirp":
        if chirp is None:
            raise SarcliError("dechirp unwrapping needs the dominant chirp (rate, frequency)")
        return unwrap_dechirp(s, t, chirp)
    raise SarcliError(f"unknown unwrapping method {method!r}; choose one of {', '.join(METHODS)}")
