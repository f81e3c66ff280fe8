"""chirp_replica: store the transmitted chirp replica in /radar/replica.

replica[n] = exp(+j*pi*K*t_n^2), t_n = (n - (N-1)/2)/fs, N = round(T*fs): the pulse centred on
its reference time, the same waveform the echo kernel uses. Quantized too if quantization is listed.
"""

import numpy as np

from sarcli.sim.effects import no_parameters

NAME = "chirp_replica"
DOC = "store the chirp replica in the product"
ORDER = 10

parse = no_parameters


def replica(radar) -> np.ndarray:
    """The chirp sampled at the range sampling rate, centred (complex128)."""
    n = max(1, round(radar.pulse_length_s * radar.range_sampling_rate_hz))
    t = (np.arange(n) - (n - 1) / 2.0) / radar.range_sampling_rate_hz
    return np.exp(1j * np.pi * radar.chirp_rate_hz_per_s * t * t)


def apply(ctx, params, product):
    product.replica = replica(ctx.scene.radar).astype(np.complex64)
