"""Quantization statistics against theory for Gaussian input (4-bit odd levels, AGC per line)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.stats import norm

from sarcli.sim.effects import quantization as Q


def _theory(s: float, bits: int):
    """E[q^2] and E[u q] per component for u ~ N(0, s^2) through the odd-level quantizer."""
    top = 2**bits - 1
    levels = np.arange(-top, top + 1, 2.0)
    lo = np.concatenate([[-np.inf], levels[1:] - 1.0])
    hi = np.concatenate([levels[:-1] + 1.0, [np.inf]])
    p = norm.cdf(hi / s) - norm.cdf(lo / s)
    euq = np.sum(levels * s * (norm.pdf(lo / s) - norm.pdf(hi / s)))
    return np.sum(levels**2 * p), euq


@pytest.mark.parametrize("bits", [2, 4, 6])
def test_levels_agc_and_power_match_theory(bits):
    rng = np.random.default_rng(1)
    n_lines, n = 64, 20000
    sigma = 10 ** (np.linspace(-1.0, 1.0, n_lines))[:, None]  # 40 dB of line-power variation
    x = (rng.standard_normal((n_lines, n)) + 1j * rng.standard_normal((n_lines, n))) * sigma
    prod = SimpleNamespace(echo=x.astype(np.complex64), echo_channels=None, replica=None, agc_db=None,
                           radar=SimpleNamespace(quantization_bits=0), truth={})
    params = Q.parse(None, None) if bits == 4 else (bits, 0.373 * 2**bits, 10.0)
    Q.apply(None, params, prod)
    q, agc, g_db = prod.echo, prod.agc_db, prod.truth["receiver_gain_db"]
    top = 2**bits - 1
    assert prod.radar.quantization_bits == bits and q.dtype == np.complex64
    vals = np.unique(np.concatenate([q.real.ravel(), q.imag.ravel()]))
    assert np.all(vals % 2 == 1) and vals.min() >= -top and vals.max() <= top
    assert np.all(agc == np.round(agc)) and agc.min() >= 0 and agc.max() <= 63
    rms = np.sqrt(np.mean(np.abs(x) ** 2, axis=1) / 2)  # measured per-component RMS of each input line
    s = rms * 10 ** (g_db / 20) * 10 ** (-agc / 20)  # ... at the quantizer input
    free = (agc > 0) & (agc < 63)
    assert free.sum() > n_lines // 2
    assert np.all(np.abs(20 * np.log10(s[free] / params[1])) <= 0.5 + 1e-3)  # AGC keeps the loading
    for k in np.flatnonzero(free)[::7]:
        eq2, euq = _theory(s[k], bits)
        meas = np.mean(q[k].real.astype(float) ** 2)
        assert abs(meas / eq2 - 1) < 0.03
        u = (x[k] * 10 ** (g_db / 20) * 10 ** (-agc[k] / 20)).real
        assert abs(np.mean(u * q[k].real) / euq - 1) < 0.03
    # undoing the AGC restores the line power within the quantizer's gain error
    undone = q * (10 ** (agc / 20) / 10 ** (g_db / 20))[:, None]
    ratio = np.mean(np.abs(undone) ** 2, axis=1) / (2 * sigma[:, 0] ** 2)
    assert np.all(np.abs(10 * np.log10(ratio[free])) < 1.0)


def test_quantizer_boundaries():
    u = np.array([-100.0, -2.0, -0.1, 0.0, 0.1, 1.99, 2.0, 13.9, 14.0, 100.0])
    out = Q.quantize(u + 0j, 4).real
    assert out.tolist() == [-15, -1, -1, 1, 1, 1, 3, 13, 15, 15]
