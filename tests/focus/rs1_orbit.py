"""A RADARSAT-1-like orbit for geometry tests: 798 km, sun-synchronous inclination, ascending through
~49 N at t = 0 (J2-propagated over +-60 s, 10 s steps), in ECEF."""

from __future__ import annotations

import numpy as np

from orbit.propagate import Keplerian, kepler_to_state, propagate_j2
from orbit.statevectors import StateVectors


def rs1_ecef_orbit() -> StateVectors:
    """State vectors of the orbit (epoch 2002-06-16T00:00:00Z), ECEF."""
    e, inc, w = 0.00115, np.radians(98.594), np.radians(90.0)
    nu = np.arcsin(np.sin(np.radians(49.0)) / np.sin(inc)) - w
    ea = 2 * np.arctan(np.sqrt((1 - e) / (1 + e)) * np.tan(nu / 2))
    r0, v0 = kepler_to_state(Keplerian(7167.1e3, e, inc, 0.0, w, ea - e * np.sin(ea)))
    t = np.arange(-60.0, 61.0, 10.0)
    r, v = propagate_j2(r0, v0, t)
    return StateVectors(t, r, v, "ECI", "2002-06-16T00:00:00Z").to_ecef()
