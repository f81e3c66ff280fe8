"""Scene files (TOML) -> validated dataclasses for the stripmap simulator.

A scene lists radar, antenna, platform, targets, clutter patches and an explicit list of effects;
the simulator computes only the listed effects. Each table is parsed with :func:`sarcli.config.from_mapping`
into a frozen dataclass (``_RadarTable``, ...), then checked for finite numbers and ranges: every mistake
(unknown key, unknown effect, wrong type, impossible value) is a one-line :class:`sarcli.errors.ConfigError`
naming the file and the key (``scene.toml: radar.n_lines: must be an integer >= 1, got -3``).
Units: SI; angles in degrees in the file (``*_deg`` keys), radians in the dataclasses.
Times: seconds after ``scene.epoch_utc``; target azimuth times are relative to the scene centre.
See ``docs/simulate.md`` for the format with examples.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, TypeVar

import numpy as np

from orbit.propagate import Keplerian
from sarcli.config import from_mapping, load_toml
from sarcli.errors import ConfigError, ProductError
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import Radar

PLATFORM_TYPES = ("orbit", "state_vectors", "linear")
T = TypeVar("T")


def _numbers(v: Any) -> Iterable[float]:
    if isinstance(v, float):
        yield v
    elif isinstance(v, tuple | list):
        for x in v:
            yield from _numbers(x)


def table(cls: type[T], data: Any, where: str, positive: tuple[str, ...] = (), nonneg: tuple[str, ...] = (),
          at_least: Mapping[str, int] | None = None) -> T:
    """``cls`` from one TOML table (``where``: ``"file.toml: radar"``), with every number finite, the
    ``positive`` fields > 0, the ``nonneg`` fields >= 0 and the ``at_least`` integers >= their bound
    (``None``, "not given", passes)."""
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where} must be a table")
    obj = from_mapping(cls, data, where)
    for f in dataclasses.fields(obj):  # type: ignore[arg-type]
        v = getattr(obj, f.name)
        for x in _numbers(v):
            if not math.isfinite(x):
                raise ConfigError(f"{where}.{f.name}: expected a finite number, got {x!r}")
        if v is None:
            continue
        if f.name in positive and not v > 0:
            raise ConfigError(f"{where}.{f.name}: must be > 0, got {v!r}")
        if f.name in nonneg and not v >= 0:
            raise ConfigError(f"{where}.{f.name}: must be >= 0, got {v!r}")
        if at_least and f.name in at_least and v < at_least[f.name]:
            raise ConfigError(f"{where}.{f.name}: must be an integer >= {at_least[f.name]}, got {v!r}")
    return obj


# ---------------------------------------------------------------------------------------------------------
# The tables of a scene file, as written (SI units, degrees)


@dataclass(frozen=True, kw_only=True)
class _SceneTable:
    seed: int
    name: str | None = None
    epoch_utc: str = "2000-01-01T12:00:00Z"
    center_time_s: float = 0.0
    reference_height_m: float = 0.0
    clutter_model: Literal["binned", "exact"] = "binned"
    clutter_oversampling: int = 4
    effects: tuple[str, ...] = ()
    description: str = ""


@dataclass(frozen=True, kw_only=True)
class _RadarTable:
    carrier_frequency_hz: float
    prf_hz: float
    range_sampling_rate_hz: float
    chirp_rate_hz_per_s: float
    pulse_length_s: float
    n_lines: int
    n_samples: int
    window_start_s: float | None = None
    first_range_m: float | None = None
    look_side: Literal["right", "left"] = "right"


@dataclass(frozen=True, kw_only=True)
class _AntennaTable:
    length_m: float
    height_m: float
    look_angle_deg: float
    beam_extent: float = 1.0


@dataclass(frozen=True, kw_only=True)
class _OrbitTable:
    type: str
    semi_major_axis_m: float
    eccentricity: float
    inclination_deg: float
    raan_deg: float
    arg_perigee_deg: float
    mean_anomaly_deg: float


@dataclass(frozen=True, kw_only=True)
class _StateVectorTable:
    type: str
    frame: Literal["ECI", "ECEF"]
    time_s: tuple[float, ...]
    position_m: tuple[tuple[float, float, float], ...]
    velocity_mps: tuple[tuple[float, float, float], ...]


@dataclass(frozen=True, kw_only=True)
class _LinearTable:
    type: str
    velocity_mps: float
    height_m: float
    x_m: float = 0.0
    y_m: float = 0.0


@dataclass(frozen=True, kw_only=True)
class _LocalPlace:
    """A position on a linear-platform (flat-Earth LOCAL) scene."""

    x_m: float
    y_m: float
    z_m: float = 0.0


@dataclass(frozen=True, kw_only=True)
class _EarthPlace:
    """A position on an orbit scene: geodetic (lat_deg, lon_deg, height_m), or slant (slant_range_m at
    azimuth_time_s, height_m)."""

    lat_deg: float | None = None
    lon_deg: float | None = None
    slant_range_m: float | None = None
    azimuth_time_s: float = 0.0
    height_m: float = 0.0


@dataclass(frozen=True, kw_only=True)
class _LocalTarget(_LocalPlace):
    amplitude: float = 1.0
    phase_deg: float = 0.0
    vx_mps: float = 0.0
    vy_mps: float = 0.0


@dataclass(frozen=True, kw_only=True)
class _EarthTarget(_EarthPlace):
    amplitude: float = 1.0
    phase_deg: float = 0.0
    v_east_mps: float = 0.0
    v_north_mps: float = 0.0
    v_up_mps: float = 0.0


@dataclass(frozen=True, kw_only=True)
class _Patch:
    range_extent_m: float
    azimuth_extent_m: float
    sigma0_db: float
    density_per_m2: float


@dataclass(frozen=True, kw_only=True)
class _LocalClutter(_LocalPlace, _Patch):
    pass


@dataclass(frozen=True, kw_only=True)
class _EarthClutter(_EarthPlace, _Patch):
    pass


# ---------------------------------------------------------------------------------------------------------
# The validated scene


@dataclass(frozen=True)
class RadarConfig:
    """Radar timing and waveform. Pulse centred on its delay, transmitted phase +pi*K*t^2 (K signed)."""

    carrier_frequency_hz: float
    prf_hz: float
    range_sampling_rate_hz: float
    chirp_rate_hz_per_s: float
    pulse_length_s: float
    n_lines: int
    n_samples: int
    window_start_s: float  # two-way time of the first range sample after the pulse centre is sent
    look_side: str

    @property
    def wavelength_m(self) -> float:
        return C_LIGHT / self.carrier_frequency_hz

    @property
    def first_range_m(self) -> float:
        return self.window_start_s * C_LIGHT / 2.0

    def slant_range(self) -> np.ndarray:
        """Slant range (m) of every range sample."""
        return self.first_range_m + np.arange(self.n_samples) * C_LIGHT / (2.0 * self.range_sampling_rate_hz)


@dataclass(frozen=True)
class AntennaConfig:
    """Antenna: azimuth length, elevation height, boresight look angle from the nadir, beam extent.

    ``beam_extent`` is the processed half-width of the beam in units of the first null: pulses with
    |sin psi_az| > beam_extent * lam / length_m are not computed, and targets with
    |sin psi_el| > beam_extent * lam / height_m (e.g. on the other side of the track) stay dark.
    """

    length_m: float
    height_m: float
    look_angle_rad: float
    beam_extent: float


@dataclass(frozen=True)
class OrbitPlatform:
    """Keplerian osculating elements at the scene epoch, propagated with J2 (orbit.propagate)."""

    elements: Keplerian


@dataclass(frozen=True)
class StateVectorPlatform:
    """Explicit state vectors (the truth is their Hermite interpolation). Frame ECI or ECEF."""

    frame: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray


@dataclass(frozen=True)
class LinearPlatform:
    """Airborne straight flight in the LOCAL frame: position (x_m, y_m + v*t, height_m), t from the centre."""

    velocity_mps: float
    height_m: float
    x_m: float
    y_m: float


@dataclass(frozen=True)
class PointTarget:
    """One point target. ``where`` is ('geodetic', lat_deg, lon_deg, h), ('slant', range_m, az_time_s, h)
    or ('local', x, y, z); ``velocity`` (3,) m/s in ENU (orbit scenes) or LOCAL (linear scenes)."""

    where: tuple
    reflectivity: complex
    velocity: tuple[float, float, float]


@dataclass(frozen=True)
class ClutterPatch:
    """A rectangular clutter patch of random-phase scatterers with mean backscatter sigma0.

    Centre as for point targets ('slant' or 'geodetic' on orbits, 'local' on linear platforms);
    extents in metres on the ground (along the beam's ground range and along track)."""

    where: tuple
    range_extent_m: float
    azimuth_extent_m: float
    sigma0: float  # linear, m^2/m^2
    density_per_m2: float


@dataclass
class Scene:
    """A validated scene. ``effects`` in file order; ``effect_params`` holds each effect's parsed table."""

    path: str
    source_text: str
    name: str
    seed: int
    epoch_utc: str
    center_time_s: float
    effects: tuple[str, ...]
    effect_params: dict[str, Any]
    radar: RadarConfig
    antenna: AntennaConfig
    platform: OrbitPlatform | StateVectorPlatform | LinearPlatform
    targets: list[PointTarget] = field(default_factory=list)
    clutter: list[ClutterPatch] = field(default_factory=list)
    reference_height_m: float = 0.0
    clutter_model: str = "binned"
    clutter_oversampling: int = 4


def _radar(where: str, data: Any) -> RadarConfig:
    t = table(_RadarTable, data, where, positive=("carrier_frequency_hz", "prf_hz", "range_sampling_rate_hz",
                                                  "pulse_length_s", "window_start_s", "first_range_m"),
              at_least={"n_lines": 1, "n_samples": 1})
    if (t.window_start_s is None) == (t.first_range_m is None):
        raise ConfigError(f"{where}.window_start_s: give exactly one of window_start_s or first_range_m")
    if t.chirp_rate_hz_per_s == 0:
        raise ConfigError(f"{where}.chirp_rate_hz_per_s: must be non-zero (sign = chirp direction)")
    ws = t.window_start_s if t.window_start_s is not None else 2.0 * t.first_range_m / C_LIGHT
    try:  # the checks of a raw product (what the HDF5, CEOS and Level-0 outputs will hold), before simulating
        Radar(carrier_frequency_hz=t.carrier_frequency_hz, wavelength_m=C_LIGHT / t.carrier_frequency_hz,
              prf_hz=t.prf_hz, range_sampling_rate_hz=t.range_sampling_rate_hz,
              chirp_rate_hz_per_s=t.chirp_rate_hz_per_s, pulse_length_s=t.pulse_length_s, window_start_s=ws,
              first_range_m=C_LIGHT * ws / 2.0).validate(where, t.n_samples)
    except ProductError as e:
        raise ConfigError(str(e)) from None
    return RadarConfig(
        carrier_frequency_hz=t.carrier_frequency_hz, prf_hz=t.prf_hz, range_sampling_rate_hz=t.range_sampling_rate_hz,
        chirp_rate_hz_per_s=t.chirp_rate_hz_per_s, pulse_length_s=t.pulse_length_s, n_lines=t.n_lines,
        n_samples=t.n_samples,
        window_start_s=t.window_start_s if t.window_start_s is not None else 2.0 * t.first_range_m / C_LIGHT,
        look_side=t.look_side)


def _antenna(where: str, data: Any) -> AntennaConfig:
    t = table(_AntennaTable, data, where, positive=("length_m", "height_m", "beam_extent"))
    if not 0.0 < t.look_angle_deg < 90.0:
        raise ConfigError(f"{where}.look_angle_deg: must be in (0, 90) degrees, got {t.look_angle_deg!r}")
    return AntennaConfig(length_m=t.length_m, height_m=t.height_m, look_angle_rad=math.radians(t.look_angle_deg),
                         beam_extent=t.beam_extent)


def _platform(where: str, data: Any) -> OrbitPlatform | StateVectorPlatform | LinearPlatform:
    kind = data.get("type") if isinstance(data, Mapping) else None
    if kind is None:
        raise ConfigError(f"{where}: missing required option(s) type (one of {', '.join(PLATFORM_TYPES)})")
    if kind not in PLATFORM_TYPES:
        raise ConfigError(f"{where}.type: {kind!r} is not one of {', '.join(PLATFORM_TYPES)}")
    if kind == "orbit":
        o = table(_OrbitTable, data, where, positive=("semi_major_axis_m",), nonneg=("eccentricity",))
        if o.eccentricity >= 1:
            raise ConfigError(f"{where}.eccentricity: must be < 1 (closed orbit), got {o.eccentricity!r}")
        return OrbitPlatform(Keplerian(
            semi_major_axis_m=o.semi_major_axis_m, eccentricity=o.eccentricity,
            inclination_rad=math.radians(o.inclination_deg), raan_rad=math.radians(o.raan_deg),
            arg_perigee_rad=math.radians(o.arg_perigee_deg), mean_anomaly_rad=math.radians(o.mean_anomaly_deg)))
    if kind == "state_vectors":
        sv = table(_StateVectorTable, data, where)
        time = np.asarray(sv.time_s, np.float64)
        if not (len(time) == len(sv.position_m) == len(sv.velocity_mps)) or len(time) < 4:
            raise ConfigError(f"{where}.time_s: need >= 4 state vectors with as many positions and velocities")
        if not np.all(np.diff(time) > 0):
            raise ConfigError(f"{where}.time_s: times must be strictly increasing")
        return StateVectorPlatform(sv.frame, time, np.asarray(sv.position_m, np.float64).reshape(-1, 3),
                                   np.asarray(sv.velocity_mps, np.float64).reshape(-1, 3))
    lin = table(_LinearTable, data, where, positive=("velocity_mps", "height_m"))
    return LinearPlatform(lin.velocity_mps, lin.height_m, lin.x_m, lin.y_m)


def _place_kind(where: str, data: Any, linear: bool) -> None:
    """Refuse a position given in the other kind of scene's keys, saying which keys place it."""
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where} must be a table")
    if linear and ("lat_deg" in data or "slant_range_m" in data):
        raise ConfigError(f"{where}.x_m: a linear-platform scene places targets by x_m, y_m (z_m)")
    if not linear and "x_m" in data:
        raise ConfigError(f"{where}.x_m: orbit scenes place targets by lat_deg/lon_deg or slant_range_m/azimuth_time_s")


