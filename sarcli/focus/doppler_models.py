"""A geometric Doppler model (hyperbolic range, constant effective velocity and squint).

``fdc(R, t) = -2 V sin(theta) / lam`` and ``fr(R, t) = -2 V^2 cos^2(theta) / (lam R)`` with R the
beam-centre slant range (see :mod:`sarcli.focus.kinematics`). It serves where no estimated model
exists: published processing parameters (``from_centroid_and_rate``, e.g. the Radarsat-1 Vancouver
block's fdc = -6900 Hz, Ka = 1733 Hz/s) and the focusing tests' synthetic scenes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.errors import SarcliError


@dataclass(frozen=True)
class GeometricDoppler:
    """Constant effective velocity ``velocity_mps`` and squint (``sin_squint``), carrier wavelength."""

    velocity_mps: float
    sin_squint: float
    wavelength_m: float

    def fdc(self, range_m, azimuth_time_s=0.0) -> np.ndarray:
        shape = np.broadcast(np.asarray(range_m), np.asarray(azimuth_time_s)).shape
        return np.full(shape, -2.0 * self.velocity_mps * self.sin_squint / self.wavelength_m)

    def fr(self, range_m, azimuth_time_s=0.0) -> np.ndarray:
        r = np.broadcast_to(np.asarray(range_m, np.float64),
                            np.broadcast(np.asarray(range_m), np.asarray(azimuth_time_s)).shape)
        return -2.0 * self.velocity_mps**2 * (1.0 - self.sin_squint**2) / (self.wavelength_m * r)

    @classmethod
    def from_centroid_and_rate(cls, fdc_hz: float, fr_hz_per_s: float, range_m: float,
                               wavelength_m: float) -> GeometricDoppler:
        """The model through (fdc, fr) at beam-centre range ``range_m`` (fr < 0)."""
        if not fr_hz_per_s < 0.0:
            raise SarcliError(f"Doppler rate must be negative, got {fr_hz_per_s} Hz/s")
        # fr = -2 V^2 (1 - s^2) / (lam R), s = -fdc lam / (2V)  =>  V^2 = -fr lam R / 2 + (fdc lam / 2)^2
        v = float(np.sqrt(-fr_hz_per_s * wavelength_m * range_m / 2.0 + (fdc_hz * wavelength_m / 2.0) ** 2))
        return cls(v, -fdc_hz * wavelength_m / (2.0 * v), wavelength_m)
