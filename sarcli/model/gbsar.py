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
from sarcli.model import checks as ck
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import LOOK_SIDES

# Plausibility bounds of GB-SAR products (SI; docs/products.md, "What sarcli refuses").
POLARIZATIONS = ("VV", "VH", "HV", "HH")
FREQUENCY_HZ = (1.0e3, 1.0e12)  # a VNA sweep
SWEEP_RTOL = 1e-6  # a linear sweep: every step the mean step within this (VNA frequencies are computed)
RAIL_SPAN_M = 1.0e3  # the longest rail (1-D scan): ground-based rails are metres to tens of metres
HEIGHT_M = (-1.0e4, 1.0e4)  # antenna height above the reference, site height
ANTENNA_LENGTH_M = (1e-3, 100.0)
GAIN_DBI = (-50.0, 100.0)
STOP_FLAGS = (0, 1)  # 0 good, 1 NaN / invalid sweep


@dataclass
class Site:
    """Rail geodetic position (centre) and heading; heading in degrees clockwise from north."""

    latitude_deg: float = 0.0
    longitude_deg: float = 0.0
    height_m: float = 0.0
    heading_deg: float = 0.0
    look_side: str = "right"

    def validate(self, where: str = "site") -> None:
        """Latitude within +-90 deg, longitude within -180 .. 360 deg, finite height and heading, a look side."""
        w = f"{where}: site"
        ck.number(w, "latitude_deg", self.latitude_deg, -90.0, 90.0, unit="deg")
        ck.number(w, "longitude_deg", self.longitude_deg, -180.0, 360.0, unit="deg")
        ck.number(w, "height_m", self.height_m, *HEIGHT_M, unit="m")
        ck.number(w, "heading_deg", self.heading_deg, -360.0, 720.0, unit="deg")
        ck.text(w, "look_side", self.look_side, LOOK_SIDES)


