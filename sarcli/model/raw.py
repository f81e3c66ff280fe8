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
from sarcli.model import checks as ck
from sarcli.model.constants import C_LIGHT

# Plausibility bounds of a raw product (SI). A value outside them is a damaged or mislabelled product,
# not a radar: docs/products.md, "What sarcli refuses", explains each one.
PRF_HZ = (1.0, 1.0e6)  # pulse repetition frequency
SAMPLING_RATE_HZ = (1.0e5, 1.0e11)  # complex range sampling rate
CARRIER_HZ = (1.0e7, 1.0e12)  # 30 m .. 0.3 mm wavelength
WAVELENGTH_RTOL = 1e-3  # wavelength_m * carrier_frequency_hz / c = 1 within this
FIRST_RANGE_M = (1.0, 1.0e8)
RANGE_WINDOW_RTOL = 1e-3  # first_range_m = c window_start_s / 2 within this (plus 1 m)
AZIMUTH_TIME_RTOL = 0.1  # every line interval is k/PRF (or k/prf_per_line), k >= 1, within 10 % of 1/PRF
AGC_DB = (-200.0, 200.0)
QUANTIZATION_BITS = (0, 32)
SPEED_MPS = (1e-3, 1.2e4)  # platform speed of a LOCAL (flat-Earth) trajectory, and the nominal velocity
EARTH_ORBIT_RADIUS_M = (6.5e6, 5.0e7)  # |r| of an Earth orbit, from the Earth's centre
EARTH_MU = 3.986004418e14  # m^3/s^2, WGS-84 GM
EARTH_OMEGA = 7.2921151467e-5  # rad/s, WGS-84 rotation rate
EARTH_POLAR_RADIUS_M = 6.356752e6  # WGS-84 b: an osculating perigee below it is a trajectory into the ground
ORBIT_CHORD_RTOL = 0.1  # (p[k+1] - p[k]) / dt agrees with the mean velocity (when the arc is < 0.5 rad)
ORBIT_FRAMES = ("ECI", "ECEF", "LOCAL")
LOOK_SIDES = ("right", "left")


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
    #: the antenna, when the product knows it (radiometry, :mod:`sarcli.calibration.radiometry`): azimuth
    #: length and elevation height (m) of a uniformly illuminated aperture (0: uniform illumination, the
    #: pattern of a zero-size aperture), boresight look angle off the geodetic nadir (rad)
    antenna_length_m: float | None = None
    antenna_height_m: float | None = None
    antenna_look_angle_rad: float | None = None
    #: receiver noise E|n|^2 per complex echo sample (echo units), when the product states it
    noise_power: float | None = None

    def validate(self, where: str = "radar", n_samples: int | None = None) -> None:
        """Refuse (one :class:`ProductError` line) a missing, mistyped or physically implausible parameter.

        Checks: every parameter a finite number; PRF, sampling rate and carrier within the module's bounds;
        wavelength = c / carrier to 0.1 %; a non-zero chirp rate whose band |K| tau fits in the complex
        sampling rate; pulse and receive window (``n_samples`` / fs, when known) within one pulse interval
        (a monostatic radar cannot receive while it transmits); first_range_m = c window_start_s / 2.
        """
        w = f"{where}: radar"
        f0 = ck.number(w, "carrier_frequency_hz", self.carrier_frequency_hz, *CARRIER_HZ, unit="Hz")
        lam = ck.number(w, "wavelength_m", self.wavelength_m, lo=0.0, unit="m")
        if not abs(lam * f0 / C_LIGHT - 1.0) <= WAVELENGTH_RTOL:
            raise ProductError(f"{w}: wavelength_m {lam:.6g} m does not match the carrier {f0:.6g} Hz "
                               f"(c / f = {C_LIGHT / f0:.6g} m)")
        prf = ck.number(w, "prf_hz", self.prf_hz, *PRF_HZ, unit="Hz")
        fs = ck.number(w, "range_sampling_rate_hz", self.range_sampling_rate_hz, *SAMPLING_RATE_HZ, unit="Hz")
        k = ck.number(w, "chirp_rate_hz_per_s", self.chirp_rate_hz_per_s, unit="Hz/s")
        tau = ck.number(w, "pulse_length_s", self.pulse_length_s, lo=0.0, unit="s")
        if k == 0.0 or tau == 0.0:
            raise ProductError(f"{w}: chirp_rate_hz_per_s and pulse_length_s must be non-zero")
        window = 0.0 if n_samples is None else n_samples / fs
        if tau + window >= 1.0 / prf:
            raise ProductError(f"{w}: pulse ({tau * 1e6:.6g} us) plus receive window ({window * 1e6:.6g} us) "
                               f"exceed the pulse interval 1/PRF = {1e6 / prf:.6g} us")
        if abs(k) * tau > fs * (1.0 + 1e-9):
            raise ProductError(f"{w}: chirp band |K| tau = {abs(k) * tau / 1e6:.6g} MHz exceeds the sampling "
                               f"rate {fs / 1e6:.6g} MHz (the samples would alias)")
        ws = ck.number(w, "window_start_s", self.window_start_s, lo=0.0, hi=1.0, unit="s")
        r0 = ck.number(w, "first_range_m", self.first_range_m, *FIRST_RANGE_M, unit="m")
        if abs(r0 - C_LIGHT * ws / 2.0) > RANGE_WINDOW_RTOL * r0 + 1.0:
            raise ProductError(f"{w}: first_range_m {r0:.3f} m does not match window_start_s {ws:.9g} s "
                               f"(c t / 2 = {C_LIGHT * ws / 2.0:.3f} m)")
        ck.number(w, "quantization_bits", self.quantization_bits, *QUANTIZATION_BITS, integer=True)
        offsets = ck.array(w, "receiver_offsets_m", np.asarray(self.receiver_offsets_m), "f", ndim=1, min_size=1)
        if np.any(np.abs(offsets) > 1e3):
            raise ProductError(f"{w}: receiver_offsets_m {offsets.tolist()} are implausible (|offset| > 1 km)")
        if self.platform_velocity_mps is not None:
            ck.number(w, "platform_velocity_mps", self.platform_velocity_mps, *SPEED_MPS, unit="m/s")


