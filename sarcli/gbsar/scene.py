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
    [effects.antenna_pattern] {}            two-way pattern of the L_x x L_R aperture
    [effects.noise] power_db                complex white noise power per S21 sample (dB re 1)
    [effects.vertical_baseline] offset_m    added to every rail height
    [effects.frequency_shift] shift_hz      added to every sweep frequency
    [effects.displacement] scale            target displacements applied (times scale)
    [effects.decorrelation] coherence       unstable scatterers (clutter and stable = false)
    [effects.atmosphere] refractivity_ppm   extra path (N * 1e-6) * R: a range-proportional phase

``scattering`` is a table ``{VV = a, VH = a, HV = a, HH = a}`` whose values are a real number or a
``[re, im]`` pair (missing channels are 0), or a single value/pair meaning VV = HH = value.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, FormatError, SarcliError
from sarcli.io.scan import POLARIZATIONS
from sarcli.model.constants import C_LIGHT
from sarcli.model.gbsar import Antenna, Site

EFFECTS = ("antenna_pattern", "noise", "vertical_baseline", "frequency_shift", "displacement",
           "decorrelation", "atmosphere")
_EFFECT_KEYS = {
    "antenna_pattern": {}, "noise": {"power_db": -60.0}, "vertical_baseline": {"offset_m": 0.0},
    "frequency_shift": {"shift_hz": 0.0}, "displacement": {"scale": 1.0},
    "decorrelation": {"coherence": 0.5}, "atmosphere": {"refractivity_ppm": 0.0},
}
KIND_POINT, KIND_WALL, KIND_CLUTTER = 0, 1, 2


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


class _Table:
    """A TOML table read key by key; leftover (unknown) keys are refused in one line."""

    def __init__(self, d: Any, where: str):
        if not isinstance(d, dict):
            raise FormatError(f"scene: [{where}] must be a table")
        self.d, self.where, self.used = d, where, set()

    def get(self, key: str, default: Any = None, kind: type | tuple = (int, float)) -> Any:
        self.used.add(key)
        if key not in self.d:
            if default is None:
                raise FormatError(f"scene: [{self.where}] needs '{key}'")
            return default
        v = self.d[key]
        if kind is not None and (not isinstance(v, kind) or isinstance(v, bool) and kind is not bool):
            raise FormatError(f"scene: [{self.where}] {key} has the wrong type ({type(v).__name__})")
        return v

    def done(self) -> None:
        extra = sorted(set(self.d) - self.used)
        if extra:
            raise FormatError(f"scene: [{self.where}] unknown key(s) {', '.join(extra)}")


def _complex(v: Any, where: str) -> complex:
    if isinstance(v, int | float) and not isinstance(v, bool):
        return complex(v)
    if isinstance(v, list) and len(v) == 2 and all(isinstance(a, int | float) for a in v):
        return complex(v[0], v[1])
    raise FormatError(f"scene: {where}: a reflectivity is a number or an [re, im] pair")


def _scattering(v: Any, where: str) -> np.ndarray:
    """Scattering matrix -> (4,) complex128 in POLARIZATIONS order (VV, VH, HV, HH)."""
    out = np.zeros(4, np.complex128)
    if isinstance(v, dict):
        for k, a in v.items():
            if k.upper() not in POLARIZATIONS:
                raise FormatError(f"scene: {where}: unknown polarization '{k}' (use VV, VH, HV, HH)")
            out[POLARIZATIONS.index(k.upper())] = _complex(a, where)
    else:
        out[0] = out[3] = _complex(v, where)
    return out


def _vec3(v: Any, where: str) -> np.ndarray:
    if not (isinstance(v, list) and len(v) == 3 and all(isinstance(a, int | float) for a in v)):
        raise FormatError(f"scene: {where} must be [x, y, z] in metres")
    return np.asarray(v, np.float64)


def _rail(t: _Table) -> tuple[np.ndarray, float, float]:
    if "positions_m" in t.d:
        pos = np.asarray(t.get("positions_m", kind=list), np.float64)
    else:
        length, step = float(t.get("length_m")), float(t.get("step_m"))
        if step <= 0 or length < 0:
            raise FormatError("scene: [rail] needs step_m > 0 and length_m >= 0")
        n = int(round(length / step)) + 1  # N_x = X/dx + 1 (Table 1 prints "- 1", a typo)
        pos = (np.arange(n) - (n - 1) / 2) * step
    if pos.ndim != 1 or pos.size < 1 or not np.all(np.isfinite(pos)):
        raise FormatError("scene: [rail] positions must be a non-empty list of finite numbers")
    if pos.size > 1 and not np.all(np.diff(pos) > 0):
        raise FormatError("scene: [rail] positions must be strictly increasing")
    height = float(t.get("height_m", 0.0))
    dur = float(t.get("stop_duration_s", 1.0))
    t.done()
    return pos, height, dur


