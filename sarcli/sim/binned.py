"""Fast clutter: scatterers splatted onto an oversampled delay grid, then one FFT convolution per line.

For many scatterers the exact kernel costs (pulses in beam) x (T fs samples) per scatterer; here each
scatterer costs (pulses in beam) x 2 grid updates, plus one FFT convolution per line and channel:

    grid[m] += a G exp(-j 4 pi R_c/lam) (1 - f) at m = floor(x), and f at m + 1,
    x = (2 R_env/c - ws) q fs + M  (delay bin at q times the sampling rate, M = floor(T q fs / 2)),
    out[n] = (grid * c_q)[q n + 2M],  c_q[j] = exp(j pi K (j/(q fs))^2) for |j| <= M,

with the chirp spectrum divided by sinc^2(nu) (nu = frequency / (q fs)) to undo the triangular
splatting kernel. The carrier phase of every scatterer and pulse is exact. Errors: the splat's
aliasing, sinc^2(1 - nu_max)/sinc^2(nu_max) with nu_max = B/(2 q fs) (-35 dB at q = 4, -48 dB at
q = 8 for B = 0.93 fs), and the rectangular pulse edges, which land on the q-grid instead of at the
exact sub-sample delay. Measured against the exact kernel (tests, benchmark): -31 dB (q = 4) and
-37 dB (q = 8) relative error energy, i.e. the edges dominate. Knob: [scene] clutter_oversampling
(default 4: speckle-level error, half the FFT cost of 8); clutter_model = "exact" sends clutter
through the exact kernel instead.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.fft

from sarcli.sim.kernel import splat_kernel

BLOCK_LINES = 256


def chirp_filter(radar, q: int, nfft: int) -> np.ndarray:
    """Spectrum (nfft bins) of the chirp c_q at q fs divided by the splat response sinc^2(nu)."""
    fq = q * radar.range_sampling_rate_hz
    m = int(math.floor(0.5 * radar.pulse_length_s * fq))
    j = np.arange(-m, m + 1)
    c = np.exp(1j * np.pi * radar.chirp_rate_hz_per_s * (j / fq) ** 2)
    return scipy.fft.fft(c, nfft) / np.sinc(scipy.fft.fftfreq(nfft)) ** 2


def add_binned_echo(out: np.ndarray, args: tuple, radar, q: int, block: int, tick=None) -> None:
    """Add the echoes of the targets in ``args`` (``stripmap.kernel_args`` layout) to ``out`` (n_ch, lines, n).

    ``tick(n)`` (optional) is called after each block of n lines. The grid is allocated at the FFT
    length (no padding copy) and held in complex64, like the FFTs: the method's own error (about
    -31 dB) is far above single precision."""
    n_ch, n_lines, n_s = out.shape
    fq = q * radar.range_sampling_rate_hz
    m = int(math.floor(0.5 * radar.pulse_length_s * fq))
    n_grid = q * (n_s - 1) + 2 * m + 2
    nfft = scipy.fft.next_fast_len(n_grid + 2 * m, real=False)
    spec = chirp_filter(radar, q, nfft).astype(np.complex64)
    x0 = radar.window_start_s * fq - m
    kargs = args[:14] + (fq, x0) + args[18:]
    pick = q * np.arange(n_s) + 2 * m
    for line0 in range(0, n_lines, BLOCK_LINES):
        nb = min(BLOCK_LINES, n_lines - line0)
        grid = np.zeros((n_ch, nb, nfft), np.complex64)
        splat_kernel(grid, line0, n_grid, *kargs, block)
        y = scipy.fft.fft(grid, axis=-1)
        y *= spec
        out[:, line0:line0 + nb, :] += scipy.fft.ifft(y, axis=-1)[..., pick]
        if tick is not None:
            tick(nb)
