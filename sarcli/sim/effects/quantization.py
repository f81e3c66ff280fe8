"""quantization: n-bit I/Q quantization behind a per-line AGC, like Radarsat-1 (4-bit, odd levels).

Stored samples are odd integer levels -(2^b-1) .. (2^b-1) (4-bit code s -> 2s+1), as complex64.
Model per line k (x the complex echo, G a fixed receiver gain, A_k the integer AGC attenuation):

    u = x * G * 10^(-A_k/20),  q(u) = clip(2*floor(u/2) + 1, -(2^b-1), 2^b-1)  on I and Q,
    A_k = clip(round(20*log10(G * sigma_k / target_rms)), 0, 63),  sigma_k = RMS of I/Q of line k.

So ``line * 10**(agc_db/20) / G`` undoes the AGC (G in /truth/receiver_gain_db). G is chosen once
per scene so that the median lit line needs ``agc_center_db`` (default 10 dB) of attenuation.
``target_rms`` (per component, default 0.373*2^b, Max's optimum loading for a 4-bit Gaussian
quantizer) sets the loading. The replica, if stored, is quantized at the same loading.
"""

from dataclasses import dataclass

import numpy as np

from sarcli.errors import ConfigError

NAME = "quantization"
DOC = "n-bit I/Q quantization with integer-dB AGC per line (4-bit odd levels like Radarsat-1)"
ORDER = 30


@dataclass(frozen=True)
class Options:
    """bits: 2..8; target_rms: loading per component (default 0.373 * 2^bits); agc_center_db: AGC of the
    median lit line (dB)."""

    bits: int = 4
    target_rms: float | None = None
    agc_center_db: float = 10.0


def parse(options, platform):
    o = options or Options()
    if not 2 <= o.bits <= 8:
        raise ConfigError(f"quantization.bits: must be 2..8, got {o.bits}")
    if o.target_rms is not None and not o.target_rms > 0:
        raise ConfigError(f"quantization.target_rms: must be > 0, got {o.target_rms!r}")
    return o.bits, (0.373 * 2**o.bits if o.target_rms is None else o.target_rms), o.agc_center_db


def quantize(u: np.ndarray, bits: int) -> np.ndarray:
    """Uniform mid-rise quantizer with odd integer levels (step 2), I and Q separately -> complex64."""
    top = 2**bits - 1

    def q(a):
        return np.clip(2 * np.floor(a * np.float32(0.5)) + 1, -top, top)

    return (q(u.real) + 1j * q(u.imag)).astype(np.complex64)


def line_rms(x: np.ndarray) -> np.ndarray:
    """RMS per component of each line (axis -1), float64."""
    return np.sqrt(np.mean(np.abs(x.astype(np.complex128)) ** 2, axis=-1) / 2.0)


def agc_db(sigma: np.ndarray, gain: float, target_rms: float) -> np.ndarray:
    with np.errstate(divide="ignore"):
        a = np.round(20.0 * np.log10(gain * sigma / target_rms))
    return np.clip(np.nan_to_num(a, nan=0.0, neginf=0.0), 0, 63)


def apply(ctx, params, product):
    bits, rms, center = params
    sigma = line_rms(product.echo)
    lit = sigma[sigma > 0]
    g_db = float(np.round(center - 20.0 * np.log10(np.median(lit) / rms))) if lit.size else 0.0
    gain = 10.0 ** (g_db / 20.0)
    a = agc_db(sigma, gain, rms)
    scale = (gain * 10.0 ** (-a / 20.0)).astype(np.float32)[:, None]  # float32: no complex128 temporaries
    product.echo = quantize(product.echo * scale, bits)
    if product.echo_channels is not None:
        product.echo_channels = quantize(product.echo_channels * scale[None], bits)
    if product.replica is not None:
        product.replica = quantize(product.replica * (rms * np.sqrt(2.0)), bits)
    product.agc_db = a.astype(np.float32)
    product.radar.quantization_bits = bits
    # the stated thermal noise, through the receiver gain G (the focuser undoes the AGC, not G); the
    # quantization noise is not in it
    if getattr(product.radar, "noise_power", None) is not None:
        product.radar.noise_power *= gain**2
    product.truth["receiver_gain_db"] = np.float64(g_db)
