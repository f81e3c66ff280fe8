"""Plain-numpy synthetic signals with a known Doppler centroid / rate for the Doppler tests.

Independent of sarcli: everything here is written from the signal model, not from the estimators.
"""

from __future__ import annotations

import numpy as np

C = 299792458.0


def azimuth_process(n_lines: int, n_cols: int, prf: float, fdc: float, bw: float, rng: np.random.Generator,
                    snr_db: float | None = None) -> np.ndarray:
    """Stationary complex Gaussian azimuth signal, Gaussian power spectrum of rms width ``bw`` (Hz)
    centred (on the PRF circle) at ``fdc``; optional white noise at ``snr_db``. complex64 (lines, cols).

    The lag-1 correlation of such a process has phase exactly 2*pi*fdc/PRF (symmetric spectrum)."""
    f = np.fft.fftfreq(n_lines, 1.0 / prf)
    d = np.mod(f - fdc + prf / 2, prf) - prf / 2
    amp = np.exp(-0.25 * (d / bw) ** 2)  # power ~ exp(-d^2 / (2 bw^2))
    w = rng.standard_normal((n_lines, n_cols)) + 1j * rng.standard_normal((n_lines, n_cols))
    x = np.fft.ifft(np.fft.fft(w, axis=0) * amp[:, None], axis=0)
    x /= np.sqrt(np.mean(np.abs(x) ** 2))
    if snr_db is not None:
        s = 10 ** (-snr_db / 20) / np.sqrt(2)
        x = x + s * (rng.standard_normal(x.shape) + 1j * rng.standard_normal(x.shape))
    return x.astype(np.complex64)


def quantize_4bit(x: np.ndarray, gain: float) -> np.ndarray:
    """Radarsat-1 style 4-bit quantizer: odd levels -15..15 on I and Q (clipped = saturated)."""
    def q(a):
        return np.clip(2 * np.floor(a * gain / 2) + 1, -15, 15)
    return (q(x.real) + 1j * q(x.imag)).astype(np.complex64)


def point_target_raw(n_lines: int, n_samples: int, prf: float, fs: float, f0: float, K: float, Tp: float,
                     fdc: float, fr: float, n_targets: int, rng: np.random.Generator,
                     beam_s: float = 0.3, r0: float = 850e3) -> np.ndarray:
    """Raw echoes of random point targets with range history
    R(eta) = Rc - (lam/2) fdc (eta - eta_c) - (lam/4) fr (eta - eta_c)^2 around each target's beam-centre
    time eta_c, Gaussian azimuth beam of rms ``beam_s`` seconds, pulse centred at 2R/c with phase
    exp(+j pi K (tau - 2R/c)^2) exp(-j 4 pi R / lam) (the project's convention)."""
    lam = C / f0
    eta = np.arange(n_lines) / prf
    tau = 2 * r0 / C + np.arange(n_samples) / fs
    out = np.zeros((n_lines, n_samples), np.complex128)
    margin = Tp / 2 * C / 2
    for _ in range(n_targets):
        ec = rng.uniform(eta[0], eta[-1])
        rc = r0 + rng.uniform(margin, n_samples / fs * C / 2 - margin)
        a = rng.standard_normal() + 1j * rng.standard_normal()
        de = eta - ec
        wa = np.exp(-0.5 * (de / beam_s) ** 2)
        use = wa > 1e-3
        R = rc - 0.5 * lam * fdc * de[use] - 0.25 * lam * fr * de[use] ** 2
        k0 = max(int(np.floor(((2 * R.min() / C - Tp / 2) - tau[0]) * fs)), 0)
        k1 = min(int(np.ceil(((2 * R.max() / C + Tp / 2) - tau[0]) * fs)) + 1, n_samples)
        t = tau[None, k0:k1] - 2 * R[:, None] / C
        pulse = (np.abs(t) <= Tp / 2) * np.exp(1j * np.pi * K * t * t)
        out[use, k0:k1] += a * wa[use, None] * pulse * np.exp(-4j * np.pi * R / lam)[:, None]
    return out.astype(np.complex64)