def _where(where: str, p: _LocalPlace | _EarthPlace) -> tuple:
    """Position spec of a target or patch centre: ('local', x, y, z), ('geodetic', lat, lon, h) or
    ('slant', range, azimuth time, h)."""
    if isinstance(p, _LocalPlace):
        return ("local", p.x_m, p.y_m, p.z_m)
    if p.lat_deg is not None or p.lon_deg is not None:
        if p.lat_deg is None or p.lon_deg is None:
            raise ConfigError(f"{where}: a geodetic position needs both lat_deg and lon_deg")
        return ("geodetic", p.lat_deg, p.lon_deg, p.height_m)
    if p.slant_range_m is None:
        raise ConfigError(f"{where}: missing required option(s) slant_range_m (or lat_deg and lon_deg)")
    return ("slant", p.slant_range_m, p.azimuth_time_s, p.height_m)


def _target(where: str, data: Any, linear: bool) -> PointTarget:
    _place_kind(where, data, linear)
    t = table(_LocalTarget if linear else _EarthTarget, data, where, positive=("slant_range_m",),
              nonneg=("amplitude",))
    amp, ph = t.amplitude, math.radians(t.phase_deg)
    vel = (t.vx_mps, t.vy_mps, 0.0) if isinstance(t, _LocalTarget) else (t.v_east_mps, t.v_north_mps, t.v_up_mps)
    return PointTarget(_where(where, t), complex(amp * math.cos(ph), amp * math.sin(ph)), vel)