@dataclass
class Orbit:
    """State vectors as delivered: times (s after the product epoch), positions (m), velocities (m/s)."""

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    frame: str

    def validate(self, where: str = "orbit") -> None:
        """Refuse state vectors that cannot describe a platform (one :class:`ProductError` line).

        At least two vectors, strictly increasing finite times, finite (n, 3) positions and velocities.
        Earth frames: every radius within ``EARTH_ORBIT_RADIUS_M`` of the Earth's centre, and the
        osculating orbit (inertial velocity, ECEF + w x r) bound (v^2 < 2 mu / r) with its perigee
        h^2 / (mu (1 + e)) above the ground. LOCAL: speeds within ``SPEED_MPS``. Both: the chord
        (p[k+1] - p[k]) / dt agrees with the mean of the two velocities within 10 % wherever the arc
        between them is below 0.5 rad (chord/tangent differ by ~ arc^2 / 6 there, < 4.2 %).
        """
        w = f"{where}: orbit"
        ck.text(w, "frame", self.frame, ORBIT_FRAMES)
        t = ck.array(w, "time", self.time, "f", ndim=1, min_size=2)
        n = t.shape[0]
        ck.increasing(w, "time", t)
        r = ck.array(w, "position", self.position, "f", shape=(n, 3)).astype(np.float64)
        v = ck.array(w, "velocity", self.velocity, "f", shape=(n, 3)).astype(np.float64)
        rad = np.linalg.norm(r, axis=1)
        speed = np.linalg.norm(v, axis=1)
        if self.frame == "LOCAL":
            bad = (speed < SPEED_MPS[0]) | (speed > SPEED_MPS[1])
            if bad.any():
                raise ProductError(f"{w}: platform speed {speed[bad][0]:.6g} m/s is implausible "
                                   f"(expected {SPEED_MPS[0]:g} .. {SPEED_MPS[1]:g} m/s)")
            arc = np.zeros(n - 1)
        else:
            lo, hi = EARTH_ORBIT_RADIUS_M
            bad = (rad < lo) | (rad > hi)
            if bad.any():
                raise ProductError(f"{w}: state vector radius {rad[bad][0]:.6g} m is not an Earth orbit "
                                   f"(expected {lo:g} .. {hi:g} m from the Earth's centre)")
            vi = v + np.cross([0.0, 0.0, EARTH_OMEGA], r) if self.frame == "ECEF" else v
            v2 = np.sum(vi * vi, axis=1)
            energy = v2 / 2.0 - EARTH_MU / rad
            h = np.linalg.norm(np.cross(r, vi), axis=1)
            ecc = np.sqrt(np.maximum(1.0 + 2.0 * energy * h**2 / EARTH_MU**2, 0.0))
            perigee = h**2 / (EARTH_MU * (1.0 + ecc))
            bad = (energy >= 0.0) | (perigee < EARTH_POLAR_RADIUS_M)
            if bad.any():
                k = int(np.argmax(bad))
                why = "unbound" if energy[k] >= 0 else "its perigee is below the ground"
                raise ProductError(f"{w}: velocity {np.sqrt(v2[k]):.6g} m/s at radius {rad[k]:.6g} m is not an "
                                   f"Earth orbit ({why})")
            arc = 0.5 * (speed[1:] + speed[:-1]) * np.diff(t) / rad[:-1]
        vmean = 0.5 * (v[1:] + v[:-1])
        chord = np.diff(r, axis=0) / np.diff(t)[:, None]
        err = np.linalg.norm(chord - vmean, axis=1) / np.maximum(np.linalg.norm(vmean, axis=1), SPEED_MPS[0])
        bad = (arc < 0.5) & ~(err <= ORBIT_CHORD_RTOL)
        if bad.any():
            k = int(np.argmax(bad))
            raise ProductError(f"{w}: positions and velocities disagree: between vectors {k} and {k + 1} the "
                               f"platform moves at {np.linalg.norm(chord[k]):.6g} m/s, its velocity says "
                               f"{np.linalg.norm(vmean[k]):.6g} m/s")


