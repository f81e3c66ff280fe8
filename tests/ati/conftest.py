"""Plain-numpy synthesis of two-channel slow-time signals from the exact (bistatic) range history.

Independent of sarcli.ati: the geometry is written out here from the seed's Fig. 1 (target on the
ground, platform at height H along +y), one transmitter on the platform, receiver 0 on it, receiver 1
``d`` ahead along-track; receiver-1 samples co-registered by d/(2*Vp).
"""

from __future__ import annotations

import numpy as np
import pytest

C = 299792458.0
PAPER = {"f0": 1e9, "prf": 3000.0, "cpi": 0.6, "d": 2.0, "H": 10e3, "Vp": 2000.0,
         "x0": 5095.3, "y0": 500.0, "vx": 10.0, "vy": 50.0}


def _rng(x0, y0, vx, vy, eta, H, Vp, dy=0.0):
    return np.sqrt((x0 + vx * eta) ** 2 + (y0 + (vy - Vp) * eta - dy) ** 2 + H ** 2)


def synth_slowtime(x0=5095.3, y0=500.0, vx=10.0, vy=50.0, H=10e3, Vp=2000.0, f0=1e9, d=2.0,
                   prf=3000.0, cpi=0.6, snr_db=40.0, seed=0, t0=0.0, gate=None, amp=1.0):
    """(eta, s0, s1, r_min): per-sample SNR ``snr_db`` (signal amplitude ``amp``, unit noise scale)."""
    lam = C / f0
    eta = t0 + np.arange(int(round(cpi * prf))) / prf
    r = _rng(x0, y0, vx, vy, eta, H, Vp)
    e = eta - 0.5 * d / Vp
    r1 = 0.5 * (_rng(x0, y0, vx, vy, e, H, Vp) + _rng(x0, y0, vx, vy, e, H, Vp, dy=d))
    a = amp * np.ones_like(eta) if gate is None else amp * gate(eta)
    rng = np.random.default_rng(seed)
    sig = 10 ** (-snr_db / 20) * amp

    def noise():
        return sig * (rng.standard_normal(eta.size) + 1j * rng.standard_normal(eta.size)) / np.sqrt(2)

    s0 = a * np.exp(-4j * np.pi * r / lam + 0.7j) + noise()
    s1 = a * np.exp(-4j * np.pi * r1 / lam + 0.7j) + noise()
    # closest approach of the (infinite) straight-line trajectory, by brute force on a fine grid
    tt = np.linspace(-5, 5, 200001)
    r_min = float(_rng(x0, y0, vx, vy, tt, H, Vp).min())
    return eta, s0, s1, r_min


@pytest.fixture
def synth():
    return synth_slowtime


@pytest.fixture
def paper():
    return dict(PAPER)
