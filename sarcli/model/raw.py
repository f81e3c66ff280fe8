"""The stripmap raw-echo model: radar parameters, state vectors, attitude and the echo lines.

Pure data (no file format): readers (``sarcli.io``) build a :class:`RawProduct`, processing reads it.
Units are SI; times are float64 seconds after ``epoch_utc`` (ISO-8601 UTC). Phase convention: a
scatterer at one-way range R contributes ``exp(-j 4 pi R / lam)``. The file layout is in
``sarcli.io.raw`` and ``docs/products.md``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.errors import ProductError
from sarcli.model.constants import C_LIGHT


@dataclass
class Radar:
    """Radar parameters (SI units). ``chirp_rate_hz_per_s`` is signed: transmitted phase +pi*K*t^2."""

    carrier_frequency_hz: float
    wavelength_m: float
    prf_hz: float
    range_sampling_rate_hz: float
    chirp_rate_hz_per_s: float
    pulse_length_s: float
    window_start_s: float
    first_range_m: float
    quantization_bits: int = 0
    receiver_offsets_m: tuple[float, ...] = (0.0,)
    platform_velocity_mps: float | None = None


@dataclass
class Orbit:
    """State vectors as delivered: times (s after the product epoch), positions (m), velocities (m/s)."""

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    frame: str


@dataclass
class Attitude:
    """Attitude angles (rad) at times (s after the product epoch)."""

    time: np.ndarray
    pitch: np.ndarray
    roll: np.ndarray
    yaw: np.ndarray


@dataclass
class RawProduct:
    """In-memory stripmap raw product. ``echo`` is (n_lines, n_samples) complex64, channel 0.

    ``calibration``: lines that are not echoes (internal calibration pulses), kept for inspection and
    never focused: ``echo`` (n_cal, n_channels, n_samples) complex64, ``line`` (their slots in the line
    grid, zero in ``echo``), ``azimuth_time``, and reader-specific labels (e.g. ``cal_type``).
    """

    echo: np.ndarray
    azimuth_time: np.ndarray
    epoch_utc: str
    radar: Radar
    look_side: str = "right"
    source: str = "simulated"
    echo_channels: np.ndarray | None = None
    prf_per_line: np.ndarray | None = None
    agc_db: np.ndarray | None = None
    replica: np.ndarray | None = None
    orbit: Orbit | None = None
    attitude: Attitude | None = None
    truth: dict[str, Any] | None = None
    extra_attrs: dict[str, Any] = field(default_factory=dict)
    #: named arrays a reader keeps beside the echo (e.g. Sentinel-1 noise and calibration lines, packet
    #: header tables); names may contain '/' (sub-groups); see ``docs/products.md``.
    auxiliary: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def shape(self) -> tuple[int, int]:
        return tuple(self.echo.shape)  # type: ignore[return-value]

    @property
    def n_channels(self) -> int:
        return 1 + (0 if self.echo_channels is None else self.echo_channels.shape[0])

    def slant_range(self) -> np.ndarray:
        """Slant range of every range sample (m), from first_range_m and the sampling rate."""
        n = self.echo.shape[1]
        return self.radar.first_range_m + np.arange(n) * C_LIGHT / (2.0 * self.radar.range_sampling_rate_hz)

    def line_gain(self) -> np.ndarray | None:
        """float32 factor per line that undoes the receiver attenuation, 10**(agc_db/20); None without AGC."""
        if self.agc_db is None:
            return None
        return (10.0 ** (np.asarray(self.agc_db, np.float64) / 20.0)).astype(np.float32)

    def calibrated(self) -> RawProduct:
        """The same product with the per-line AGC undone in the echo (a copy; itself when there is no AGC)."""
        gain = self.line_gain()
        if gain is None:
            return self
        extra = None if self.echo_channels is None else self.echo_channels * gain[None, :, None]
        return dataclasses.replace(self, echo=self.echo * gain[:, None], echo_channels=extra, agc_db=None)

    def channel(self, k: int) -> np.ndarray:
        """Echo of receive channel k (0 = /echo)."""
        if k == 0:
            return self.echo
        if self.echo_channels is None or k > self.echo_channels.shape[0]:
            raise ProductError(f"product has {self.n_channels} channel(s), channel {k} requested")
        return self.echo_channels[k - 1]
