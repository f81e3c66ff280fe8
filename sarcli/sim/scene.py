"""Scene files (TOML) -> validated dataclasses for the stripmap simulator.

A scene lists radar, antenna, platform, targets, clutter patches and an explicit list of effects;
the simulator computes only the listed effects. Every mistake (unknown key, unknown effect, wrong
type, impossible value) is a one-line :class:`sarcli.errors.FormatError` naming the file and key.
Units: SI; angles in degrees in the file (``*_deg`` keys), radians in the dataclasses.
Times: seconds after ``scene.epoch_utc``; target azimuth times are relative to the scene centre.
See the README (section ``sarcli simulate``) for the format with examples.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from orbit.propagate import Keplerian
from sarcli.errors import ConfigError, FormatError
from sarcli.model.constants import C_LIGHT

PLATFORM_TYPES = ("orbit", "state_vectors", "linear")


class _Table:
    """Strict accessor for one TOML table: typed gets, and an error for keys nobody read."""

    def __init__(self, data: Any, where: str, src: str):
        if not isinstance(data, dict):
            raise FormatError(f"{src}: [{where}] must be a table")
        self.data, self.where, self.src, self.used = data, where, src, set()

    def err(self, key: str, msg: str) -> FormatError:
        return FormatError(f"{self.src}: [{self.where}] {key}: {msg}")

    def has(self, key: str) -> bool:
        return key in self.data

    def num(self, key: str, default: float | None = None, *, positive: bool = False,
            nonneg: bool = False) -> float:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.err(key, "required number is missing")
            return float(default)
        v = self.data[key]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise self.err(key, f"expected a finite number, got {v!r}")
        if positive and v <= 0:
            raise self.err(key, f"must be > 0, got {v!r}")
        if nonneg and v < 0:
            raise self.err(key, f"must be >= 0, got {v!r}")
        return float(v)

    def opt_num(self, key: str, **kw: Any) -> float | None:
        return self.num(key, **kw) if key in self.data else None

    def int(self, key: str, default: int | None = None, *, minimum: int = 1) -> int:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.err(key, "required integer is missing")
            return default
        v = self.data[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < minimum:
            raise self.err(key, f"expected an integer >= {minimum}, got {v!r}")
        return v

    def str(self, key: str, default: str | None = None, choices: tuple[str, ...] | None = None) -> str:
        self.used.add(key)
        if key not in self.data:
            if default is None:
                raise self.err(key, "required string is missing")
            return default
        v = self.data[key]
        if not isinstance(v, str):
            raise self.err(key, f"expected a string, got {v!r}")
        if choices is not None and v not in choices:
            raise self.err(key, f"{v!r} is not one of {', '.join(choices)}")
        return v

    def array(self, key: str, shape_tail: tuple[int, ...] = ()) -> np.ndarray:
        self.used.add(key)
        if key not in self.data:
            raise self.err(key, "required array is missing")
        try:
            a = np.asarray(self.data[key], dtype=np.float64)
        except (TypeError, ValueError):
            raise self.err(key, "expected an array of numbers") from None
        if a.ndim != 1 + len(shape_tail) or a.shape[1:] != shape_tail or not np.all(np.isfinite(a)):
            raise self.err(key, f"expected finite numbers of shape (n,{','.join(map(str, shape_tail))})")
        return a

    def sub(self, key: str) -> _Table | None:
        self.used.add(key)
        where = key if self.where == "" else f"{self.where}.{key}"
        return _Table(self.data[key], where, self.src) if key in self.data else None

    def finish(self) -> None:
        extra = sorted(set(self.data) - self.used)
        if extra:
            where = f"[{self.where}]" if self.where else "top level:"
            raise FormatError(f"{self.src}: {where} unknown key(s): {', '.join(extra)}")


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


def _radar(t: _Table) -> RadarConfig:
    fs = t.num("range_sampling_rate_hz", positive=True)
    ws = t.opt_num("window_start_s", positive=True)
    r0 = t.opt_num("first_range_m", positive=True)
    if (ws is None) == (r0 is None):
        raise t.err("window_start_s", "give exactly one of window_start_s or first_range_m")
    k = t.num("chirp_rate_hz_per_s")
    if k == 0:
        raise t.err("chirp_rate_hz_per_s", "must be non-zero (sign = chirp direction)")
    r = RadarConfig(
        carrier_frequency_hz=t.num("carrier_frequency_hz", positive=True),
        prf_hz=t.num("prf_hz", positive=True),
        range_sampling_rate_hz=fs,
        chirp_rate_hz_per_s=k,
        pulse_length_s=t.num("pulse_length_s", positive=True),
        n_lines=t.int("n_lines"),
        n_samples=t.int("n_samples"),
        window_start_s=ws if ws is not None else 2.0 * r0 / C_LIGHT,
        look_side=t.str("look_side", "right", ("right", "left")),
    )
    t.finish()
    return r


def _antenna(t: _Table) -> AntennaConfig:
    a = AntennaConfig(
        length_m=t.num("length_m", positive=True),
        height_m=t.num("height_m", positive=True),
        look_angle_rad=math.radians(t.num("look_angle_deg")),
        beam_extent=t.num("beam_extent", 1.0, positive=True),
    )
    if not 0.0 < a.look_angle_rad < math.pi / 2:
        raise t.err("look_angle_deg", "must be in (0, 90) degrees")
    t.finish()
    return a


def _platform(t: _Table) -> OrbitPlatform | StateVectorPlatform | LinearPlatform:
    kind = t.str("type", choices=PLATFORM_TYPES)
    if kind == "orbit":
        e = t.num("eccentricity", nonneg=True)
        if e >= 1:
            raise t.err("eccentricity", "must be < 1 (closed orbit)")
        p: Any = OrbitPlatform(Keplerian(
            semi_major_axis_m=t.num("semi_major_axis_m", positive=True), eccentricity=e,
            inclination_rad=math.radians(t.num("inclination_deg")),
            raan_rad=math.radians(t.num("raan_deg")),
            arg_perigee_rad=math.radians(t.num("arg_perigee_deg")),
            mean_anomaly_rad=math.radians(t.num("mean_anomaly_deg"))))
    elif kind == "state_vectors":
        time = t.array("time_s")
        p = StateVectorPlatform(t.str("frame", choices=("ECI", "ECEF")), time,
                                t.array("position_m", (3,)), t.array("velocity_mps", (3,)))
        if not (len(time) == len(p.position) == len(p.velocity)) or len(time) < 4:
            raise t.err("time_s", "need >= 4 state vectors with as many positions and velocities")
        if not np.all(np.diff(time) > 0):
            raise t.err("time_s", "times must be strictly increasing")
    else:
        p = LinearPlatform(t.num("velocity_mps", positive=True), t.num("height_m", positive=True),
                           t.num("x_m", 0.0), t.num("y_m", 0.0))
    t.finish()
    return p


def _where(t: _Table, linear: bool) -> tuple:
    """Position spec of a target or patch centre: geodetic, slant (range + azimuth time) or local."""
    if linear:
        if t.has("lat_deg") or t.has("slant_range_m"):
            raise t.err("x_m", "a linear-platform scene places targets by x_m, y_m (z_m)")
        return ("local", t.num("x_m"), t.num("y_m"), t.num("z_m", 0.0))
    if t.has("x_m"):
        raise t.err("x_m", "orbit scenes place targets by lat_deg/lon_deg or slant_range_m/azimuth_time_s")
    if t.has("lat_deg"):
        return ("geodetic", t.num("lat_deg"), t.num("lon_deg"), t.num("height_m", 0.0))
    return ("slant", t.num("slant_range_m", positive=True), t.num("azimuth_time_s", 0.0),
            t.num("height_m", 0.0))


def _target(t: _Table, linear: bool) -> PointTarget:
    where = _where(t, linear)
    amp = t.num("amplitude", 1.0, nonneg=True)
    ph = math.radians(t.num("phase_deg", 0.0))
    if linear:
        vel = (t.num("vx_mps", 0.0), t.num("vy_mps", 0.0), 0.0)
    else:
        vel = (t.num("v_east_mps", 0.0), t.num("v_north_mps", 0.0), t.num("v_up_mps", 0.0))
    t.finish()
    return PointTarget(where, complex(amp * math.cos(ph), amp * math.sin(ph)), vel)


def _clutter(t: _Table, linear: bool) -> ClutterPatch:
    c = ClutterPatch(
        where=_where(t, linear),
        range_extent_m=t.num("range_extent_m", positive=True),
        azimuth_extent_m=t.num("azimuth_extent_m", positive=True),
        sigma0=10.0 ** (t.num("sigma0_db") / 10.0),
        density_per_m2=t.num("density_per_m2", positive=True),
    )
    t.finish()
    return c


def parse_scene(text: str, src: str = "<scene>") -> Scene:
    """Parse and validate scene TOML text (see the module docstring)."""
    from sarcli.sim.effects import parse_effects  # registry; imported here to avoid a cycle

    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{src}: not valid TOML ({e})") from None
    root = _Table(doc, "", src)
    for key in ("scene", "radar", "antenna", "platform"):
        if key not in doc:
            raise FormatError(f"{src}: missing table [{key}]")
    st = root.sub("scene")
    assert st is not None
    seed = st.int("seed", minimum=0)
    name = st.str("name", Path(src).stem)
    epoch = st.str("epoch_utc", "2000-01-01T12:00:00Z")
    from orbit.timeutil import parse_utc
    try:
        parse_utc(epoch)
    except ValueError as e:
        raise st.err("epoch_utc", str(e)) from None
    center = st.num("center_time_s", 0.0)
    ref_h = st.num("reference_height_m", 0.0)
    clutter_model = st.str("clutter_model", "binned", ("binned", "exact"))
    clutter_q = st.int("clutter_oversampling", 4, minimum=2)
    st.used.add("effects")
    effects = st.data.get("effects", [])
    if not isinstance(effects, list) or not all(isinstance(x, str) for x in effects):
        raise st.err("effects", "expected a list of effect names")
    if len(set(effects)) != len(effects):
        raise st.err("effects", "an effect is listed twice")
    st.str("description", "")
    st.finish()
    radar = _radar(root.sub("radar"))  # type: ignore[arg-type]
    antenna = _antenna(root.sub("antenna"))  # type: ignore[arg-type]
    platform = _platform(root.sub("platform"))  # type: ignore[arg-type]
    linear = isinstance(platform, LinearPlatform)
    targets = [_target(_Table(x, f"targets.{i}", src), linear) for i, x in enumerate(_list(root, "targets"))]
    clutter = [_clutter(_Table(x, f"clutter.{i}", src), linear) for i, x in enumerate(_list(root, "clutter"))]
    if not targets and not clutter:
        raise FormatError(f"{src}: the scene has no [[targets]] and no [[clutter]]")
    params = parse_effects(effects, root, platform)
    root.finish()
    return Scene(path=src, source_text=text, name=name, seed=seed, epoch_utc=epoch, center_time_s=center,
                 effects=tuple(effects), effect_params=params, radar=radar, antenna=antenna,
                 platform=platform, targets=targets, clutter=clutter, reference_height_m=ref_h,
                 clutter_model=clutter_model, clutter_oversampling=clutter_q)


def _list(root: _Table, key: str) -> list:
    root.used.add(key)
    v = root.data.get(key, [])
    if not isinstance(v, list):
        raise FormatError(f"{root.src}: {key} must be an array of tables ([[{key}]])")
    return v


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; every problem is one :class:`FormatError` line."""
    p = Path(path)
    if not p.is_file():
        raise FormatError(f"{p}: scene file not found")
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise FormatError(f"{p}: cannot read scene file ({e.__class__.__name__})") from None
    return parse_scene(text, str(p))
