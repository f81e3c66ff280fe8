"""Plain-numpy synthesis of two-channel slow-time signals from the exact (bistatic) range history.

Independent of sarcli.ati: the geometry is written out here from [Ryu2017, Fig. 1] (target on the
ground, platform at height H along +y), one transmitter on the platform, receiver 0 on it, receiver 1
``d`` ahead along-track; receiver-1 samples co-registered by d/(2*Vp).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

C = 299792458.0
PAPER = {"f0": 1e9, "prf": 3000.0, "cpi": 0.6, "d": 2.0, "H": 10e3, "Vp": 2000.0,
         "x0": 5095.3, "y0": 500.0, "vx": 10.0, "vy": 50.0}


def _rng(x0, y0, vx, vy, eta, H, Vp, dy=0.0):
    return np.sqrt((x0 + vx * eta) ** 2 + (y0 + (vy - Vp) * eta - dy) ** 2 + H ** 2)


def synth_slowtime(x0=5095.3, y0=500.0, vx=10.0, vy=50.0, H=10e3, Vp=2000.0, f0=1e9, d=2.0,
                   prf=3000.0, cpi=0.6, snr_db=40.0, seed=0, t0=0.0, gate=None, amp=1.0):
    """(eta, s0, s1, r_track): per-sample SNR ``snr_db`` (signal amplitude ``amp``, unit noise scale);
    r_track = R*sqrt(1 - R'^2/Vp^2), where a range-Doppler RCMC puts the mover."""
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
    rdot = ((x0 + vx * eta) * vx + (y0 + (vy - Vp) * eta) * (vy - Vp)) / r
    return eta, s0, s1, r * np.sqrt(1.0 - (rdot / Vp) ** 2)


@pytest.fixture
def synth():
    return synth_slowtime


@pytest.fixture
def paper():
    return dict(PAPER)


SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "ati_paper.toml"


def _set(text: str, key: str, value) -> str:
    out, n = re.subn(rf"^{key} = .*$", f"{key} = {value!r}", text, flags=re.M)
    assert n == 1, key
    return out


def small_scene(tmp_path, targets=(), clutter=(), snr=20.0, seed=11, n_lines=450, n_samples=160,
                first_range=11120.0, name="small.toml"):
    """A reduced ATI scene (B 32 MHz, CPI 0.3 s at 1.5 kHz) written to ``tmp_path/name``: the paper
    sample's radar, antenna, platform and channels with smaller numbers and the given scatterers.

    ``targets``: dicts with x_m, y_m, vx_mps, vy_mps, amplitude; ``clutter``: dicts with x_m, y_m,
    range_extent_m, azimuth_extent_m, sigma0_db, density_per_m2.
    """
    full = SAMPLE.read_text()
    head, rest = full.split("[[targets]]", 1)
    tail = rest[rest.index("[second_channel]"):]
    for k, v in (("seed", seed), ("prf_hz", 1500.0), ("range_sampling_rate_hz", 40.0e6),
                 ("chirp_rate_hz_per_s", 3.2e13), ("n_lines", n_lines), ("n_samples", n_samples),
                 ("first_range_m", first_range)):
        head = _set(head, k, v)
    text = head + _set(tail, "snr_db", float(snr))
    for t in targets:
        text += "\n[[targets]]\n" + "".join(f"{k} = {float(v)!r}\n" for k, v in t.items())
    for c in clutter:
        text += "\n[[clutter]]\n" + "".join(f"{k} = {float(v)!r}\n" for k, v in c.items())
    p = tmp_path / name
    p.write_text(text + "\n")
    return p


@pytest.fixture
def scene_file():
    return small_scene