def _clutter(where: str, data: Any, linear: bool) -> ClutterPatch:
    _place_kind(where, data, linear)
    c = table(_LocalClutter if linear else _EarthClutter, data, where,
              positive=("slant_range_m", "range_extent_m", "azimuth_extent_m", "density_per_m2"))
    return ClutterPatch(where=_where(where, c), range_extent_m=c.range_extent_m, azimuth_extent_m=c.azimuth_extent_m,
                        sigma0=10.0 ** (c.sigma0_db / 10.0), density_per_m2=c.density_per_m2)


def _array_of_tables(doc: Mapping[str, Any], key: str, src: str) -> list:
    v = doc.get(key, [])
    if not isinstance(v, list):
        raise ConfigError(f"{src}: {key} must be an array of tables ([[{key}]])")
    return v


def scene_from_mapping(doc: Mapping[str, Any], src: str = "<scene>", text: str = "") -> Scene:
    """Validate a parsed scene file (``doc``: its TOML; ``src`` names it in messages; ``text``: its source,
    kept in the product's truth)."""
    from orbit.timeutil import parse_utc
    from sarcli.sim.effects import known_effects, parse_effects  # registry; imported here to avoid a cycle

    for key in ("scene", "radar", "antenna", "platform"):
        if key not in doc:
            raise ConfigError(f"{src}: missing table [{key}]")
    known = {"scene", "radar", "antenna", "platform", "targets", "clutter", *known_effects()}
    unknown = sorted(set(doc) - known)
    if unknown:
        raise ConfigError(f"{src}: unknown table(s) {', '.join(unknown)}; known: scene, radar, antenna, platform, "
                          f"targets, clutter and the effect tables ({', '.join(known_effects())})")
    st = table(_SceneTable, doc["scene"], f"{src}: scene", at_least={"seed": 0, "clutter_oversampling": 2})
    try:
        parse_utc(st.epoch_utc)
    except ValueError as e:
        raise ConfigError(f"{src}: scene.epoch_utc: {e}") from None
    if len(set(st.effects)) != len(st.effects):
        raise ConfigError(f"{src}: scene.effects: an effect is listed twice")
    radar = _radar(f"{src}: radar", doc["radar"])
    antenna = _antenna(f"{src}: antenna", doc["antenna"])
    platform = _platform(f"{src}: platform", doc["platform"])
    linear = isinstance(platform, LinearPlatform)
    targets = [_target(f"{src}: targets[{i}]", x, linear) for i, x in enumerate(_array_of_tables(doc, "targets", src))]
    clutter = [_clutter(f"{src}: clutter[{i}]", x, linear)
               for i, x in enumerate(_array_of_tables(doc, "clutter", src))]
    if not targets and not clutter:
        raise ConfigError(f"{src}: the scene has no [[targets]] and no [[clutter]]")
    params = parse_effects(list(st.effects), doc, platform, src)
    return Scene(path=src, source_text=text, name=st.name if st.name is not None else Path(src).stem, seed=st.seed,
                 epoch_utc=st.epoch_utc, center_time_s=st.center_time_s, effects=tuple(st.effects),
                 effect_params=params, radar=radar, antenna=antenna, platform=platform, targets=targets,
                 clutter=clutter, reference_height_m=st.reference_height_m, clutter_model=st.clutter_model,
                 clutter_oversampling=st.clutter_oversampling)


def parse_scene(text: str, src: str = "<scene>") -> Scene:
    """Parse and validate scene TOML text."""
    import tomllib

    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{src}: not valid TOML ({e})") from None
    return scene_from_mapping(doc, src, text)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; every problem is one :class:`ConfigError` line."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{p}: no such file")
    doc = load_toml(p)
    return scene_from_mapping(doc, str(p), p.read_text(encoding="utf-8"))
