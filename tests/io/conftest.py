"""Fixtures for the CEOS / MATLAB / info tests: small Radarsat-1-like raw products built here.

Products use code-exact timing (PRF code 4283, window code 1262, 8 pulses in flight: the Vancouver
values of the format notes), random 4-bit levels, random whole-dB AGC and a J2-propagated orbit
with 15 ECI state vectors 480 s apart.
"""

from __future__ import annotations

import numpy as np
import pytest

from orbit.propagate import Keplerian, kepler_to_state, propagate_j2
from sarcli.io.ceos.radarsat1 import aux as A
from sarcli.model.raw import Orbit, Radar, RawProduct

C = 299_792_458.0
PRF_CODE, WINDOW_CODE, ADC, N_PULSES = 4283, 1262, 0, 8


def levels(rng: np.random.Generator, shape) -> np.ndarray:
    return (2 * rng.integers(-8, 8, shape) + 1 + 1j * (2 * rng.integers(-8, 8, shape) + 1)).astype(np.complex64)


@pytest.fixture(scope="session")
def rs1_orbit():
    k = Keplerian(7_167_000.0, 0.0011, np.radians(98.59), 0.7, 1.3, 2.1)
    r0, v0 = kepler_to_state(k)
    t = -3360.0 + 480.0 * np.arange(15)
    pos, vel = propagate_j2(r0, v0, t)
    return t, pos, vel


@pytest.fixture
def make_raw(rs1_orbit):
    """Factory: ``make_raw(n_lines=40, n_samples=96, seed=0, epoch=..., replica=True, **overrides)``."""

    def make(n_lines=40, n_samples=96, seed=0, epoch="2002-06-16T15:41:07.250125Z", replica=True, **kw):
        rng = np.random.default_rng(seed)
        fs = 1.0 / float(A.clock_period_s(ADC))
        prf = float(A.prf_from_code(PRF_CODE, ADC))
        tau0 = float(A.first_sample_time(WINDOW_CODE, PRF_CODE, ADC, N_PULSES))
        t, pos, vel = rs1_orbit
        raw = RawProduct(
            echo=levels(rng, (n_lines, n_samples)), azimuth_time=np.arange(n_lines) / prf, epoch_utc=epoch,
            radar=Radar(5.3e9, C / 5.3e9, prf, fs, -0.72135e12, 41.75e-6, tau0, C * tau0 / 2, 4),
            agc_db=rng.integers(2, 18, n_lines).astype(np.float32), orbit=Orbit(t, pos, vel, "ECI"),
            replica=levels(rng, A.replica_samples(ADC)) if replica else None, source="simulated")
        for k, v in kw.items():
            setattr(raw, k, v)
        return raw

    return make
