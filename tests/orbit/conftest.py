"""Orbit test fixtures (truth orbits from tests/orbit/truth.py)."""

from __future__ import annotations

import pytest

from orbit.accuracy import TruthOrbit
from orbit.statevectors import StateVectors
from tests.orbit.truth import make_truth


@pytest.fixture(scope="session")
def polar_truth() -> TruthOrbit:
    """Sun-synchronous-like (98.6 deg) orbit; the 2 h span covers ascending and descending passes."""
    return make_truth(98.6)


@pytest.fixture(scope="session")
def ecef_truth(polar_truth) -> StateVectors:
    """The polar truth's state vectors in ECEF."""
    return polar_truth.sv.to_ecef()
