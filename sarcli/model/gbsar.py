"""GB-SAR models: the rail site, the antenna, a scan (one frequency sweep per rail stop), a focused image.

Phase convention: a scatterer at one-way range R from the antenna phase centre gives
``S21 ~ exp(-j 4 pi f R / c)``; an image pixel at R0 carries ``-4 pi R0 / lam``. A scan may instead
hold one sweep per 3-D antenna position (``antenna_position``, e.g. an airborne phase history) and a
reference range per sweep (``reference_range`` r_ref: the sweep was de-ramped / motion-compensated to
it, ``S21 ~ exp(-j 4 pi f (R - r_ref) / c)``); such scans are focused on a grid (``grid_z_m``), where a
scatterer focuses to its complex amplitude. File layouts: ``sarcli.io.scan`` and ``sarcli.io.gbsar_image``.
"""

from __future__ import annotations

import math
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
    """In-memory GB-SAR scan. ``s21`` is (n_pol, n_stops, n_freq) complex64.

    A rail scan has antenna phase centres ``(rail_position, 0, rail_height)`` in the scan frame (x
    along the rail, y horizontal towards the scene, z up). ``antenna_position`` (n_stops, 3) m, when
    given, replaces them with any 3-D track in a local Cartesian frame (then ``rail_position`` is the
    distance travelled along the track and ``rail_height`` its z). ``reference_range`` (n_stops,) m,
    when given, is the range each sweep's phase is referenced to (module docstring).
    """

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
    antenna_position: np.ndarray | None = None
    reference_range: np.ndarray | None = None

    @property
    def n_stops(self) -> int:
        return int(self.s21.shape[1])

    @property
    def is_rail(self) -> bool:
        """True for a straight-rail scan in absolute range (no 3-D track, no reference range)."""
        return self.antenna_position is None and self.reference_range is None

    def antenna_xyz(self) -> np.ndarray:
        """(n_stops, 3) float64 antenna phase centres in the scan frame (class docstring)."""
        if self.antenna_position is not None:
            return np.asarray(self.antenna_position, np.float64)
        x = np.asarray(self.rail_position, np.float64)
        return np.stack([x, np.zeros_like(x), np.asarray(self.rail_height, np.float64)], axis=1)

    def pol(self, name: str) -> np.ndarray:
        """(n_stops, n_freq) S21 of one polarization."""
        if name not in self.polarizations:
            raise ProductError(f"scan has polarizations {','.join(self.polarizations)}, not {name}")
        return self.s21[self.polarizations.index(name)]


@dataclass
class GbsarImage:
    """A focused image. Rail images (``grid_z_m`` None) lie in the slant plane of the rail: rows
    ``range_m`` (R0, distance from the rail line), columns ``azimuth_m`` (x along the rail), phase
    ``-4 pi R0/lam`` at a scatterer. Grid images (``grid_z_m`` a height) lie in the horizontal plane
    z = grid_z_m of the scan frame: rows ``range_m`` hold y, columns ``azimuth_m`` hold x, and a
    scatterer focuses to its complex amplitude. ``permittivity``: relative permittivity of the medium
    the waves travelled in (speed c/sqrt(eps)); ranges are geometric metres in that medium."""

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
    permittivity: float = 1.0
    grid_z_m: float | None = None

    def pol(self, name: str) -> np.ndarray:
        if name not in self.polarizations:
            raise ProductError(f"image has polarizations {','.join(self.polarizations)}, not {name}")
        return self.image[self.polarizations.index(name)]

    @property
    def wavelength_m(self) -> float:
        """Centre wavelength in the medium, c / (f_c sqrt(eps))."""
        return C_LIGHT / (self.center_frequency_hz * math.sqrt(self.permittivity))
