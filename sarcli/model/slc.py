"""The focused single-look complex image model (zero-Doppler lines, slant-range columns).

Phase convention: a scatterer at closest range R0 has phase ``arg(sigma) - 4 pi R0 / lam`` at its
peak. The file layout is in ``sarcli.io.slc``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.model.raw import Attitude, Orbit, Radar


@dataclass
class DopplerUsed:
    """Centroid, rate and effective velocity used per processing block (rows) and range (columns)."""

    block_time: np.ndarray
    range_m: np.ndarray
    fdc_hz: np.ndarray
    fr_hz_per_s: np.ndarray
    velocity_mps: np.ndarray


@dataclass
class Calibration:
    """Radiometric look-up tables of an SLC on a coarse (zero-Doppler time, slant range) grid
    (:mod:`sarcli.calibration.radiometry` derives them; NISAR RSLC's convention): beta0 = |DN|^2 * beta0,
    sigma0 = |DN|^2 * sigma0, gamma0 = |DN|^2 * gamma0 (ellipsoid incidence), all (n_t, n_r), NaN where the
    product is not calibrated (outside the antenna's main lobe); ``nes0`` the noise-equivalent sigma0
    (linear, NaN without a noise measurement). ``constant`` is the absolute calibration constant K
    (|DN|^2 = K F beta0, F the modelled gain), ``applied`` / ``not_applied`` name the terms of the
    radiometric model that were and were not applied; ``details`` the numbers behind them."""

    azimuth_time: np.ndarray
    slant_range: np.ndarray
    beta0: np.ndarray
    sigma0: np.ndarray
    gamma0: np.ndarray
    nes0: np.ndarray
    constant: float
    applied: tuple[str, ...]
    not_applied: tuple[str, ...]
    details: dict[str, Any] = field(default_factory=dict)


@dataclass
class SLC:
    """In-memory focused image with its axes; ``image`` (n_lines, n_samples) complex64."""

    image: np.ndarray
    azimuth_time: np.ndarray
    slant_range: np.ndarray
    epoch_utc: str
    radar: Radar
    doppler: DopplerUsed
    look_side: str = "right"
    source: str = "simulated"
    algorithm: str = "rd"
    azimuth_spacing_m: float = float("nan")
    first_full_line: int = 0
    last_full_line: int = -1
    parameters: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    orbit: Orbit | None = None
    attitude: Attitude | None = None
    truth: dict[str, Any] | None = None
    calibration: Calibration | None = None

    @classmethod
    def from_raw(cls, raw, *, image: np.ndarray, azimuth_time: np.ndarray, slant_range: np.ndarray,
                 doppler: DopplerUsed, algorithm: str, azimuth_spacing_m: float, first_full_line: int,
                 last_full_line: int, parameters: dict[str, Any] | None = None,
                 timings: dict[str, float] | None = None) -> SLC:
        """The SLC of a focuser: what it computed, plus everything the raw product passes through
        unchanged (epoch, radar, look side, source, orbit, attitude, and the truth of a simulated
        product, which ``sarcli quality`` compares with; processing never reads it). The one
        constructor every focuser uses (:mod:`sarcli.focus.base`)."""
        return cls(image=image, azimuth_time=np.asarray(azimuth_time, np.float64),
                   slant_range=np.asarray(slant_range, np.float64), epoch_utc=raw.epoch_utc, radar=raw.radar,
                   doppler=doppler, look_side=raw.look_side, source=raw.source, algorithm=algorithm,
                   azimuth_spacing_m=float(azimuth_spacing_m), first_full_line=int(first_full_line),
                   last_full_line=int(last_full_line), parameters=dict(parameters or {}),
                   timings=dict(timings or {}), orbit=raw.orbit, attitude=raw.attitude, truth=raw.truth)

    @classmethod
    def placeholder(cls, raw, shape: tuple[int, int]) -> SLC:
        """An empty SLC for :func:`slc_writer` to fill while streaming (see :meth:`update_from`)."""
        e = np.zeros(0)
        return cls(image=np.zeros((0, 0), np.complex64), azimuth_time=np.zeros(shape[0]),
                   slant_range=np.zeros(shape[1]), epoch_utc=raw.epoch_utc, radar=raw.radar,
                   doppler=DopplerUsed(e, e, e, e, e))

    def update_from(self, other: SLC) -> None:
        """Take every field of ``other`` except the image (metadata known after streaming)."""
        for f in dataclasses.fields(self):
            if f.name != "image":
                setattr(self, f.name, getattr(other, f.name))

    @property
    def prf_hz(self) -> float:
        return float(1.0 / np.median(np.diff(self.azimuth_time))) if self.azimuth_time.size > 1 else self.radar.prf_hz

    @property
    def range_spacing_m(self) -> float:
        return float(self.slant_range[1] - self.slant_range[0]) if self.slant_range.size > 1 else float("nan")