def _targets(doc: dict, lam: float, rail_h: float) -> list[tuple[np.ndarray, np.ndarray, int, bool,
                                                                  np.ndarray]]:
    """(positions (k,3), reflectivity (4,k), kind, stable, displacement (3,) m) per points/walls entry."""
    out = []
    for i, p in enumerate(doc.get("points", [])):
        t = _Table(p, f"points {i}")
        pos = np.array([t.get("x_m", 0.0), t.get("y_m"), t.get("z_m", 0.0)], np.float64)
        refl = _scattering(t.get("scattering", 1.0, kind=None), f"points {i}")
        disp = _displacement(t, pos, rail_h, f"points {i}")
        stable = bool(t.get("stable", True, kind=bool))
        t.done()
        out.append((pos[None, :], refl[:, None], KIND_POINT, stable, disp))
    for i, w in enumerate(doc.get("walls", [])):
        t = _Table(w, f"walls {i}")
        a, b = _vec3(t.get("start_m", kind=list), f"walls {i} start_m"), _vec3(t.get("end_m", kind=list),
                                                                                f"walls {i} end_m")
        spacing = float(t.get("spacing_m", lam / 4))
        if spacing <= 0:
            raise FormatError(f"scene: [walls {i}] spacing_m must be > 0")
        n = max(int(np.ceil(np.linalg.norm(b - a) / spacing)) + 1, 2)
        pos = a + (b - a) * np.linspace(0.0, 1.0, n)[:, None]
        refl = np.repeat(_scattering(t.get("scattering", 1.0, kind=None), f"walls {i}")[:, None], n, 1)
        disp = _displacement(t, 0.5 * (a + b), rail_h, f"walls {i}")
        stable = bool(t.get("stable", True, kind=bool))
        t.done()
        out.append((pos, refl, KIND_WALL, stable, disp))
    return out


def _displacement(t: _Table, pos: np.ndarray, rail_h: float, where: str) -> np.ndarray:
    if "displacement_mm" in t.d and "los_displacement_mm" in t.d:
        raise FormatError(f"scene: [{where}] give displacement_mm or los_displacement_mm, not both")
    if "displacement_mm" in t.d:
        return _vec3(t.get("displacement_mm", kind=list), f"{where} displacement_mm") * 1e-3
    los = float(t.get("los_displacement_mm", 0.0)) * 1e-3
    r = pos - np.array([0.0, 0.0, rail_h])
    nr = np.linalg.norm(r)
    return r / nr * los if nr > 0 else np.zeros(3)


def _clutter(d: Any, rail_h: float) -> tuple[np.ndarray, np.ndarray]:
    t = _Table(d, "clutter")
    xr, yr = t.get("x_m", kind=list), t.get("y_m", kind=list)
    if len(xr) != 2 or len(yr) != 2 or xr[1] < xr[0] or yr[1] < yr[0]:
        raise FormatError("scene: [clutter] x_m and y_m are [min, max] pairs")
    z = float(t.get("z_m", 0.0))
    dens = float(t.get("density_per_m2"))
    scat = _scattering(t.get("scattering", 1.0, kind=None), "clutter")
    rng = np.random.default_rng(int(t.get("seed", 0, kind=int)))
    t.done()
    n = int(rng.poisson(dens * (xr[1] - xr[0]) * (yr[1] - yr[0])))
    pos = np.column_stack([rng.uniform(xr[0], xr[1], n), rng.uniform(yr[0], yr[1], n), np.full(n, z)])
    # co-polar channels share one circular Gaussian, cross-polar channels another (reciprocal VH = HV)
    g = (rng.standard_normal((2, n)) + 1j * rng.standard_normal((2, n))) / np.sqrt(2)
    refl = np.empty((4, n), np.complex128)
    refl[0], refl[3] = scat[0] * g[0], scat[3] * g[0]
    refl[1], refl[2] = scat[1] * g[1], scat[2] * g[1]
    return pos, refl


