"""GB-SAR scene description (TOML) -> :class:`Scene`, the scatterers realised once per scan.

A scene lists the VNA sweep, the rail, the antenna, the site and the scatterers; only the effects
listed under ``[effects.<name>]`` are computed. Layout (SI units, degrees only where named ``_deg``)::

    [scene]    name, seed (per-acquisition randomness: noise, decorrelation), epoch_utc
    [sweep]    center_frequency_hz, bandwidth_hz, points, polarizations = ["VV", ...]
    [rail]     length_m + step_m (stops centred on x = 0) or positions_m = [...];
               height_m (antenna phase-centre height z), stop_duration_s
    [antenna]  length_azimuth_m (L_x), length_range_m (L_R), gain_dbi, depression_deg,
               pattern = "sinc" | "rect" (used only with the antenna_pattern effect)
    [site]     latitude_deg, longitude_deg, height_m (of the local origin z = 0),
               heading_deg (rail direction, clockwise from north), look_side = "right" | "left"
    [processing]  optional: max_range_m (image extent used by `plan` for N_xfft of RD)
    [[points]] x_m, y_m, z_m (default 0), scattering, stable (default true), displacement_mm = [dx, dy, dz]
               or los_displacement_mm (along the line of sight from the rail centre, + = away)
    [[walls]]  start_m = [x, y, z], end_m = [x, y, z], spacing_m, scattering, stable
    [clutter]  x_m = [min, max], y_m = [min, max], z_m, density_per_m2, scattering, seed
    [[zones]]  name, x_m = [min, max], y_m = [min, max], z_m (at y_min), dz_dy (slope), density_per_m2,
               scattering, seed, stable (default true), motion: a seeded Poisson field of scatterers that
               move together (a landslide body, a rock face, a bench of a mine wall)
    motion     on [[points]], [[walls]], [[zones]]: ``{law = "linear" | "failure", velocity_mm_per_h,
               onset_h, failure_h}``, LOS displacement in time (:class:`MotionLaw`), used by
               :func:`scene_at` (a scene realised at a time after its epoch)
    [effects.antenna_pattern] {}            two-way pattern of the L_x x L_R aperture
    [effects.noise] power_db                complex white noise power per S21 sample (dB re 1)
    [effects.vertical_baseline] offset_m    added to every rail height
    [effects.frequency_shift] shift_hz      added to every sweep frequency
    [effects.displacement] scale            target displacements applied (times scale)
    [effects.decorrelation] coherence       unstable scatterers (clutter and stable = false)
    [effects.atmosphere] refractivity_ppm   extra path (N * 1e-6) * R: a range-proportional phase;
                            in time (:func:`scene_at`): drift_ppm_per_h, diurnal_ppm / diurnal_period_h /
                            diurnal_phase_deg, a vertical gradient gradient_ppm_per_m (+ its drift
                            gradient_drift_ppm_per_m_per_h) and a turbulent screen turbulence_mm /
                            turbulence_scale_m / seed (:class:`AtmosphereEffect`)

**Time** (the monitoring emulator, :func:`scene_at`): the scene at ``t`` seconds after its epoch, scan
``index``: targets displaced along their line of sight by their :class:`MotionLaw`, the atmosphere's
refractivity ``N(t)``, its vertical gradient and a new turbulent screen, and every per-acquisition
random draw (noise, decorrelation of unstable scatterers) from a seed derived from (seed, index), so
vegetation decorrelates from scan to scan. ``scene_at(scene, 0, 0)`` is the scene as loaded.

``scattering`` is a table ``{VV = a, VH = a, HV = a, HH = a}`` whose values are a real number or a
``[re, im]`` pair (missing channels are 0), or a single value/pair meaning VV = HH = value.

Each table is a frozen dataclass below (:class:`SceneFile` and its sections), checked by the one
configuration helper :func:`sarcli.config.from_mapping`: an unknown key or a value of the wrong type
is one :class:`~sarcli.errors.ConfigError` line naming the file and the table
(``scene.toml [rail]: unknown option(s) lenght_m; known: ...``).
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sarcli.config import from_mapping, load_toml
from sarcli.errors import ConfigError, SarcliError
from sarcli.io.scan import POLARIZATIONS
from sarcli.memory import fits_in_memory
from sarcli.model.constants import C_LIGHT
from sarcli.model.gbsar import RAIL_SPAN_M, Antenna, Site

KIND_POINT, KIND_WALL, KIND_CLUTTER, KIND_ZONE = 0, 1, 2, 3


@dataclass
class Scatterers:
    """Realised scatterers: positions (n, 3) m in the local frame, reflectivity (4, n) complex128
    in the order VV, VH, HV, HH, kind (n,) (0 point, 1 wall, 2 clutter), the displacement applied
    (n, 3) m and its line-of-sight component (n,) m (+ = away from the rail centre)."""

    position: np.ndarray
    reflectivity: np.ndarray
    kind: np.ndarray
    displacement: np.ndarray
    los_displacement: np.ndarray
    group: np.ndarray | None = None  # (n,) index into Scene.groups, -1 for clutter
    atmosphere_m: np.ndarray | None = None  # (n,) apparent one-way path (m) of the stratified + turbulent atmosphere


@dataclass(frozen=True)
class MotionLaw:
    """``motion = {...}``: the line-of-sight displacement ``d(t)`` of a target (mm, + = away from the
    rail centre, the convention of ``los_displacement_mm``) at ``t`` hours after the scene's epoch.

    ``law = "linear"``: steady creep, ``d = v t`` with ``v = velocity_mm_per_h``.
    ``law = "failure"``: creep at ``v0 = velocity_mm_per_h`` until ``onset_h`` (t_a), then the
    accelerating phase that ends in failure at ``failure_h`` (t_f), with an inverse velocity falling
    linearly to zero (Fukuzono's law with alpha = 2 [Fukuzono1985], [Voight1988]):
    ``1/v(t) = (1/v0) (t_f - t)/(t_f - t_a)``, hence
    ``d(t) = v0 t_a + v0 (t_f - t_a) ln((t_f - t_a)/(t_f - t))`` for ``t_a <= t < t_f``. At and after
    ``t_f`` the target has collapsed: its scatterers decorrelate completely (fresh reflectivities every
    scan) and ``d`` stays at its value one minute before ``t_f``.
    """

    law: Literal["linear", "failure"] = "linear"
    velocity_mm_per_h: float = 0.0
    onset_h: float = 0.0
    failure_h: float | None = None

    def __post_init__(self) -> None:
        if self.law == "failure":
            if self.failure_h is None or not self.failure_h > self.onset_h >= 0 or not self.velocity_mm_per_h != 0:
                raise ConfigError("motion law 'failure' needs 0 <= onset_h < failure_h and velocity_mm_per_h != 0")

    def failed(self, t_h: float) -> bool:
        return self.law == "failure" and self.failure_h is not None and t_h >= self.failure_h

    def displacement_mm(self, t_h: float) -> float:
        v0 = self.velocity_mm_per_h
        if self.law == "linear" or self.failure_h is None:
            return v0 * t_h
        ta, tf = self.onset_h, self.failure_h
        t = min(t_h, tf - 1.0 / 60.0)
        if t <= ta:
            return v0 * t
        return v0 * ta + v0 * (tf - ta) * float(np.log((tf - ta) / (tf - t)))

    def velocity_mm_per_h_at(self, t_h: float) -> float:
        v0 = self.velocity_mm_per_h
        if self.law == "linear" or self.failure_h is None or t_h <= self.onset_h:
            return v0
        tf = self.failure_h
        return v0 * (tf - self.onset_h) / (tf - min(t_h, tf - 1.0 / 60.0))


@dataclass
class TargetGroup:
    """One ``[[points]]``, ``[[walls]]`` or ``[[zones]]`` entry of a realised scene: its name (default
    ``points-0``, ``zones-1``, ...), kind, stability and motion law."""

    name: str
    kind: int
    stable: bool
    motion: MotionLaw | None


@dataclass
class Scene:
    name: str
    seed: int
    epoch_utc: str
    center_frequency_hz: float
    bandwidth_hz: float
    points: int
    polarizations: tuple[str, ...]
    positions_m: np.ndarray
    height_m: float
    stop_duration_s: float
    antenna: Antenna
    depression_rad: float
    pattern: str
    site: Site
    scatterers: Scatterers
    effects: dict[str, dict[str, float]]
    processing: dict[str, Any] = field(default_factory=dict)
    source_toml: str = ""
    file: SceneFile | None = None  # the checked TOML document (to realise the scene at another time)
    groups: list[TargetGroup] = field(default_factory=list)
    time_s: float = 0.0  # seconds after epoch_utc this realisation stands for (scene_at)
    scan_index: int = 0

    @property
    def wavelength_m(self) -> float:
        return C_LIGHT / self.center_frequency_hz

    def frequencies(self) -> np.ndarray:
        """Sweep frequencies (Hz), with the frequency_shift effect applied when listed."""
        shift = self.effects.get("frequency_shift", {}).get("shift_hz", 0.0)
        f0 = self.center_frequency_hz - self.bandwidth_hz / 2
        if self.points == 1:
            return np.array([self.center_frequency_hz + shift])
        return f0 + shift + self.bandwidth_hz * np.arange(self.points) / (self.points - 1)

    def rail_heights(self) -> np.ndarray:
        """Antenna height of every stop (m), with the vertical_baseline effect applied when listed."""
        off = self.effects.get("vertical_baseline", {}).get("offset_m", 0.0)
        return np.full(self.positions_m.shape, self.height_m + off)

    def stop_times(self) -> np.ndarray:
        return self.stop_duration_s * np.arange(self.positions_m.size, dtype=np.float64)


@dataclass(frozen=True)
class SceneSection:
    """``[scene]``: name, per-acquisition seed (noise, decorrelation), epoch (ISO-8601 UTC)."""

    name: str = "gbsar"
    seed: int = 0
    epoch_utc: str = "2000-01-01T00:00:00Z"


@dataclass(frozen=True)
class SweepSection:
    """``[sweep]``: the VNA sweep (Hz) and the polarizations (TX letter, RX letter)."""

    center_frequency_hz: float
    points: int
    bandwidth_hz: float = 0.0
    polarizations: tuple[str, ...] = ("VV",)

    def __post_init__(self) -> None:
        fc, bw, n = self.center_frequency_hz, self.bandwidth_hz, self.points
        if not (fc > 0 and bw >= 0 and n >= 1 and (n == 1 or bw > 0)) or not np.isfinite([fc, bw]).all():
            raise ConfigError("[sweep] needs center_frequency_hz > 0, points >= 1 and bandwidth_hz > 0")
        if fc - bw / 2 <= 0:
            raise ConfigError("[sweep] the sweep would reach zero or negative frequencies")
        pols = tuple(p.upper() for p in self.polarizations)
        if not pols or any(p not in POLARIZATIONS for p in pols) or len(set(pols)) != len(pols):
            raise ConfigError(f"[sweep] polarizations must be distinct names among {POLARIZATIONS}")
        object.__setattr__(self, "polarizations", pols)


@dataclass(frozen=True)
class RailSection:
    """``[rail]``: ``length_m`` + ``step_m`` (stops centred on x = 0) or ``positions_m``; antenna height (m)."""

    length_m: float | None = None
    step_m: float | None = None
    positions_m: tuple[float, ...] | None = None
    height_m: float = 0.0
    stop_duration_s: float = 1.0

    def positions(self) -> np.ndarray:
        if self.positions_m is not None:
            pos = np.asarray(self.positions_m, np.float64)
        else:
            if self.length_m is None or self.step_m is None:
                raise ConfigError("[rail] needs length_m and step_m, or positions_m")
            if not (self.step_m > 0 and self.length_m >= 0):
                raise ConfigError("[rail] needs step_m > 0 and length_m >= 0")
            if not self.length_m <= RAIL_SPAN_M:  # the scan it makes would be refused (sarcli.model.gbsar)
                raise ConfigError(f"[rail] length_m = {self.length_m:g} m: a ground-based rail is at most "
                                  f"{RAIL_SPAN_M:g} m long")
            n_stops = self.length_m / self.step_m + 1
            fits_in_memory(f"[rail] {n_stops:.4g} stops", n_stops * 64.0)  # positions, heights, times, S21 rows
            n = int(round(self.length_m / self.step_m)) + 1  # N_x = X/dx + 1 (Table 1 prints "- 1", a typo)
            pos = (np.arange(n) - (n - 1) / 2) * self.step_m
        if pos.size < 1 or not np.all(np.isfinite(pos)):
            raise ConfigError("[rail] positions must be a non-empty list of finite numbers")
        if pos.size > 1 and not np.all(np.diff(pos) > 0):
            raise ConfigError("[rail] positions must be strictly increasing")
        return pos


@dataclass(frozen=True)
class AntennaSection:
    """``[antenna]``: L_x, L_R (m), gain, depression (deg), pattern (used with the antenna_pattern effect)."""

    length_azimuth_m: float = 0.25
    length_range_m: float = 0.25
    gain_dbi: float = 20.0
    depression_deg: float = 0.0
    pattern: Literal["sinc", "rect"] = "sinc"

    def __post_init__(self) -> None:
        if not (self.length_azimuth_m > 0 and self.length_range_m > 0):
            raise ConfigError("[antenna] needs positive lengths")


@dataclass(frozen=True)
class PointEntry:
    """``[[points]]``: position (m), scattering, stability, displacement (vector or along the LOS, mm)."""

    y_m: float
    x_m: float = 0.0
    z_m: float = 0.0
    scattering: Any = 1.0
    stable: bool = True
    displacement_mm: tuple[float, float, float] | None = None
    los_displacement_mm: float | None = None
    name: str = ""
    motion: MotionLaw | None = None


@dataclass(frozen=True)
class WallEntry:
    """``[[walls]]``: a line of scatterers from ``start_m`` to ``end_m`` every ``spacing_m`` (default lam/4)."""

    start_m: tuple[float, float, float]
    end_m: tuple[float, float, float]
    spacing_m: float | None = None
    scattering: Any = 1.0
    stable: bool = True
    displacement_mm: tuple[float, float, float] | None = None
    los_displacement_mm: float | None = None
    name: str = ""
    motion: MotionLaw | None = None


@dataclass(frozen=True)
class ZoneEntry:
    """``[[zones]]``: a seeded Poisson field of scatterers over ``x_m`` x ``y_m`` (``[min, max]`` pairs) on
    the surface ``z = z_m + dz_dy (y - y_min)``, moving together by ``motion``; unstable zones decorrelate
    like clutter (with ``[effects.decorrelation]``)."""

    x_m: tuple[float, float]
    y_m: tuple[float, float]
    density_per_m2: float
    name: str = ""
    z_m: float = 0.0
    dz_dy: float = 0.0
    scattering: Any = 1.0
    seed: int = 0
    stable: bool = True
    motion: MotionLaw | None = None

    def __post_init__(self) -> None:
        if self.x_m[1] < self.x_m[0] or self.y_m[1] < self.y_m[0] or not self.density_per_m2 >= 0:
            raise ConfigError("[[zones]] x_m and y_m are [min, max] pairs and density_per_m2 >= 0")


@dataclass(frozen=True)
class ClutterSection:
    """``[clutter]``: a seeded Poisson field of scatterers over ``x_m`` x ``y_m`` (``[min, max]`` pairs)."""

    x_m: tuple[float, float]
    y_m: tuple[float, float]
    density_per_m2: float
    z_m: float = 0.0
    scattering: Any = 1.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.x_m[1] < self.x_m[0] or self.y_m[1] < self.y_m[0]:
            raise ConfigError("[clutter] x_m and y_m are [min, max] pairs")


@dataclass(frozen=True)
class AntennaPatternEffect:
    """Two-way pattern of the L_x x L_R aperture."""


@dataclass(frozen=True)
class NoiseEffect:
    power_db: float = -60.0  # complex white noise power per S21 sample (dB re 1)


@dataclass(frozen=True)
class VerticalBaselineEffect:
    offset_m: float = 0.0  # added to every rail height


@dataclass(frozen=True)
class FrequencyShiftEffect:
    shift_hz: float = 0.0  # added to every sweep frequency


@dataclass(frozen=True)
class DisplacementEffect:
    scale: float = 1.0  # target displacements applied times scale


@dataclass(frozen=True)
class DecorrelationEffect:
    coherence: float = 0.5  # of unstable scatterers (clutter and stable = false) between scans

    def __post_init__(self) -> None:
        if not 0.0 <= self.coherence <= 1.0:
            raise ConfigError("[effects.decorrelation] coherence must be in [0, 1]")


@dataclass(frozen=True)
class AtmosphereEffect:
    """Refractivity N (ppm) at the radar: extra one-way path ``N 1e-6 R`` (a range-proportional phase).

    In time (:func:`scene_at`, t in hours after the epoch):
    ``N(t) = refractivity_ppm + drift_ppm_per_h t + diurnal_ppm sin(2 pi t / diurnal_period_h + phase)``;
    a vertical gradient ``G(t) = gradient_ppm_per_m + gradient_drift_ppm_per_m_per_h t`` adds, along the
    straight path from the antenna (height h) to a scatterer at height z, the mean ``G (z - h)/2``:
    ``1e-6 R G (z - h)/2``; a turbulent screen adds ``s(x, y)`` (m), a Gaussian random field of standard
    deviation ``turbulence_mm`` and covariance ``exp(-d^2/(2 L^2))`` with ``L = turbulence_scale_m``
    (64 random Fourier modes), drawn anew for every scan from (seed, scan index). The stratified and
    turbulent paths are applied as apparent line-of-sight displacements of the scatterers (exact to
    ``(u/R)^2/2`` of the path for a rail stop ``u`` off the centre: 6e-6 at u = 0.5 m, R = 150 m).
    """

    refractivity_ppm: float = 0.0  # extra path (N * 1e-6) * R
    drift_ppm_per_h: float = 0.0
    diurnal_ppm: float = 0.0
    diurnal_period_h: float = 24.0
    diurnal_phase_deg: float = 0.0
    gradient_ppm_per_m: float = 0.0
    gradient_drift_ppm_per_m_per_h: float = 0.0
    turbulence_mm: float = 0.0
    turbulence_scale_m: float = 50.0
    seed: int = 0

    def __post_init__(self) -> None:
        if not (self.diurnal_period_h > 0 and self.turbulence_scale_m > 0 and self.turbulence_mm >= 0):
            raise ConfigError("[effects.atmosphere] needs diurnal_period_h > 0, turbulence_scale_m > 0, "
                              "turbulence_mm >= 0")

    def refractivity_at(self, t_h: float) -> float:
        return (self.refractivity_ppm + self.drift_ppm_per_h * t_h
                + self.diurnal_ppm * float(np.sin(2 * np.pi * t_h / self.diurnal_period_h
                                                  + np.deg2rad(self.diurnal_phase_deg))))

    def gradient_at(self, t_h: float) -> float:
        return self.gradient_ppm_per_m + self.gradient_drift_ppm_per_m_per_h * t_h


@dataclass(frozen=True)
class EffectsSection:
    """``[effects.<name>]``: an effect is computed only when its table is present."""

    antenna_pattern: AntennaPatternEffect | None = None
    noise: NoiseEffect | None = None
    vertical_baseline: VerticalBaselineEffect | None = None
    frequency_shift: FrequencyShiftEffect | None = None
    displacement: DisplacementEffect | None = None
    decorrelation: DecorrelationEffect | None = None
    atmosphere: AtmosphereEffect | None = None

    def as_dict(self) -> dict[str, dict[str, float]]:
        return {f.name: asdict(v) for f in fields(self) if (v := getattr(self, f.name)) is not None}


@dataclass(frozen=True)
class ProcessingSection:
    max_range_m: float | None = None  # image extent used by `plan` for N_xfft of RD


@dataclass(frozen=True)
class SceneFile:
    """A scene TOML document, checked (unknown keys, types) by :func:`sarcli.config.from_mapping`."""

    sweep: SweepSection
    scene: SceneSection = field(default_factory=SceneSection)
    rail: RailSection = field(default_factory=RailSection)
    antenna: AntennaSection = field(default_factory=AntennaSection)
    site: Site = field(default_factory=Site)
    processing: ProcessingSection = field(default_factory=ProcessingSection)
    points: tuple[PointEntry, ...] = ()
    walls: tuple[WallEntry, ...] = ()
    zones: tuple[ZoneEntry, ...] = ()
    clutter: ClutterSection | None = None
    effects: EffectsSection = field(default_factory=EffectsSection)


#: memory per realised scatterer (position, 4 complex reflectivities, kind, displacement, gains), bytes
SCATTERER_BYTES = 256


def _finite(v: Any, where: str) -> None:
    """Refuse a NaN or infinite number anywhere in a scene table (``where``: its place in the file)."""
    if isinstance(v, float) and not np.isfinite(v):
        raise ConfigError(f"{where} = {v}: expected a finite number")
    if isinstance(v, dict):
        for k, x in v.items():
            _finite(x, f"{where}.{k}" if where[-1] != "]" else f"{where} {k}")
    elif isinstance(v, list):
        for i, x in enumerate(v):
            _finite(x, f"{where}[{i}]")


_TABLES = {"scene": SceneSection, "sweep": SweepSection, "rail": RailSection, "antenna": AntennaSection,
           "site": Site, "processing": ProcessingSection, "clutter": ClutterSection, "effects": EffectsSection}
_ARRAYS = {"points": PointEntry, "walls": WallEntry, "zones": ZoneEntry}


def parse_scene_file(doc: Any, source: str = "scene") -> SceneFile:
    """Check a parsed scene TOML: every table through :func:`sarcli.config.from_mapping`; messages name
    ``source`` (the file) and the table (``scene.toml [rail]: ...``, ``scene.toml [[points]] 2: ...``)."""
    if not isinstance(doc, dict):
        raise ConfigError(f"{source}: a scene is a table of sections")
    parts: dict[str, Any] = {}
    for key, value in doc.items():
        _finite(value, f"{source} [{key}]")
        try:
            if key in _TABLES:
                parts[key] = from_mapping(_TABLES[key], value, f"{source} [{key}]")
            elif key in _ARRAYS:
                if not isinstance(value, list):
                    raise ConfigError(f"{source}: {key} must be an array of tables ([[{key}]])")
                parts[key] = tuple(from_mapping(_ARRAYS[key], v, f"{source} [[{key}]] {i}")
                                   for i, v in enumerate(value))
            else:
                parts[key] = value
        except ConfigError as e:  # a __post_init__ check names its table, not the file
            msg = str(e)
            raise ConfigError(msg if msg.startswith(source) else f"{source}: {msg}") from None
    return from_mapping(SceneFile, parts, source)


def _complex(v: Any, where: str) -> complex:
    if isinstance(v, int | float) and not isinstance(v, bool):
        return complex(v)
    if isinstance(v, list) and len(v) == 2 and all(isinstance(a, int | float) for a in v):
        return complex(v[0], v[1])
    raise ConfigError(f"{where}: a reflectivity is a number or an [re, im] pair")


def _scattering(v: Any, where: str) -> np.ndarray:
    """Scattering matrix -> (4,) complex128 in POLARIZATIONS order (VV, VH, HV, HH)."""
    out = np.zeros(4, np.complex128)
    if isinstance(v, dict):
        for k, a in v.items():
            if k.upper() not in POLARIZATIONS:
                raise ConfigError(f"{where}: unknown polarization '{k}' (use VV, VH, HV, HH)")
            out[POLARIZATIONS.index(k.upper())] = _complex(a, where)
    else:
        out[0] = out[3] = _complex(v, where)
    return out


def _displacement(e: PointEntry | WallEntry, pos: np.ndarray, rail_h: float, where: str) -> np.ndarray:
    """Displacement (3,) m: the vector, or ``los_displacement_mm`` along the line of sight from the rail centre."""
    if e.displacement_mm is not None and e.los_displacement_mm is not None:
        raise ConfigError(f"{where}: give displacement_mm or los_displacement_mm, not both")
    if e.displacement_mm is not None:
        return np.asarray(e.displacement_mm, np.float64) * 1e-3
    los = (e.los_displacement_mm or 0.0) * 1e-3
    r = pos - np.array([0.0, 0.0, rail_h])
    nr = np.linalg.norm(r)
    return r / nr * los if nr > 0 else np.zeros(3)


def _targets(doc: SceneFile, lam: float, rail_h: float, source: str
             ) -> list[tuple[np.ndarray, np.ndarray, int, bool, np.ndarray, TargetGroup]]:
    """(positions (k,3), reflectivity (4,k), kind, stable, displacement (3,) m, group) per points, walls
    and zones entry (zones have no static displacement)."""
    out = []
    for i, p in enumerate(doc.points):
        where = f"{source} [[points]] {i}"
        pos = np.array([p.x_m, p.y_m, p.z_m], np.float64)
        out.append((pos[None, :], _scattering(p.scattering, where)[:, None], KIND_POINT, p.stable,
                    _displacement(p, pos, rail_h, where),
                    TargetGroup(p.name or f"points-{i}", KIND_POINT, p.stable, p.motion)))
    for i, w in enumerate(doc.walls):
        where = f"{source} [[walls]] {i}"
        a, b = np.asarray(w.start_m, np.float64), np.asarray(w.end_m, np.float64)
        spacing = lam / 4 if w.spacing_m is None else w.spacing_m
        if not spacing > 0:
            raise ConfigError(f"{where}: spacing_m must be > 0")
        n_f = np.ceil(np.linalg.norm(b - a) / spacing) + 1
        fits_in_memory(f"{where}: {n_f:.4g} scatterers (spacing_m = {spacing:g} m)", n_f * SCATTERER_BYTES)
        n = max(int(n_f), 2)
        pos = a + (b - a) * np.linspace(0.0, 1.0, n)[:, None]
        refl = np.repeat(_scattering(w.scattering, where)[:, None], n, 1)
        out.append((pos, refl, KIND_WALL, w.stable, _displacement(w, 0.5 * (a + b), rail_h, where),
                    TargetGroup(w.name or f"walls-{i}", KIND_WALL, w.stable, w.motion)))
    for i, z in enumerate(doc.zones):
        where = f"{source} [[zones]] {i}"
        (x0, x1), (y0, y1) = z.x_m, z.y_m
        rng = np.random.default_rng(z.seed)
        n = int(rng.poisson(z.density_per_m2 * (x1 - x0) * (y1 - y0)))
        y = rng.uniform(y0, y1, n)
        pos = np.column_stack([rng.uniform(x0, x1, n), y, z.z_m + z.dz_dy * (y - y0)])
        g = (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2)
        refl = _scattering(z.scattering, where)[:, None] * g[None, :]
        out.append((pos, refl, KIND_ZONE, z.stable, np.zeros(3),
                    TargetGroup(z.name or f"zones-{i}", KIND_ZONE, z.stable, z.motion)))
    return out


def _clutter(c: ClutterSection, source: str) -> tuple[np.ndarray, np.ndarray]:
    (x0, x1), (y0, y1) = c.x_m, c.y_m
    scat = _scattering(c.scattering, f"{source} [clutter]")
    rng = np.random.default_rng(c.seed)
    n = int(rng.poisson(c.density_per_m2 * (x1 - x0) * (y1 - y0)))
    pos = np.column_stack([rng.uniform(x0, x1, n), rng.uniform(y0, y1, n), np.full(n, c.z_m)])
    # co-polar channels share one circular Gaussian, cross-polar channels another (reciprocal VH = HV)
    g = (rng.standard_normal((2, n)) + 1j * rng.standard_normal((2, n))) / np.sqrt(2)
    refl = np.empty((4, n), np.complex128)
    refl[0], refl[3] = scat[0] * g[0], scat[3] * g[0]
    refl[1], refl[2] = scat[1] * g[1], scat[2] * g[1]
    return pos, refl


def scene_from_dict(doc: dict, source_toml: str = "", source: str = "scene") -> Scene:
    """Build a scene from a parsed TOML document (layout in the module docstring); ``source`` names it
    in error messages."""
    f = parse_scene_file(doc, source)
    if f.site.look_side not in ("right", "left") or abs(f.site.latitude_deg) > 90:
        raise ConfigError(f"{source}: [site] look_side is 'right' or 'left' and |latitude_deg| <= 90")
    try:
        f.rail.positions()
    except ConfigError as e:
        raise ConfigError(f"{source}: {e}") from None
    return _build(f, source_toml, source, 0.0, 0)


def scene_at(scene: Scene, time_s: float, index: int) -> Scene:
    """The scene at ``time_s`` seconds after its epoch, for acquisition (scan) ``index`` (0 = the first):
    targets moved by their motion laws, the atmosphere at that time with a new turbulent screen, and the
    per-acquisition randomness (noise, decorrelation) drawn from a seed derived from (seed, index).
    ``scene_at(scene, 0, 0)`` equals the scene as loaded."""
    if scene.file is None:
        raise SarcliError("this scene was not built from a scene document: it cannot be realised at another time")
    return _build(scene.file, scene.source_toml, "scene", float(time_s), int(index))


def scan_seed(seed: int, index: int) -> int:
    """The per-acquisition seed of scan ``index``: the scene's own for index 0, else derived from both."""
    if index == 0:
        return int(seed)
    return int(np.random.SeedSequence([int(seed), int(index)]).generate_state(1, np.uint32)[0])


def _build(f: SceneFile, source_toml: str, source: str, time_s: float, index: int) -> Scene:
    sw, rail, an, site = f.sweep, f.rail, f.antenna, f.site
    lam = C_LIGHT / sw.center_frequency_hz
    antenna = Antenna(length_azimuth_m=an.length_azimuth_m, length_range_m=an.length_range_m,
                      beamwidth_rad=lam / an.length_azimuth_m, gain_dbi=an.gain_dbi)
    effects = f.effects.as_dict()
    t_h = time_s / 3600.0
    if f.effects.atmosphere is not None:
        effects["atmosphere"]["refractivity_ppm"] = f.effects.atmosphere.refractivity_at(t_h)
    seed = scan_seed(f.scene.seed, index)
    scat, groups = _realise(f, lam, rail.height_m, seed, effects, source, t_h, index)
    processing = {} if f.processing.max_range_m is None else {"max_range_m": f.processing.max_range_m}
    return Scene(name=f.scene.name, seed=seed, epoch_utc=f.scene.epoch_utc,
                 center_frequency_hz=sw.center_frequency_hz, bandwidth_hz=sw.bandwidth_hz, points=sw.points,
                 polarizations=sw.polarizations, positions_m=rail.positions(), height_m=rail.height_m,
                 stop_duration_s=rail.stop_duration_s, antenna=antenna,
                 depression_rad=float(np.deg2rad(an.depression_deg)), pattern=an.pattern, site=site,
                 scatterers=scat, effects=effects, processing=processing, source_toml=source_toml, file=f,
                 groups=groups, time_s=time_s, scan_index=index)


def _turbulence_m(atm: AtmosphereEffect, pos: np.ndarray, index: int) -> np.ndarray:
    """The turbulent screen (m) at scatterers ``pos`` (n, 3) for scan ``index``: 64 random Fourier modes,
    ``s = sigma sqrt(2/M) sum_m cos(k_m . p + phi_m)`` with ``k_m ~ N(0, 1/L^2)`` per horizontal axis, so
    ``E[s(p) s(q)] = sigma^2 exp(-|p - q|^2 / (2 L^2))``."""
    m = 64
    rng = np.random.default_rng([atm.seed, index, 0xA7])
    k = rng.standard_normal((m, 2)) / atm.turbulence_scale_m
    phi = rng.uniform(0.0, 2 * np.pi, m)
    arg = pos[:, :2] @ k.T + phi[None, :]
    return atm.turbulence_mm * 1e-3 * np.sqrt(2.0 / m) * np.cos(arg).sum(axis=1)


def _realise(doc: SceneFile, lam: float, rail_h: float, seed: int, effects: dict, source: str,
             t_h: float = 0.0, index: int = 0) -> tuple[Scatterers, list[TargetGroup]]:
    """Positions and reflectivities of every scatterer at ``t_h`` hours after the epoch, with displacement
    (static and motion laws), decorrelation and the atmosphere's apparent displacement applied."""
    parts = _targets(doc, lam, rail_h, source)
    pos_l, refl_l, kind_l, stable_l, disp_l, group_l = [], [], [], [], [], []
    groups: list[TargetGroup] = []
    for gi, (pos, refl, kind, stable, disp, grp) in enumerate(parts):
        pos_l.append(pos)
        refl_l.append(refl)
        kind_l.append(np.full(pos.shape[0], kind, np.int8))
        stable_l.append(np.full(pos.shape[0], stable))
        disp_l.append(np.repeat(disp[None, :], pos.shape[0], 0))
        group_l.append(np.full(pos.shape[0], gi, np.int32))
        groups.append(grp)
    if doc.clutter is not None:
        cp, cr = _clutter(doc.clutter, source)
        pos_l.append(cp)
        refl_l.append(cr)
        kind_l.append(np.full(cp.shape[0], KIND_CLUTTER, np.int8))
        stable_l.append(np.zeros(cp.shape[0], bool))
        disp_l.append(np.zeros((cp.shape[0], 3)))
        group_l.append(np.full(cp.shape[0], -1, np.int32))
    if not pos_l:
        raise ConfigError(f"{source}: no scatterers (add [[points]], [[walls]], [[zones]] or [clutter])")
    pos = np.concatenate(pos_l)
    refl = np.concatenate(refl_l, axis=1)
    kind, stable = np.concatenate(kind_l), np.concatenate(stable_l)
    disp = np.concatenate(disp_l)
    group = np.concatenate(group_l)
    centre = np.array([0.0, 0.0, rail_h])
    if "displacement" in effects:
        disp = disp * effects["displacement"]["scale"]
    else:
        disp = np.zeros_like(disp)
    rest = pos.copy()  # where the scatterers are without any displacement
    u = rest - centre
    nu = np.linalg.norm(u, axis=1)
    unit = u / np.where(nu > 0, nu, 1.0)[:, None]
    failed = np.zeros(pos.shape[0], bool)
    for gi, grp in enumerate(groups):
        if grp.motion is None:
            continue
        sel = group == gi
        disp[sel] += unit[sel] * grp.motion.displacement_mm(t_h) * 1e-3
        failed[sel] = grp.motion.failed(t_h)
    pos = pos + disp
    r = pos - disp - centre
    nr = np.linalg.norm(r, axis=1)
    los = np.where(nr > 0, np.einsum("ij,ij->i", disp, r) / np.where(nr > 0, nr, 1.0), 0.0)
    if "decorrelation" in effects:
        # a' = sqrt(g) a + sqrt(1-g) |a| n with n ~ CN(0,1) drawn from the scan's seed: two scans with
        # different seeds then have correlation coefficient g for these scatterers (E|a'|^2 = |a|^2).
        gam = effects["decorrelation"]["coherence"]
        rng = np.random.default_rng([seed, 0xDEC0])
        n = (rng.standard_normal(refl.shape) + 1j * rng.standard_normal(refl.shape)) / np.sqrt(2)
        mix = np.sqrt(gam) * refl + np.sqrt(1.0 - gam) * np.abs(refl) * n
        refl = np.where(stable[None, :], refl, mix)
    if failed.any():  # a collapsed target: fresh reflectivities every scan (coherence 0)
        rng = np.random.default_rng([seed, 0xFA11])
        n = (rng.standard_normal(refl.shape) + 1j * rng.standard_normal(refl.shape)) / np.sqrt(2)
        refl = np.where(failed[None, :], np.abs(refl) * n, refl)
    atm_path = None
    atm = doc.effects.atmosphere
    if atm is not None and (atm.gradient_ppm_per_m or atm.gradient_drift_ppm_per_m_per_h or atm.turbulence_mm):
        atm_path = 1e-6 * nu * atm.gradient_at(t_h) * (rest[:, 2] - rail_h) / 2
        if atm.turbulence_mm:
            atm_path = atm_path + _turbulence_m(atm, rest, index)
        pos = pos + unit * atm_path[:, None]
    scat = Scatterers(position=pos, reflectivity=refl, kind=kind, displacement=disp, los_displacement=los,
                      group=group, atmosphere_m=atm_path)
    return scat, groups


def scene_truth(scene: Scene) -> dict[str, Any]:
    """What the scene realisation holds, for tests and the emulator's truth file: time, atmosphere
    (N, gradient) and per target group its law, true LOS displacement (mm) and velocity (mm/h), whether
    it failed, and the mean apparent path of the stratified + turbulent atmosphere over its scatterers (mm)."""
    f = scene.file
    t_h = scene.time_s / 3600.0
    sc = scene.scatterers
    out: dict[str, Any] = {"scan_index": scene.scan_index, "time_s": scene.time_s, "epoch_utc": scene.epoch_utc,
                           "groups": {}}
    if f is not None and f.effects.atmosphere is not None:
        a = f.effects.atmosphere
        out["atmosphere"] = {"refractivity_ppm": a.refractivity_at(t_h), "gradient_ppm_per_m": a.gradient_at(t_h),
                             "turbulence_mm": a.turbulence_mm}
    for gi, g in enumerate(scene.groups):
        sel = sc.group == gi if sc.group is not None else np.zeros(0, bool)
        law = g.motion
        entry = {"kind": ["point", "wall", "clutter", "zone"][g.kind], "stable": g.stable,
                 "n_scatterers": int(sel.sum()),
                 "los_displacement_mm": float(np.mean(sc.los_displacement[sel]) * 1e3) if sel.any() else 0.0,
                 "velocity_mm_per_h": law.velocity_mm_per_h_at(t_h) if law is not None else 0.0,
                 "failed": bool(law.failed(t_h)) if law is not None else False,
                 "atmosphere_mm": float(np.mean(sc.atmosphere_m[sel]) * 1e3)
                 if sc.atmosphere_m is not None and sel.any() else 0.0}
        if law is not None:
            entry["law"] = asdict(law)
        if g.kind == KIND_POINT and sel.any():
            entry["position_m"] = [float(v) for v in sc.position[sel][0] - sc.displacement[sel][0]]
        out["groups"][g.name] = entry
    return out


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and check a GB-SAR scene TOML file; every error is one :class:`ConfigError` line naming the
    file and the table."""
    doc = load_toml(path)
    return scene_from_dict(doc, Path(path).read_text(encoding="utf-8"), str(path))
