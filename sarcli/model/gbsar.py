"""GB-SAR models: the rail site, the antenna, a scan (one frequency sweep per rail stop), a focused image.

Phase convention: a scatterer at one-way range R from the antenna phase centre gives
``S21 ~ exp(-j 4 pi f R / c)``; an image pixel at R0 carries ``-4 pi R0 / lam``. File layouts:
``sarcli.io.scan`` and ``sarcli.io.gbsar_image``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.errors import ProductError
from sarcli.model.constants import C_LIGHT


@dataclass
class Site:
    """Rail geodetic position (centre) and heading; heading in degrees clockwise from north."""

    latitude_deg: float = 0.0
    longitude_deg: float = 0.0
    height_m: float = 0.0
    heading_deg: float = 0.0
    look_side: str = "right"


@dataclass
class Antenna:
    length_azimuth_m: float = 0.25
    length_range_m: float = 0.25
    beamwidth_rad: float = float(np.deg2rad(15.0))
    gain_dbi: float = 20.0


@dataclass
class Scan:
    """In-memory GB-SAR scan. ``s21`` is (n_pol, n_stops, n_freq) complex64."""

    s21: np.ndarray
    frequency: np.ndarray
    rail_position: np.ndarray
    rail_height: np.ndarray
    polarizations: tuple[str, ...]
    epoch_utc: str
    stop_time: np.ndarray | None = None
    stop_flags: np.ndarray | None = None
    site: Site = field(default_factory=Site)
    antenna: Antenna = field(default_factory=Antenna)
    instrument: dict[str, Any] = field(default_factory=dict)
    truth: dict[str, Any] | None = None
    source: str = "simulated"
    status: str = "simulated"
    n_planned: int | None = None

    @property
    def n_stops(self) -> int:
        return int(self.s21.shape[1])

    def pol(self, name: str) -> np.ndarray:
        """(n_stops, n_freq) S21 of one polarization."""
        if name not in self.polarizations:
            raise ProductError(f"scan has polarizations {','.join(self.polarizations)}, not {name}")
        return self.s21[self.polarizations.index(name)]


@dataclass
class GbsarImage:
    image: np.ndarray
    range_m: np.ndarray
    azimuth_m: np.ndarray
    algorithm_map: np.ndarray
    polarizations: tuple[str, ...]
    algorithm: str
    center_frequency_hz: float
    frequency_step_hz: float
    n_freq: int
    rail_height_m: float
    rail_centre_m: float
    rail_length_m: float
    epoch_utc: str
    scan_time_s: float
    site: Site = field(default_factory=Site)
    report: dict[str, Any] = field(default_factory=dict)

    def pol(self, name: str) -> np.ndarray:
        if name not in self.polarizations:
            raise ProductError(f"image has polarizations {','.join(self.polarizations)}, not {name}")
        return self.image[self.polarizations.index(name)]

    @property
    def wavelength_m(self) -> float:
        return C_LIGHT / self.center_frequency_hz