def scene_from_dict(doc: dict, source_toml: str = "") -> Scene:
    """Build a scene from a parsed TOML document (see the module docstring for the layout)."""
    known = {"scene", "sweep", "rail", "antenna", "site", "processing", "points", "walls", "clutter",
             "effects"}
    extra = sorted(set(doc) - known)
    if extra:
        raise FormatError(f"scene: unknown section(s) {', '.join(extra)}")
    sc = _Table(doc.get("scene", {}), "scene")
    name = str(sc.get("name", "gbsar", kind=str))
    seed = int(sc.get("seed", 0, kind=int))
    epoch = str(sc.get("epoch_utc", "2000-01-01T00:00:00Z", kind=str))
    sc.done()

    sw = _Table(doc.get("sweep", {}), "sweep")
    fc, bw = float(sw.get("center_frequency_hz")), float(sw.get("bandwidth_hz", 0.0))
    npts = int(sw.get("points", kind=int))
    pols = tuple(str(p).upper() for p in sw.get("polarizations", ["VV"], kind=list))
    sw.done()
    if fc <= 0 or bw < 0 or npts < 1 or (npts > 1 and bw <= 0):
        raise FormatError("scene: [sweep] needs center_frequency_hz > 0, points >= 1 and bandwidth_hz > 0")
    if fc - bw / 2 <= 0:
        raise FormatError("scene: [sweep] the sweep would reach zero or negative frequencies")
    if not pols or any(p not in POLARIZATIONS for p in pols) or len(set(pols)) != len(pols):
        raise FormatError(f"scene: [sweep] polarizations must be distinct names among {POLARIZATIONS}")
    lam = C_LIGHT / fc

    positions, rail_h, dur = _rail(_Table(doc.get("rail", {}), "rail"))

    an = _Table(doc.get("antenna", {}), "antenna")
    lx, lr = float(an.get("length_azimuth_m", 0.25)), float(an.get("length_range_m", 0.25))
    antenna = Antenna(length_azimuth_m=lx, length_range_m=lr, beamwidth_rad=lam / lx,
                      gain_dbi=float(an.get("gain_dbi", 20.0)))
    depression = np.deg2rad(float(an.get("depression_deg", 0.0)))
    pattern = str(an.get("pattern", "sinc", kind=str))
    an.done()
    if lx <= 0 or lr <= 0 or pattern not in ("sinc", "rect"):
        raise FormatError("scene: [antenna] needs positive lengths and pattern 'sinc' or 'rect'")

    si = _Table(doc.get("site", {}), "site")
    site = Site(latitude_deg=float(si.get("latitude_deg", 0.0)), longitude_deg=float(si.get("longitude_deg", 0.0)),
                height_m=float(si.get("height_m", 0.0)), heading_deg=float(si.get("heading_deg", 0.0)),
                look_side=str(si.get("look_side", "right", kind=str)))
    si.done()
    if site.look_side not in ("right", "left") or abs(site.latitude_deg) > 90:
        raise FormatError("scene: [site] look_side is 'right' or 'left' and |latitude_deg| <= 90")

    effects: dict[str, dict[str, float]] = {}
    for ename, params in doc.get("effects", {}).items():
        if ename not in EFFECTS:
            raise FormatError(f"scene: unknown effect '{ename}' (known: {', '.join(EFFECTS)})")
        et = _Table(params, f"effects.{ename}")
        effects[ename] = {k: float(et.get(k, dv)) for k, dv in _EFFECT_KEYS[ename].items()}
        et.done()
    if "decorrelation" in effects and not 0.0 <= effects["decorrelation"]["coherence"] <= 1.0:
        raise FormatError("scene: [effects.decorrelation] coherence must be in [0, 1]")

    scat = _realise(doc, lam, rail_h, seed, effects)
    pr = _Table(doc.get("processing", {}), "processing")
    processing = {k: float(pr.get(k)) for k in ("max_range_m",) if k in pr.d}
    pr.done()
    return Scene(name=name, seed=seed, epoch_utc=epoch, center_frequency_hz=fc, bandwidth_hz=bw, points=npts,
                 polarizations=pols, positions_m=positions, height_m=rail_h, stop_duration_s=dur,
                 antenna=antenna, depression_rad=float(depression), pattern=pattern, site=site,
                 scatterers=scat, effects=effects, processing=processing, source_toml=source_toml)


def _realise(doc: dict, lam: float, rail_h: float, seed: int, effects: dict) -> Scatterers:
    """Positions and reflectivities of every scatterer, with displacement and decorrelation applied."""
    parts = _targets(doc, lam, rail_h)
    pos_l, refl_l, kind_l, stable_l, disp_l = [], [], [], [], []
    for pos, refl, kind, stable, disp in parts:
        pos_l.append(pos)
        refl_l.append(refl)
        kind_l.append(np.full(pos.shape[0], kind, np.int8))
        stable_l.append(np.full(pos.shape[0], stable))
        disp_l.append(np.repeat(disp[None, :], pos.shape[0], 0))
    if "clutter" in doc:
        cp, cr = _clutter(doc["clutter"], rail_h)
        pos_l.append(cp)
        refl_l.append(cr)
        kind_l.append(np.full(cp.shape[0], KIND_CLUTTER, np.int8))
        stable_l.append(np.zeros(cp.shape[0], bool))
        disp_l.append(np.zeros((cp.shape[0], 3)))
    if not pos_l:
        raise FormatError("scene: no scatterers (add [[points]], [[walls]] or [clutter])")
    pos = np.concatenate(pos_l)
    refl = np.concatenate(refl_l, axis=1)
    kind, stable = np.concatenate(kind_l), np.concatenate(stable_l)
    disp = np.concatenate(disp_l)
    if "displacement" in effects:
        disp = disp * effects["displacement"]["scale"]
        pos = pos + disp
    else:
        disp = np.zeros_like(disp)
    r = pos - disp - np.array([0.0, 0.0, rail_h])
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
    return Scatterers(position=pos, reflectivity=refl, kind=kind, displacement=disp, los_displacement=los)


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and validate a GB-SAR scene TOML file; errors are one-line :class:`SarcliError`."""
    try:
        with open(path, "rb") as f:
            text = f.read().decode("utf-8")
    except FileNotFoundError:
        raise SarcliError(f"{path}: no such scene file") from None
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: scene file is not UTF-8 text") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{path}: invalid TOML ({e})") from None
    return scene_from_dict(doc, text)
