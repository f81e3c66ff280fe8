"""The acquisition configuration (``scan.toml``), command-line overrides and plan validation.

Everything that can be checked without touching an instrument is checked here, so that a bad
configuration gives one clear error before anything moves: frequency range (30 kHz..3 GHz, 6 GHz
with option 006), allowed points and IF bandwidths, power range, polarizations vs. switch,
rail travel within ``[0, max_travel_m]``. Units are SI (Hz, m, s, dBm); angles in degrees.

The file's tables (``[vna]``, ``[rail]``, ``[polarization]``, ``[site]``, ``[antenna]``) are the frozen
dataclasses below, read by the one configuration helper :func:`sarcli.config.from_mapping`: an
unknown table or key, or a value of the wrong type, is one :class:`~sarcli.errors.ConfigError` line
naming the file and the table (``scan.toml [vna]: unknown option(s) points_typo; known: ...``).
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.acquire import vna8753 as vna
from sarcli.acquire.motion import move_time
from sarcli.acquire.polswitch import SWITCH_KINDS
from sarcli.config import from_mapping, load_toml
from sarcli.errors import ConfigError
from sarcli.io.scan import POLARIZATIONS
from sarcli.model.gbsar import Antenna, Site


@dataclass(frozen=True)
class VnaConfig:
    start_hz: float = 5.2e9
    stop_hz: float = 5.4e9
    points: int = 201
    if_bandwidth_hz: float = 1000.0
    power_dbm: float = 0.0
    parameter: str = "S21"
    data_format: str = "FORM2"
    model: str = "8753ES"           # IDN? model field must match
    gpib_address: int = 16
    max_frequency_hz: float = vna.MAX_FREQUENCY_OPT006_HZ  # 3e9 without option 006
    read_timeout_ms: int = 500      # Prologix ++read_tmo_ms
    read_margin_s: float = 0.25     # host waits ++read_tmo_ms + this for the first byte (USB latency)
    data_timeout_s: float = 5.0     # extra time allowed for a whole data block
    opc_read_timeout_ms: int = 3000  # ++read_tmo_ms while waiting for OPC? after SING (<= 3000)
    retries: int = 3
    preset: bool = True


@dataclass(frozen=True)
class RailConfig:
    start_m: float = 0.0
    step_m: float = 0.05
    count: int = 21
    settle_s: float = 0.5
    feed_mm_min: float = 500.0
    accel_mm_s2: float = 10.0       # for the plan; the scan uses GRBL's $120
    max_travel_m: float = 2.0       # machine travel; checked again against GRBL's $130 at connection
    machine_zero_m: float = 0.0     # rail-frame position (m) of GRBL's X0: rail = X/1000 + zero
    height_m: float = 0.0           # antenna phase-centre height written to rail_height
    home: bool = False              # $H before the scan (needs $22=1)
    return_to_start: bool = False
    retries: int = 2
    timeout_s: float = 2.0

    def positions(self) -> np.ndarray:
        """Rail positions (m, rail frame) of the stops."""
        return self.start_m + self.step_m * np.arange(self.count)

    def machine_mm(self, position_m: float) -> float:
        """GRBL machine X (mm) of a rail-frame position, rounded to GRBL's 3 decimals."""
        return round((position_m - self.machine_zero_m) * 1000.0, 3)


@dataclass(frozen=True)
class PolConfig:
    polarizations: tuple[str, ...] = ("VV",)
    switch: str = "none"            # none | grbl | 11713a
    address: int = 28               # 11713A GPIB address
    settle_s: float = 0.05


@dataclass(frozen=True)
class ScanConfig:
    vna: VnaConfig = field(default_factory=VnaConfig)
    rail: RailConfig = field(default_factory=RailConfig)
    polarization: PolConfig = field(default_factory=PolConfig)
    site: Site = field(default_factory=Site)
    antenna: Antenna = field(default_factory=Antenna)

    def vna_settings(self) -> vna.VnaSettings:
        v = self.vna
        return vna.VnaSettings(v.start_hz, v.stop_hz, v.points, v.if_bandwidth_hz, v.power_dbm,
                               v.parameter, v.data_format)

    def identity(self) -> dict[str, Any]:
        """The settings that define the measurement; ``--resume`` requires them to match."""
        v, r = self.vna, self.rail
        return {"start_hz": float(v.start_hz), "stop_hz": float(v.stop_hz), "points": int(v.points),
                "if_bandwidth_hz": float(v.if_bandwidth_hz), "power_dbm": float(v.power_dbm),
                "parameter": v.parameter, "polarizations": ",".join(self.polarization.polarizations),
                "rail_start_m": float(r.start_m), "rail_step_m": float(r.step_m),
                "rail_count": int(r.count), "rail_height_m": float(r.height_m),
                "rail_machine_zero_m": float(r.machine_zero_m)}


