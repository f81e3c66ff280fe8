"""The monitoring configuration (``monitor.toml``): acquisition, focusing, selection, atmosphere,
unwrapping, velocity windows, watch points, areas with alarm thresholds, forecast and page.

Layout (SI units except where a name says mm, h or dB; every table optional)::

    acquisition = "scan.toml"      the acquisition settings (path, relative to this file), or inline
    [acquisition.vna] ...          tables as in samples/scan.toml ([vna], [rail], [polarization], ...)
    meteo = "meteo.csv"            time_utc, temperature_c, humidity_percent, pressure_hpa
    [focus]                        sarcli.gbsar.focus.FocusOptions (algorithm, max_range_m, ...)
    [processing] pol, coherence_window
    [selection]  dynamic_range_db, amplitude_dispersion, coherence, min_scans_dispersion, increment_coherence
    [aps]        dem (GeoTIFF), stable_velocity_mm_per_h, stable_coherence, min_stable_points, huber_k
    [unwrap]     reliable_coherence, max_implausible_fraction, min_scan_coherence, spatial,
                 max_velocity_mm_per_h
    [velocity]   window_scans, acceleration_window_scans
    [forecast]   window_scans, velocity_window_scans, min_velocity_mm_per_h, min_r2
    [page]       refresh_s, title
    [[watch]]    name, azimuth_m + range_m (image geometry) or x_m + y_m (+ z_m) (site frame), radius_m
    [[areas]]    name, polygon = [[a, b], ...] (frame "image": azimuth, range; "site": x, y) or
                 mask = "file.npy" (bool, the image grid), stable, velocity_mm_per_h = [attention,
                 pre-alarm, alarm], acceleration_mm_per_h2 = [...], hysteresis, clear_scans

A file that holds ``[vna]``/``[rail]``/... at its top level is an acquisition file: it is taken as the
``acquisition`` of a default configuration (``gbsar monitor -c scan.toml`` works). Every table goes
through :func:`sarcli.config.from_mapping` (unknown keys and wrong types are one line naming the table).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from sarcli.config import from_mapping, load_toml, to_mapping
from sarcli.errors import ConfigError
from sarcli.gbsar.focus import FocusOptions

LEVELS = ("none", "attention", "pre-alarm", "alarm")
_ACQUISITION_TABLES = ("vna", "rail", "polarization", "site", "antenna")


@dataclass(frozen=True)
class ProcessingSection:
    """``pol``: the polarization monitored (default: the first scan's first); ``coherence_window``:
    boxcar size (pixels) of the coherence between consecutive scans."""

    pol: str | None = None
    coherence_window: int = 5

    def __post_init__(self) -> None:
        if self.coherence_window < 1:
            raise ConfigError("[processing] coherence_window must be >= 1")


@dataclass(frozen=True)
class SelectionSection:
    """Points measured: pixels within ``dynamic_range_db`` of the brightest mean amplitude that are
    persistent scatterers (amplitude dispersion ``sigma_A/mu_A <= amplitude_dispersion`` after at least
    ``min_scans_dispersion`` scans [Ferretti2001]) or distributed scatterers (mean coherence between
    consecutive scans >= ``coherence``), and whose own phase follows the prediction from scan to scan:
    the mean of ``cos r`` over the increments (r: the part of an increment the APS and the point's
    velocity do not explain) >= ``increment_coherence`` (for Gaussian r of standard deviation s, the
    mean is exp(-s^2/2): 0.95 keeps s <= 0.32 rad, 1.4 mm of LOS at 5.3 GHz, per increment)."""

    dynamic_range_db: float = 30.0
    amplitude_dispersion: float = 0.25
    coherence: float = 0.8
    min_scans_dispersion: int = 4
    increment_coherence: float = 0.95

    def __post_init__(self) -> None:
        if not (self.dynamic_range_db > 0 and self.amplitude_dispersion > 0 and 0 < self.coherence <= 1
                and self.min_scans_dispersion >= 2 and 0 <= self.increment_coherence <= 1):
            raise ConfigError("[selection] needs dynamic_range_db > 0, amplitude_dispersion > 0, coherence and "
                              "increment_coherence in [0, 1] and min_scans_dispersion >= 2")


@dataclass(frozen=True)
class ApsSection:
    """Atmospheric phase screen: model ``a + b R`` (``+ c R (z - h)`` with a DEM: heights z of the pixels,
    h the antenna's) fitted robustly (Huber, ``huber_k`` robust sigmas) on stable points: the areas
    marked ``stable`` or, without any, the selected points with ``|v| <= stable_velocity_mm_per_h`` and
    mean coherence >= ``stable_coherence``. Fewer than ``min_stable_points``: a constant only."""

    dem: Path | None = None
    stable_velocity_mm_per_h: float = 0.3
    stable_coherence: float = 0.9
    min_stable_points: int = 20
    huber_k: float = 1.345

    def __post_init__(self) -> None:
        if not (self.stable_velocity_mm_per_h > 0 and 0 < self.stable_coherence <= 1 and self.min_stable_points >= 3
                and self.huber_k > 0):
            raise ConfigError("[aps] needs stable_velocity_mm_per_h > 0, stable_coherence in (0, 1], "
                              "min_stable_points >= 3 and huber_k > 0")


@dataclass(frozen=True)
class UnwrapSection:
    """Temporal unwrapping between consecutive scans around a prediction (APS increment + each point's
    velocity). A scan is rejected when the median coherence of the points is below
    ``min_scan_coherence``, or when more than ``max_implausible_fraction`` of the reliable points
    (coherence >= ``reliable_coherence``) jump by more than a quarter cycle off the prediction (an
    implied velocity beyond lam/8 per interval) and spatial unwrapping (``spatial``) cannot explain the
    jump within ``max_velocity_mm_per_h``."""

    reliable_coherence: float = 0.7
    max_implausible_fraction: float = 0.1
    min_scan_coherence: float = 0.4
    spatial: bool = True
    max_velocity_mm_per_h: float = 100.0

    def __post_init__(self) -> None:
        if not (0 < self.reliable_coherence <= 1 and 0 <= self.max_implausible_fraction < 1
                and 0 <= self.min_scan_coherence <= 1 and self.max_velocity_mm_per_h > 0):
            raise ConfigError("[unwrap] needs reliable_coherence in (0, 1], max_implausible_fraction in [0, 1), "
                              "min_scan_coherence in [0, 1] and max_velocity_mm_per_h > 0")


@dataclass(frozen=True)
class VelocitySection:
    """Least-squares windows (in scans): the velocity is the slope over the last ``window_scans``
    accepted scans, the acceleration twice the quadratic term over ``acceleration_window_scans``. An
    area's velocity (what its alarms compare) is brought from the slope window's mean time to the scan's
    time with the area's acceleration, ``v + a (t_k - mean t)``, so that it does not lag by half a window."""

    window_scans: int = 3
    acceleration_window_scans: int = 8

    def __post_init__(self) -> None:
        if self.window_scans < 2 or self.acceleration_window_scans < 3:
            raise ConfigError("[velocity] needs window_scans >= 2 and acceleration_window_scans >= 3")


@dataclass(frozen=True)
class ForecastSection:
    """Inverse-velocity forecast of an area [Fukuzono1985]: each scan gives a velocity sample (the median
    over the area's points of the slope over the last ``velocity_window_scans`` scans, placed at the
    window's mean time); the acceleration persists when over the last ``window_scans`` samples every
    ``|v| >= min_velocity_mm_per_h`` and a straight line fitted to 1/v falls (slope < 0) with
    ``r^2 >= min_r2``; the line's zero is the forecast failure time."""

    window_scans: int = 12
    velocity_window_scans: int = 6
    min_velocity_mm_per_h: float = 0.2
    min_r2: float = 0.7

    def __post_init__(self) -> None:
        if not (self.window_scans >= 4 and self.velocity_window_scans >= 2 and self.min_velocity_mm_per_h > 0
                and 0 <= self.min_r2 <= 1):
            raise ConfigError("[forecast] needs window_scans >= 4, velocity_window_scans >= 2, "
                              "min_velocity_mm_per_h > 0 and min_r2 in [0, 1]")


@dataclass(frozen=True)
class PageSection:
    """The live page: reloads itself every ``refresh_s`` seconds; ``title`` (default: the folder name)."""

    refresh_s: float = 60.0
    title: str = ""

    def __post_init__(self) -> None:
        if not self.refresh_s > 0:
            raise ConfigError("[page] refresh_s must be > 0")


@dataclass(frozen=True)
class WatchPoint:
    """A named point whose displacement is reported every scan: image geometry (``azimuth_m``,
    ``range_m``) or the site frame (``x_m`` along the rail, ``y_m`` across, ``z_m`` up; R0 =
    sqrt(y^2 + (z - h)^2)); the brightest pixel (first scan) within ``radius_m`` is used."""

    name: str
    azimuth_m: float | None = None
    range_m: float | None = None
    x_m: float | None = None
    y_m: float | None = None
    z_m: float = 0.0
    radius_m: float = 1.0

    def __post_init__(self) -> None:
        image = self.azimuth_m is not None and self.range_m is not None
        site = self.x_m is not None and self.y_m is not None
        if image == site:
            raise ConfigError(f"[[watch]] {self.name}: give azimuth_m and range_m, or x_m and y_m")
        if not self.radius_m >= 0:
            raise ConfigError(f"[[watch]] {self.name}: radius_m must be >= 0")


Triple = tuple[float, float, float]


@dataclass(frozen=True)
class AreaEntry:
    """An area of interest (module docstring); thresholds are ``[attention, pre-alarm, alarm]``,
    increasing; ``hysteresis``: a level is left only after ``clear_scans`` consecutive scans below its
    thresholds times ``1 - hysteresis``."""

    name: str
    polygon: tuple[tuple[float, float], ...] | None = None
    frame: Literal["image", "site"] = "image"
    mask: Path | None = None
    stable: bool = False
    velocity_mm_per_h: Triple | None = None
    acceleration_mm_per_h2: Triple | None = None
    hysteresis: float = 0.2
    clear_scans: int = 3

    def __post_init__(self) -> None:
        if (self.polygon is None) == (self.mask is None):
            raise ConfigError(f"[[areas]] {self.name}: give a polygon or a mask")
        if self.polygon is not None and len(self.polygon) < 3:
            raise ConfigError(f"[[areas]] {self.name}: a polygon needs at least 3 vertices")
        for what in (self.velocity_mm_per_h, self.acceleration_mm_per_h2):
            if what is not None and not (0 < what[0] <= what[1] <= what[2] and all(map(math.isfinite, what))):
                raise ConfigError(f"[[areas]] {self.name}: thresholds are [attention, pre-alarm, alarm], "
                                  "positive and increasing")
        if not (0 <= self.hysteresis < 1 and self.clear_scans >= 1):
            raise ConfigError(f"[[areas]] {self.name}: hysteresis in [0, 1) and clear_scans >= 1")


@dataclass(frozen=True)
class MonitorConfig:
    """The whole campaign configuration (module docstring); ``acquisition`` is the mapping of the scan
    tables (checked by :func:`sarcli.acquire.config.load_config` when the monitor acquires)."""

    acquisition: dict[str, Any] = field(default_factory=dict)
    meteo: Path | None = None
    focus: FocusOptions = field(default_factory=FocusOptions)
    processing: ProcessingSection = field(default_factory=ProcessingSection)
    selection: SelectionSection = field(default_factory=SelectionSection)
    aps: ApsSection = field(default_factory=ApsSection)
    unwrap: UnwrapSection = field(default_factory=UnwrapSection)
    velocity: VelocitySection = field(default_factory=VelocitySection)
    forecast: ForecastSection = field(default_factory=ForecastSection)
    page: PageSection = field(default_factory=PageSection)
    watch: tuple[WatchPoint, ...] = ()
    areas: tuple[AreaEntry, ...] = ()

    def __post_init__(self) -> None:
        names = [w.name for w in self.watch] + [a.name for a in self.areas]
        bad = [n for n in names if not n or any(ch in n for ch in ',"\n\r')]
        if bad:
            raise ConfigError(f"watch point and area names must be non-empty, without commas, quotes or line "
                              f"breaks: {bad!r}")
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ConfigError(f"watch point and area names must be distinct: {', '.join(dup)}")

    def to_mapping(self) -> dict[str, Any]:
        return to_mapping(self)


def _resolve(base: Path, value: Any) -> Any:
    return str((base / value).resolve()) if isinstance(value, str) else value


def parse_monitor_config(doc: dict[str, Any], source: str = "monitor.toml", base: Path | None = None) -> MonitorConfig:
    """Check a parsed monitoring TOML; relative paths are resolved against ``base`` (the file's folder)."""
    if not isinstance(doc, dict):
        raise ConfigError(f"{source}: expected a table")
    base = base or Path(".")
    doc = dict(doc)
    if any(k in doc for k in _ACQUISITION_TABLES):
        doc = {"acquisition": doc}
    acq = doc.get("acquisition", {})
    if isinstance(acq, str):
        acq = load_toml(base / acq)
    if not isinstance(acq, dict):
        raise ConfigError(f"{source}: acquisition is a file name or a table of scan settings")
    doc["acquisition"] = acq
    if "meteo" in doc:
        doc["meteo"] = _resolve(base, doc["meteo"])
    if isinstance(doc.get("aps"), dict) and "dem" in doc["aps"]:
        doc["aps"] = {**doc["aps"], "dem": _resolve(base, doc["aps"]["dem"])}
    if isinstance(doc.get("areas"), list):
        doc["areas"] = [{**a, "mask": _resolve(base, a["mask"])} if isinstance(a, dict) and "mask" in a else a
                        for a in doc["areas"]]
    return from_mapping(MonitorConfig, doc, source)


def load_monitor_config(path: str | Path) -> MonitorConfig:
    """Read and check ``monitor.toml`` (or an acquisition TOML, see the module docstring)."""
    p = Path(path)
    return parse_monitor_config(load_toml(p), str(p), p.resolve().parent)