@dataclass
class Attitude:
    """Attitude angles (rad) at times (s after the product epoch)."""

    time: np.ndarray
    pitch: np.ndarray
    roll: np.ndarray
    yaw: np.ndarray

    def validate(self, where: str = "attitude") -> None:
        """Strictly increasing finite times; one finite angle per time for pitch, roll and yaw, |angle| <= pi."""
        w = f"{where}: attitude"
        t = ck.array(w, "time", self.time, "f", ndim=1, min_size=1)
        ck.increasing(w, "time", t)
        for name in ("pitch", "roll", "yaw"):
            a = ck.array(w, name, getattr(self, name), "f", shape=(t.shape[0],))
            if np.any(np.abs(a) > np.pi):
                raise ProductError(f"{w}: {name} exceeds pi rad in magnitude (angles are in radians)")


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
        return tuple(self.echo.shape)

    def validate(self, where: str = "raw product", n_samples: int | None = None, finite_samples: bool = True) -> None:
        """Refuse (one :class:`ProductError` line) anything a processor could not trust.

        ``n_samples``: the number of range samples when the echo is not loaded (an (n_lines, 0) echo, as
        ``read_raw(load_echo=False)`` returns it); then every check but the samples' finiteness runs, as
        it does with ``finite_samples=False``.
        Checks: the radar (:meth:`Radar.validate`); a complex (n_lines, n_samples) echo, finite when
        loaded; azimuth times finite, strictly increasing and on the pulse grid: each interval is 1/PRF
        (or 1/prf_per_line of its line) within ``AZIMUTH_TIME_RTOL``, or a whole number of them (lines
        missing from the recording and kept as a gap, ``sarcli ingest --missing keep``) with the median
        interval one pulse interval; an ISO-8601 epoch; per-line arrays
        (prf_per_line, agc_db) of one finite value per line; a finite 1-D replica; further channels
        shaped like the echo with one receiver offset per channel; the orbit and attitude.
        """
        e = self.echo
        loaded = n_samples is None and finite_samples
        ck.array(where, "echo", e, "c", ndim=2, finite=False)
        n_lines = e.shape[0]
        ns = e.shape[1] if n_samples is None else int(n_samples)
        if n_lines < 1 or ns < 1:
            raise ProductError(f"{where}: echo must be a non-empty 2-D array, got shape {(n_lines, ns)}")
        self.radar.validate(where, ns)
        t = ck.array(where, "azimuth_time", self.azimuth_time, "f", shape=(n_lines,))
        ck.increasing(where, "azimuth_time", t)
        ck.utc(where, "epoch_utc", self.epoch_utc)
        ck.text(where, "look_side", self.look_side, LOOK_SIDES)
        ck.text(where, "source", self.source)
        step: float | np.ndarray = 1.0 / self.radar.prf_hz
        if self.prf_per_line is not None:
            prf = ck.array(where, "prf_per_line", self.prf_per_line, "f", shape=(n_lines,))
            if np.any((prf < PRF_HZ[0]) | (prf > PRF_HZ[1])):
                raise ProductError(f"{where}: prf_per_line has implausible values (expected {PRF_HZ[0]:g} .. "
                                   f"{PRF_HZ[1]:g} Hz)")
            step = 1.0 / prf[:-1]
        ck.uniform(where, "azimuth_time", t, step, AZIMUTH_TIME_RTOL, gaps=True)
        if self.agc_db is not None:
            agc = ck.array(where, "radar/agc_db", self.agc_db, "f", shape=(n_lines,))
            if np.any((agc < AGC_DB[0]) | (agc > AGC_DB[1])):
                raise ProductError(f"{where}: radar/agc_db has implausible values (expected {AGC_DB[0]:g} .. "
                                   f"{AGC_DB[1]:g} dB)")
        if self.replica is not None:
            ck.array(where, "radar/replica", self.replica, "c", ndim=1, min_size=1)
        if self.echo_channels is not None:
            ck.array(where, "echo_channels", self.echo_channels, "c", shape=(None, n_lines, e.shape[1]),
                     finite=loaded)
        if len(self.radar.receiver_offsets_m) != self.n_channels:
            raise ProductError(f"{where}: radar.receiver_offsets_m has {len(self.radar.receiver_offsets_m)} "
                               f"value(s) for {self.n_channels} channel(s)")
        if loaded:
            ck.array(where, "echo", e, "c")
        if self.orbit is not None:
            self.orbit.validate(where)
        if self.attitude is not None:
            self.attitude.validate(where)

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