_SECTIONS = {"vna": VnaConfig, "rail": RailConfig, "polarization": PolConfig, "site": Site,
             "antenna": Antenna}


def load_config(path: str | Path | None, overrides: dict[str, dict[str, Any]] | None = None) -> ScanConfig:
    """Read ``path`` (or defaults), apply ``overrides`` ({table: {key: value}}, None values ignored),
    check every table with :func:`sarcli.config.from_mapping`, then validate the plan."""
    source = str(path) if path is not None else "acquisition settings"
    data: dict[str, Any] = load_toml(path) if path is not None else {}
    for section, values in (overrides or {}).items():
        given = {k: v for k, v in values.items() if v is not None}
        if given and isinstance(data.setdefault(section, {}), dict):
            data[section].update(given)
    parts = {k: from_mapping(_SECTIONS[k], v, f"{source} [{k}]") if k in _SECTIONS else v for k, v in data.items()}
    cfg = from_mapping(ScanConfig, parts, source)
    validate(cfg)
    return cfg


def validate(cfg: ScanConfig, max_frequency_hz: float | None = None, max_travel_mm: float | None = None) -> None:
    """Raise ConfigError on the first problem. Instrument limits, once known, tighten the checks."""
    v, r, p = cfg.vna, cfg.rail, cfg.polarization
    fmax = min(v.max_frequency_hz, max_frequency_hz or math.inf)
    if not (vna.MIN_FREQUENCY_HZ <= v.start_hz < v.stop_hz <= fmax):
        raise ConfigError(f"frequency range {format_frequency(v.start_hz)}-{format_frequency(v.stop_hz)} is "
                          f"outside the 8753ES range {format_frequency(vna.MIN_FREQUENCY_HZ)}-"
                          f"{format_frequency(fmax)} (or start >= stop)")
    if v.points not in vna.ALLOWED_POINTS:
        raise ConfigError(f"points = {v.points} is not allowed; choose one of "
                          f"{', '.join(map(str, vna.ALLOWED_POINTS))}")
    if v.if_bandwidth_hz not in vna.ALLOWED_IFBW_HZ:
        raise ConfigError(f"IF bandwidth {v.if_bandwidth_hz:g} Hz is not allowed; choose one of "
                          f"{', '.join(map(str, vna.ALLOWED_IFBW_HZ))} Hz")
    lo, hi = vna.POWER_RANGE_DBM
    if not lo <= v.power_dbm <= hi:
        raise ConfigError(f"power {v.power_dbm:g} dBm is outside {lo:g}..{hi:g} dBm")
    if v.parameter not in vna.PARAMETERS:
        raise ConfigError(f"parameter '{v.parameter}' must be one of {', '.join(vna.PARAMETERS)}")
    if v.data_format not in vna.DATA_FORMATS:
        raise ConfigError(f"data_format '{v.data_format}' must be one of {', '.join(vna.DATA_FORMATS)}")
    if not 0 <= v.gpib_address <= 30 or not 0 <= p.address <= 30:
        raise ConfigError("GPIB addresses must be 0..30")
    if not (1 <= v.read_timeout_ms <= 3000 and 1 <= v.opc_read_timeout_ms <= 3000):
        raise ConfigError("vna.read_timeout_ms and opc_read_timeout_ms must be 1..3000 (Prologix limit)")
    if v.read_margin_s < 0:
        raise ConfigError("vna.read_margin_s must be >= 0")
    if v.retries < 0 or r.retries < 0:
        raise ConfigError("retries must be >= 0")
    pols = p.polarizations
    if not pols or any(q not in POLARIZATIONS for q in pols) or len(set(pols)) != len(pols):
        raise ConfigError(f"polarizations {','.join(pols)} must be distinct names from "
                          f"{', '.join(POLARIZATIONS)}")
    if p.switch not in SWITCH_KINDS:
        raise ConfigError(f"polarization switch '{p.switch}' must be one of {', '.join(SWITCH_KINDS)}")
    if p.switch == "none" and len(pols) > 1:
        raise ConfigError(f"{len(pols)} polarizations need a switch (polarization.switch = grbl or 11713a)")
    if r.count < 1 or not r.step_m > 0:
        raise ConfigError("rail.count must be >= 1 and rail.step_m > 0")
    if r.settle_s < 0 or r.feed_mm_min <= 0 or r.accel_mm_s2 <= 0:
        raise ConfigError("rail.settle_s must be >= 0, feed and acceleration > 0")
    lo_m = r.start_m - r.machine_zero_m
    hi_m = lo_m + r.step_m * (r.count - 1)
    travel = r.max_travel_m if max_travel_mm is None else min(r.max_travel_m, max_travel_mm / 1000.0)
    if lo_m < -1e-9 or hi_m > travel + 1e-9:
        raise ConfigError(f"rail travel {lo_m:g}..{hi_m:g} m (machine X) is beyond the limits 0..{travel:g} m")


