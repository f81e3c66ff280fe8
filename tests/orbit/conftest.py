"""Orbit test fixtures: J2 truth orbits sampled like Radarsat-1 (15 vectors, 480 s) and densely."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from orbit.propagate import Keplerian, kepler_to_state, propagate_j2
from orbit.statevectors import StateVectors

EPOCH = "2002-06-16T15:41:00Z"
SPACING = 480.0
N_VECTORS = 15


@dataclass
class Truth:
    sv: StateVectors  # 15 x 480 s ECI state vectors
    t: np.ndarray  # dense times
    r: np.ndarray  # dense ECI truth
    v: np.ndarray


def make_truth(inclination_deg: float, n_dense: int = 1201, mean_anomaly: float = 0.4,
               node_times: np.ndarray | None = None) -> Truth:
    """Radarsat-1-like orbit (a = 7167 km, e = 0.0011) integrated with J2; ECI nodes + dense truth."""
    k = Keplerian(7_167_000.0, 0.0011, np.radians(inclination_deg), 0.3, 1.2, mean_anomaly)
    r0, v0 = kepler_to_state(k)
    tn = np.arange(N_VECTORS) * SPACING if node_times is None else node_times
    td = np.linspace(tn[0], tn[-1], n_dense)
    r, v = propagate_j2(r0, v0, np.concatenate([tn, td]))
    sv = StateVectors(tn, r[: tn.size], v[: tn.size], "ECI", EPOCH)
    return Truth(sv, td, r[tn.size:], v[tn.size:])


@pytest.fixture(scope="session")
def polar_truth() -> Truth:
    """Sun-synchronous-like (98.6 deg) orbit; the 2 h span covers ascending and descending passes."""
    return make_truth(98.6)


@pytest.fixture(scope="session")
def ecef_truth(polar_truth) -> StateVectors:
    """The polar truth's state vectors in ECEF."""
    return polar_truth.sv.to_ecef()
