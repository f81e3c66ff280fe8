"""The Doppler model handed to focusing and ATI (contract 4).

``DopplerModel.fdc(range_m, azimuth_time_s)`` is the ABSOLUTE Doppler centroid (Hz, ambiguity
included) and ``DopplerModel.fr(range_m, azimuth_time_s)`` the Doppler rate (Hz/s, negative for a
side-looking radar), both vectorized float64 over broadcastable arrays of slant range (m) and azimuth
time (s after the product epoch). Both are 2-D polynomials fitted to the per-block estimates (the
map-drift rate is the effective-velocity law -2 Vr^2/(lam R), a ``Poly2D`` with ``x_power = -1``, valid
at every range); the per-block tables, methods and parameters travel with the model (and in
``doppler.h5``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.doppler.polyfit import Poly2D


@dataclass
class DopplerModel:
    """Absolute Doppler centroid and Doppler rate as 2-D polynomials in (slant range m, time s).

    ``blocks`` maps column names to equally long 1-D arrays (one row per (azimuth, range) block):
    range_m, azimuth_time_s, fdc_baseband_hz, quality, weight, valid, ambiguity, margin_prf, fdc_hz,
    fdc_orbit_hz, fr_hz_per_s, outlier. ``summary`` carries the scene values and the method names
    (``fdc_method``, ``ambiguity_source`` = orbit|data|none, ``ambiguity_confidence``, ``fr_method``).
    """

    fdc_poly: Poly2D
    fr_poly: Poly2D
    prf_hz: float
    wavelength_m: float
    blocks: dict[str, np.ndarray] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    parameters: dict[str, Any] = field(default_factory=dict)

    def fdc(self, range_m, azimuth_time_s) -> np.ndarray:
        """Absolute Doppler centroid, Hz."""
        return self.fdc_poly(range_m, azimuth_time_s)

    def fr(self, range_m, azimuth_time_s) -> np.ndarray:
        """Doppler rate, Hz/s."""
        return self.fr_poly(range_m, azimuth_time_s)

    def fdc_baseband(self, range_m, azimuth_time_s) -> np.ndarray:
        """Centroid wrapped to [-PRF/2, PRF/2), Hz."""
        f = self.fdc(range_m, azimuth_time_s)
        return np.mod(f + 0.5 * self.prf_hz, self.prf_hz) - 0.5 * self.prf_hz

    def ambiguity(self, range_m, azimuth_time_s) -> np.ndarray:
        """PRF ambiguity number of the model centroid."""
        return np.floor(self.fdc(range_m, azimuth_time_s) / self.prf_hz + 0.5).astype(np.int64)
