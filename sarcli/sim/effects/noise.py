"""noise: circular complex white Gaussian thermal noise at a given raw-data SNR (seeded).

SNR = P_signal / P_noise with P_signal the mean power of channel 0 over the samples that hold
signal (|s| > 0) -- the single-look raw SNR of the illuminated echo; P_noise = E|n|^2 per complex
sample, the same in every channel. Alternatively ``noise_power`` sets P_noise absolutely.
The noise power used is recorded in /truth/noise_power.
"""

from dataclasses import dataclass

import numpy as np

from sarcli.errors import ConfigError, FormatError

NAME = "noise"
DOC = "thermal noise at snr_db (raw SNR of the illuminated samples) or at noise_power"
ORDER = 20


@dataclass(frozen=True)
class Options:
    """snr_db: raw SNR of the illuminated samples (dB); noise_power: E|n|^2 per complex sample. One of them."""

    snr_db: float | None = None
    noise_power: float | None = None


def parse(options, platform):
    if options is None or ((options.snr_db is None) == (options.noise_power is None)):
        raise ConfigError("effect noise needs a table [noise] with exactly one of snr_db or noise_power")
    if options.snr_db is not None:
        return ("snr_db", options.snr_db)
    if not options.noise_power > 0:
        raise ConfigError(f"noise.noise_power: must be > 0, got {options.noise_power!r}")
    return ("noise_power", options.noise_power)


def noise_power(echo: np.ndarray, params) -> float:
    kind, value = params
    if kind == "noise_power":
        return float(value)
    p = np.abs(echo) ** 2
    lit = p[p > 0]
    if lit.size == 0:
        raise FormatError("noise: the echo holds no signal, cannot set an SNR (give noise_power)")
    return float(lit.mean(dtype=np.float64) / 10.0 ** (value / 10.0))


def apply(ctx, params, product):
    pn = noise_power(product.echo, params)
    rng = ctx.rng("noise")
    sd = np.float32(np.sqrt(pn / 2.0))
    for arr in [product.echo] + ([] if product.echo_channels is None else list(product.echo_channels)):
        arr.real += rng.standard_normal(arr.shape, dtype=np.float32) * sd
        arr.imag += rng.standard_normal(arr.shape, dtype=np.float32) * sd
    product.truth["noise_power"] = np.float64(pn)
    product.radar.noise_power = float(pn)  # the receiver noise level the product states (radiometry)
