"""Doppler models: the absolute Doppler centroid and the Doppler rate over (slant range, azimuth time).

Any object with vectorized ``fdc(range_m, azimuth_time_s)`` (absolute centroid, Hz, ambiguity
included) and ``fr(range_m, azimuth_time_s)`` (Doppler rate, Hz/s, negative for a side-looking radar)
is a :class:`DopplerModel`: float64 over broadcastable arrays of slant range (m, the beam-centre
range of a RAW range sample) and azimuth (pulse) time (s after the product epoch). Two concrete
models:

- :class:`PolyDoppler`, estimated from the data (``sarcli doppler``): 2-D polynomials fitted to the
  per-block estimates (the map-drift rate is the effective-velocity law -2 Vr^2/(lam R), a
  :class:`~sarcli.model.poly.Poly2D` with ``x_power = -1``, valid at every range); the per-block
  tables, methods and parameters travel with it (and in ``doppler.h5``);
- :class:`GeometricDoppler`, hyperbolic range with a constant effective velocity and squint:
  ``fdc = -2 V sin(theta) / lam``, ``fr = -2 V^2 cos^2(theta) / (lam R)`` (published processing
  parameters, synthetic test scenes).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np

from sarcli.errors import ConfigError
from sarcli.model.doppler_summary import DopplerSummary
from sarcli.model.poly import Poly2D


@runtime_checkable
class DopplerModel(Protocol):
    """What focusing and ATI need of a Doppler model (module docstring)."""

    def fdc(self, range_m: Any, azimuth_time_s: Any) -> np.ndarray:
        """Absolute Doppler centroid, Hz."""
        ...

    def fr(self, range_m: Any, azimuth_time_s: Any) -> np.ndarray:
        """Doppler rate, Hz/s."""
        ...


@dataclass
class PolyDoppler:
    """Absolute Doppler centroid and Doppler rate as 2-D polynomials in (slant range m, time s).

    ``blocks`` maps column names to equally long 1-D arrays (one row per (azimuth, range) block):
    range_m, azimuth_time_s, fdc_baseband_hz, quality, weight, valid, ambiguity, margin_prf, fdc_hz,
    fdc_orbit_hz, fr_hz_per_s, outlier. ``summary`` (:class:`~sarcli.model.doppler_summary.DopplerSummary`)
    carries the scene values, the methods and whether the PRF ambiguity was resolved.
    """

    fdc_poly: Poly2D
    fr_poly: Poly2D
    prf_hz: float
    wavelength_m: float
    blocks: dict[str, np.ndarray] = field(default_factory=dict)
    summary: DopplerSummary | None = None
    parameters: dict[str, Any] = field(default_factory=dict)

    @property
    def ambiguity_resolved(self) -> bool:
        """True when a source (orbit, data, user) decided the PRF ambiguity of ``fdc``; False without a
        summary (nothing says it was)."""
        return self.summary is not None and self.summary.ambiguity_resolved

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
            raise ConfigError(f"Doppler rate must be negative, got {fr_hz_per_s} Hz/s")
        # fr = -2 V^2 (1 - s^2) / (lam R), s = -fdc lam / (2V)  =>  V^2 = -fr lam R / 2 + (fdc lam / 2)^2
        v = float(np.sqrt(-fr_hz_per_s * wavelength_m * range_m / 2.0 + (fdc_hz * wavelength_m / 2.0) ** 2))
        return cls(v, -fdc_hz * wavelength_m / (2.0 * v), wavelength_m)