@dataclass(frozen=True)
class PlanEstimate:
    n_stops: int
    n_sweeps: int
    sweep_s: float
    move_s: float
    duration_s: float
    travel_m: tuple[float, float]


def estimate(cfg: ScanConfig, remaining: int | None = None) -> PlanEstimate:
    """Duration of the scan (or of its ``remaining`` stops): sweeps + data + moves + settling."""
    v, r = cfg.vna, cfg.rail
    n = r.count if remaining is None else remaining
    n_pol = len(cfg.polarization.polarizations)
    sweep = vna.estimated_sweep_time(v.points, v.if_bandwidth_hz)
    bytes_per_point = 50 if v.data_format == "FORM4" else 2 * (4 if v.data_format == "FORM2" else 8)
    transfer = v.points * bytes_per_point / 50e3  # ~50 kB/s through GPIB + USB (uncertain, to verify on hardware)
    step_move = move_time(r.step_m * 1000.0, r.feed_mm_min / 60.0, r.accel_mm_s2)
    per_stop = n_pol * (sweep + transfer + (cfg.polarization.settle_s if n_pol > 1 else 0.0)) + step_move + r.settle_s
    end = r.start_m + r.step_m * (r.count - 1)
    return PlanEstimate(n, n * n_pol, sweep, step_move, n * per_stop, (r.start_m, end))


def to_attrs(cfg: ScanConfig) -> dict[str, Any]:
    """Flat JSON-able attributes for the scan file's /instrument group."""
    out: dict[str, Any] = {}
    for prefix, obj in (("vna", cfg.vna), ("rail", cfg.rail), ("pol", cfg.polarization)):  # file attribute names
        for k, val in asdict(obj).items():
            out[f"{prefix}_{k}"] = ",".join(val) if isinstance(val, tuple | list) else val
    return out


_FREQ_UNITS = {"": 1.0, "hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}
_TIME_UNITS = {"": 1.0, "s": 1.0, "m": 60.0, "min": 60.0, "h": 3600.0, "d": 86400.0}


def _quantity(text: str, units: dict[str, float], what: str) -> float:
    parts = re.findall(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z]*)", text.strip())
    joined = "".join(f"{n}{u}" for n, u in parts).replace(" ", "")
    if not parts or joined != text.strip().replace(" ", "") or any(u.lower() not in units for _, u in parts):
        raise ConfigError(f"cannot read {what} '{text}' (e.g. {'5.2GHz' if 'hz' in units else '30m, 1h30m'})")
    return sum(float(n) * units[u.lower()] for n, u in parts)


def parse_frequency(text: str) -> float:
    """'5.2GHz', '5200MHz' or '5.2e9' -> Hz."""
    return _quantity(text, _FREQ_UNITS, "frequency")


def format_frequency(hz: float) -> str:
    """30e3 -> '30 kHz', 6e9 -> '6 GHz', 5.2e9 -> '5.2 GHz' (largest unit with a value >= 1)."""
    for unit, scale in (("GHz", 1e9), ("MHz", 1e6), ("kHz", 1e3)):
        if abs(hz) >= scale:
            return f"{hz / scale:g} {unit}"
    return f"{hz:g} Hz"


def parse_duration(text: str) -> float:
    """'30m', '1h30m', '90s', '0' -> seconds."""
    return _quantity(text, _TIME_UNITS, "duration")