@dataclass
class Antenna:
    length_azimuth_m: float = 0.25
    length_range_m: float = 0.25
    beamwidth_rad: float = float(np.deg2rad(15.0))
    gain_dbi: float = 20.0

    def validate(self, where: str = "antenna") -> None:
        """Positive antenna lengths (<= 100 m), a beamwidth in (0, pi], a finite gain."""
        w = f"{where}: antenna"
        ck.number(w, "length_azimuth_m", self.length_azimuth_m, *ANTENNA_LENGTH_M, unit="m")
        ck.number(w, "length_range_m", self.length_range_m, *ANTENNA_LENGTH_M, unit="m")
        bw = ck.number(w, "beamwidth_rad", self.beamwidth_rad, 0.0, np.pi, unit="rad")
        if bw == 0.0:
            raise ProductError(f"{w}: beamwidth_rad must be positive")
        ck.number(w, "gain_dbi", self.gain_dbi, *GAIN_DBI, unit="dBi")


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

    def usable_stops(self) -> np.ndarray:
        """Boolean per stop: not flagged and every S21 sample finite (what focusing uses)."""
        ok = np.all(np.isfinite(self.s21), axis=(0, 2))
        if self.stop_flags is not None:
            ok &= np.asarray(self.stop_flags) == 0
        return ok

    def validate(self, where: str = "scan", min_usable_stops: int = 0) -> None:
        """Refuse (one :class:`ProductError` line) a scan a processor could not trust.

        s21 complex (n_pol, n_stops, n_freq) with one known polarization per plane (no repeats; NaN
        allowed: such stops are skipped, like flagged ones); frequencies finite, within
        ``FREQUENCY_HZ``, strictly increasing and uniform within ``SWEEP_RTOL``; rail positions finite
        and strictly monotonic (the rail moves one way; focusing sorts a decreasing rail), or, for a 3-D
        track (``antenna_position`` (n_stops, 3) finite, ``reference_range`` finite and positive), the
        distance along it never decreasing; heights finite within ``HEIGHT_M``;
        stop times finite and never decreasing; flags 0 or 1; an ISO-8601 epoch; site and antenna;
        instrument settings text (UTF-8) or numbers; at least ``min_usable_stops`` usable stops.
        """
        s21 = ck.array(where, "s21", self.s21, "c", ndim=3, finite=False)
        n_pol, n_stops, n_freq = s21.shape
        pols = tuple(self.polarizations)
        if n_pol < 1 or n_pol != len(pols) or len(set(pols)) != n_pol:
            raise ProductError(f"{where}: polarizations {','.join(pols) or 'none'} do not match s21's {n_pol} "
                               "plane(s)")
        for p in pols:
            ck.text(where, "polarization", p, POLARIZATIONS)
        f = ck.array(where, "frequency", self.frequency, "f", shape=(n_freq,), min_size=1)
        ck.number(where, "frequency[0]", f[0], *FREQUENCY_HZ, unit="Hz")
        ck.number(where, "frequency[-1]", f[-1], *FREQUENCY_HZ, unit="Hz")
        ck.increasing(where, "frequency", f)
        if n_freq > 1:
            ck.uniform(where, "frequency", f, (f[-1] - f[0]) / (n_freq - 1), SWEEP_RTOL)
        x = ck.array(where, "rail_position", self.rail_position, "f", shape=(n_stops,))
        if self.antenna_position is not None:
            ck.array(where, "antenna_position", self.antenna_position, "f", shape=(n_stops, 3))
            ck.increasing(where, "rail_position (distance along the track)", x, strict=False)
        elif x.size > 1 and x[-1] < x[0]:
            if not np.all(np.diff(x) < 0):
                k = int(np.argmin(np.diff(x) < 0))
                raise ProductError(f"{where}: rail_position must move one way: it decreases overall but element "
                                   f"{k + 1} = {x[k + 1]:g} follows {x[k]:g}")
        else:
            ck.increasing(where, "rail_position", x)
        if self.antenna_position is None and x.size and not np.ptp(x) <= RAIL_SPAN_M:
            raise ProductError(f"{where}: rail_position spans {np.ptp(x):.6g} m: a ground-based rail is at most "
                               f"{RAIL_SPAN_M:g} m long (positions in another unit?)")
        if self.reference_range is not None:
            rr = ck.array(where, "reference_range", self.reference_range, "f", shape=(n_stops,))
            if np.any(rr <= 0):
                raise ProductError(f"{where}: reference_range must be positive")
        z = ck.array(where, "rail_height", self.rail_height, "f", shape=(n_stops,))
        if np.any((z < HEIGHT_M[0]) | (z > HEIGHT_M[1])):
            raise ProductError(f"{where}: rail_height has implausible values (expected {HEIGHT_M[0]:g} .. "
                               f"{HEIGHT_M[1]:g} m)")
        if self.stop_time is not None:
            ck.increasing(where, "stop_time", ck.array(where, "stop_time", self.stop_time, "f", shape=(n_stops,)),
                          strict=False)
        if self.stop_flags is not None:
            flags = ck.array(where, "stop_flags", self.stop_flags, "iu", shape=(n_stops,))
            if np.any((flags < STOP_FLAGS[0]) | (flags > STOP_FLAGS[1])):
                raise ProductError(f"{where}: stop_flags must be 0 (good) or 1 (invalid sweep)")
        ck.utc(where, "epoch_utc", self.epoch_utc)
        ck.text(where, "source", self.source)
        ck.text(where, "status", self.status)
        if self.n_planned is not None:
            ck.number(where, "n_planned", self.n_planned, lo=0, integer=True)
        self.site.validate(where)
        self.antenna.validate(where)
        for name, v in self.instrument.items():
            if isinstance(v, str):
                ck.text(f"{where}: instrument", name, v)
            elif not isinstance(v, int | float | bool | np.integer | np.floating | np.bool_):
                raise ProductError(f"{where}: instrument setting {name} must be text or a number")
        n_ok = int(np.count_nonzero(self.usable_stops()))
        if n_ok < min_usable_stops:
            raise ProductError(f"{where}: {n_ok} usable rail stop(s) (unflagged, finite S21); at least "
                               f"{min_usable_stops} are needed")

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

    def validate(self, where: str = "gbsar image", pixels: bool = True) -> None:
        """A finite complex (n_pol, n_range, n_azimuth) image on finite, strictly increasing axes
        (ranges >= 0 in the rail's slant plane; a grid image's ``range`` axis is y, any sign), an
        algorithm map of codes 0..3 on the same grid, known polarizations, a sweep (centre within
        ``FREQUENCY_HZ``, positive step, >= 1 point), finite rail geometry (positive length), an
        ISO-8601 epoch, the site, a permittivity >= 1. ``pixels=False``: the image's dtype and shape
        only (an image left on disk, read block by block)."""
        if pixels:
            n_pol, n_r, n_x = ck.array(where, "image", self.image, "c", ndim=3).shape
        else:
            if np.dtype(self.image.dtype).kind != "c" or len(self.image.shape) != 3:
                raise ProductError(f"{where}: image must be complex (n_pol, n_range, n_azimuth), got "
                                   f"{self.image.dtype} {self.image.shape}")
            n_pol, n_r, n_x = self.image.shape
        pols = tuple(self.polarizations)
        if n_pol < 1 or n_pol != len(pols) or len(set(pols)) != n_pol:
            raise ProductError(f"{where}: polarizations {','.join(pols) or 'none'} do not match the image's "
                               f"{n_pol} plane(s)")
        for p in pols:
            ck.text(where, "polarization", p, POLARIZATIONS)
        r = ck.array(where, "range", self.range_m, "f", shape=(n_r,), min_size=1)
        ck.increasing(where, "range", r)
        if r[0] < 0 and self.grid_z_m is None:
            raise ProductError(f"{where}: range must be >= 0, starts at {r[0]:g} m")
        if not (math.isfinite(self.permittivity) and self.permittivity >= 1.0):
            raise ProductError(f"{where}: permittivity must be >= 1 (vacuum), got {self.permittivity}")
        ck.increasing(where, "azimuth", ck.array(where, "azimuth", self.azimuth_m, "f", shape=(n_x,), min_size=1))
        amap = ck.array(where, "algorithm_map", self.algorithm_map, "iu", shape=(n_r, n_x))
        if amap.size and (amap.min() < 0 or amap.max() > 3):
            raise ProductError(f"{where}: algorithm_map codes must be 0 (not covered), 1 DF, 2 RD or 3 BP")
        ck.text(where, "algorithm", self.algorithm)
        ck.number(where, "center_frequency_hz", self.center_frequency_hz, *FREQUENCY_HZ, unit="Hz")
        step = ck.number(where, "frequency_step_hz", self.frequency_step_hz, lo=0.0, unit="Hz")
        if step == 0.0:
            raise ProductError(f"{where}: frequency_step_hz must be positive")
        ck.number(where, "n_freq", self.n_freq, lo=1, integer=True)
        ck.number(where, "rail_height_m", self.rail_height_m, *HEIGHT_M, unit="m")
        ck.number(where, "rail_centre_m", self.rail_centre_m, unit="m")
        length = ck.number(where, "rail_length_m", self.rail_length_m, lo=0.0, unit="m")
        if length == 0.0:
            raise ProductError(f"{where}: rail_length_m must be positive")
        ck.utc(where, "epoch_utc", self.epoch_utc)
        ck.number(where, "scan_time_s", self.scan_time_s, unit="s")
        self.site.validate(where)

    def pol(self, name: str) -> np.ndarray:
        if name not in self.polarizations:
            raise ProductError(f"image has polarizations {','.join(self.polarizations)}, not {name}")
        return self.image[self.polarizations.index(name)]

    @property
    def wavelength_m(self) -> float:
        """Centre wavelength in the medium, c / (f_c sqrt(eps))."""
        return C_LIGHT / (self.center_frequency_hz * math.sqrt(self.permittivity))
