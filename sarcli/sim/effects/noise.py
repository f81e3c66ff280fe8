"""noise: circular complex white Gaussian thermal noise at a given raw-data SNR (seeded).

SNR = P_signal / P_noise with P_signal the mean power of channel 0 over the samples that hold
signal (|s| > 0) -- the single-look raw SNR of the illuminated echo; P_noise = E|n|^2 per complex
sample, the same in every channel. Alternatively ``noise_power`` sets P_noise absolutely.
The noise power used is recorded in /truth/noise_power.
"""

import numpy as np

from sarcli.errors import FormatError

NAME = "noise"
DOC = "thermal noise at snr_db (raw SNR of the illuminated samples) or at noise_power"
ORDER = 20


def parse(table, platform):
    if table is None or (table.has("snr_db") == table.has("noise_power")):
        raise FormatError("effect noise needs a table [noise] with exactly one of snr_db or noise_power")
    if table.has("snr_db"):
        return ("snr_db", table.num("snr_db"))
    return ("noise_power", table.num("noise_power", positive=True))


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
