"""Design parameters: from a design TOML (``[design]`` table), a raw product or a GB-SAR scan.

A design TOML (see ``samples/aod_ccd_example.toml``)::

    [design]
    platform = "airborne"            # airborne (flat Earth) | spaceborne (spherical Earth) | gbsar
    carrier_frequency_hz = 10.0e9
    chirp_rate_hz_per_s = 0.5e12     # or bandwidth_hz
    pulse_length_s = 20e-6
    altitude_m = 5000.0
    velocity_mps = 250.0
    look_angle_deg = 30.0
    look_angle_from = "horizontal"   # "horizontal" (depression, the convention of [KimAODCCD]) or "nadir"
    squint_angle_deg = 90.0          # angle between velocity and line of sight (90 = broadside)
    antenna_length_m = 2.0           # optional: real antenna (azimuth), enables PRF > 2v/D
    swath_slant_m = 4000.0           # optional: else from the AOD aperture, else 0
    prf_hz = [15734, 3934, 1967]
    [design.processor]               # optional: the AOD/CCD optical processor of [KimAODCCD]
    ccd_rows = 491
    ccd_line_rate_hz = 15734.0
    aod_aperture_m = 0.031
    aod_velocity_mps = 617.0

GB-SAR designs use ``platform = "gbsar"`` with frequency_start_hz, frequency_stop_hz,
n_frequencies, rail_length_m, rail_step_m, antenna_length_m, beamwidth_deg, antenna_height_m and
ranges_m (the ranges at which to evaluate resolution).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from sarcli.config import from_mapping, load_toml
from sarcli.errors import ConfigError, ProductError
from sarcli.model.constants import C_LIGHT, WGS84_A

PLATFORMS = ("airborne", "spaceborne", "gbsar")


@dataclass(frozen=True)
class Processor:
    """The AOD/CCD optical processor of [KimAODCCD] (all optional): CCD rows and line rate, AOD aperture (m)
    and acoustic velocity (m/s)."""

    ccd_rows: int | None = None
    ccd_line_rate_hz: float | None = None
    aod_aperture_m: float | None = None
    aod_velocity_mps: float | None = None


@dataclass(frozen=True)
class DesignTable:
    """The ``[design]`` table of a design TOML (module docstring); SI units, angles in degrees."""

    platform: Literal["airborne", "spaceborne", "gbsar"]
    carrier_frequency_hz: float
    chirp_rate_hz_per_s: float | None = None
    pulse_length_s: float | None = None
    bandwidth_hz: float | None = None
    altitude_m: float | None = None
    velocity_mps: float | None = None
    look_angle_deg: float | None = None
    look_angle_from: Literal["horizontal", "nadir"] = "horizontal"
    squint_angle_deg: float = 90.0
    antenna_length_m: float | None = None
    swath_slant_m: float | None = None
    slant_range_m: float | None = None
    prf_hz: tuple[float, ...] = ()
    processor: Processor = field(default_factory=Processor)
    # GB-SAR
    frequency_start_hz: float | None = None
    frequency_stop_hz: float | None = None
    n_frequencies: int | None = None
    rail_length_m: float | None = None
    rail_step_m: float | None = None
    beamwidth_deg: float | None = None
    antenna_height_m: float = 0.0
    ranges_m: tuple[float, ...] = ()


@dataclass(frozen=True)
class DesignParams(DesignTable):
    """A design: the table's parameters and where they came from (``source``: a file name)."""

    source: str = ""

    @property
    def wavelength_m(self) -> float:
        return C_LIGHT / self.carrier_frequency_hz


def _need(p: DesignParams, names: tuple[str, ...], where: str) -> None:
    missing = [n for n in names if getattr(p, n) in (None, (), [])]
    if missing:
        raise ConfigError(f"{where}: a {p.platform} design needs {', '.join(missing)}")


def validate(p: DesignParams, where: str) -> DesignParams:
    """Check completeness and ranges; one-line ConfigError on the first problem."""
    if p.platform not in PLATFORMS:
        raise ConfigError(f"{where}: platform must be one of {', '.join(PLATFORMS)}, got {p.platform!r}")
    if not (p.carrier_frequency_hz and p.carrier_frequency_hz > 0):
        raise ConfigError(f"{where}: carrier_frequency_hz must be positive")
    if p.platform == "gbsar":
        _need(p, ("frequency_start_hz", "frequency_stop_hz", "n_frequencies", "rail_length_m",
                  "rail_step_m", "antenna_length_m", "beamwidth_deg"), where)
        if p.frequency_stop_hz <= p.frequency_start_hz or p.n_frequencies < 2:
            raise ConfigError(f"{where}: need frequency_stop_hz > frequency_start_hz and n_frequencies >= 2")
        return p
    if p.bandwidth_hz is None:
        _need(p, ("chirp_rate_hz_per_s", "pulse_length_s"), where)
    _need(p, ("pulse_length_s", "altitude_m", "velocity_mps", "look_angle_deg", "prf_hz"), where)
    if not 0 < p.look_angle_deg < 90:
        raise ConfigError(f"{where}: look_angle_deg must lie strictly between 0 and 90")
    if not 0 < p.squint_angle_deg <= 90:
        raise ConfigError(f"{where}: squint_angle_deg must lie in (0, 90]")
    if any(not (f > 0) for f in p.prf_hz):
        raise ConfigError(f"{where}: every prf_hz must be positive")
    for name in ("altitude_m", "velocity_mps", "pulse_length_s"):
        if not getattr(p, name) > 0:
            raise ConfigError(f"{where}: {name} must be positive")
    return p


def from_toml(path: str | Path, doc: dict | None = None) -> DesignParams:
    """Read the ``[design]`` table of a TOML file (``doc``: the file already parsed) with
    :func:`sarcli.config.from_mapping`: unknown keys, wrong types and unknown choices are one line naming
    the file and the key (``d.toml: design.platform: 'boat' is not one of ...``)."""
    path = Path(path)
    doc = load_toml(path) if doc is None else doc
    if "design" not in doc:
        raise ConfigError(f"{path}: no [design] table (see samples/aod_ccd_example.toml)")
    table = from_mapping(DesignTable, doc["design"], where=f"{path}: design")
    p = DesignParams(**{f.name: getattr(table, f.name) for f in dataclasses.fields(table)}, source=path.name)
    return validate(p, str(path))


def doppler_bandwidth(echo: np.ndarray, prf_hz: float, energy: float = 0.99) -> float:
    """Azimuth bandwidth (Hz) holding ``energy`` of the echo's azimuth power spectrum, centred on the
    power centroid (the lag-1 phase, so squinted spaceborne data work too). It is what the antenna beam
    illuminated: B_D = 2 v / D_equivalent."""
    e = np.asarray(echo)
    centroid = np.angle(np.sum(e[1:] * np.conj(e[:-1]))) / (2 * np.pi)  # cycles per line
    spec = np.sum(np.abs(np.fft.fft(e, axis=0)) ** 2, axis=1)
    f = np.fft.fftfreq(e.shape[0])
    offset = np.abs((f - centroid + 0.5) % 1.0 - 0.5)  # circular distance from the centroid
    order = np.argsort(offset)
    cum = np.cumsum(spec[order]) / np.sum(spec)
    return float(2.0 * offset[order][min(np.searchsorted(cum, energy), e.shape[0] - 1)] * prf_hz)


def from_raw(path: str | Path) -> DesignParams:
    """Design parameters of a stripmap raw product (height and speed from its orbit when present; the
    equivalent antenna length from the echo's Doppler bandwidth, on up to 4096 x 512 central samples)."""
    from sarcli.io.raw import raw_shape, read_raw, read_raw_echo_block

    raw = read_raw(path, load_echo=False)
    r = raw.radar
    n_lines, n_samples = raw_shape(path)
    swath = n_samples * C_LIGHT / (2 * r.range_sampling_rate_hz)
    centre_range = r.first_range_m + swath / 2
    if raw.orbit is not None and raw.orbit.frame in ("ECI", "ECEF"):
        pos, vel = raw.orbit.position, raw.orbit.velocity
        k = len(pos) // 2
        rad = float(np.linalg.norm(pos[k]))
        height = rad - WGS84_A
        speed = float(np.linalg.norm(vel[k]))
        platform = "spaceborne"
        # look angle from nadir for the swath centre on a sphere of radius WGS84_A (law of cosines)
        cosg = (rad**2 + centre_range**2 - WGS84_A**2) / (2 * rad * centre_range)
        look = math.degrees(math.acos(max(-1.0, min(1.0, cosg))))
        look_from = "nadir"
    elif raw.orbit is not None:  # LOCAL airborne frame: z is height
        height = float(raw.orbit.position[len(raw.orbit.position) // 2, 2])
        speed = float(np.linalg.norm(raw.orbit.velocity[len(raw.orbit.velocity) // 2]))
        platform = "airborne"
        look = math.degrees(math.asin(min(1.0, height / centre_range)))
        look_from = "horizontal"
    else:
        raise ProductError(f"{path}: the product has no orbit; a design needs platform height and speed")
    a = max(0, n_lines // 2 - 2048)
    c = max(0, n_samples // 2 - 256)
    block = read_raw_echo_block(path, a, a + 4096)[:, c:c + 512]
    if not np.any(block):
        raise ProductError(f"{path}: the echo is all zero; its Doppler bandwidth (antenna length) cannot be measured")
    antenna = 2.0 * speed / doppler_bandwidth(block, r.prf_hz)
    p = DesignParams(platform=platform, carrier_frequency_hz=r.carrier_frequency_hz, antenna_length_m=antenna,
                     chirp_rate_hz_per_s=r.chirp_rate_hz_per_s, pulse_length_s=r.pulse_length_s,
                     altitude_m=height, velocity_mps=speed, look_angle_deg=look, look_angle_from=look_from,
                     swath_slant_m=swath, slant_range_m=centre_range, prf_hz=(r.prf_hz,),
                     source=Path(path).name)
    return validate(p, str(path))


def from_scan(path: str | Path) -> DesignParams:
    """Design parameters of a GB-SAR scan product."""
    from sarcli.io.scan import read_scan

    s = read_scan(path)
    f = s.frequency
    x = s.rail_position
    if f.size < 2 or x.size < 2:
        raise ProductError(f"{path}: a design needs at least 2 frequencies and 2 rail stops")
    p = DesignParams(platform="gbsar", carrier_frequency_hz=float(f.mean()),
                     frequency_start_hz=float(f[0]), frequency_stop_hz=float(f[-1]), n_frequencies=int(f.size),
                     rail_length_m=float(x[-1] - x[0]), rail_step_m=float(np.median(np.diff(x))),
                     antenna_length_m=s.antenna.length_azimuth_m,
                     beamwidth_deg=math.degrees(s.antenna.beamwidth_rad),
                     antenna_height_m=float(np.mean(s.rail_height)), source=Path(path).name)
    return validate(p, str(path))


def from_stripmap_scene(path: str | Path) -> DesignParams:
    """Design parameters of a ``sarcli simulate`` scene (the radar as simulated, swath = range window)."""
    from sarcli.sim.scene import LinearPlatform, OrbitPlatform, load_scene

    sc = load_scene(path)
    r, ant, pl = sc.radar, sc.antenna, sc.platform
    swath = r.n_samples * C_LIGHT / (2 * r.range_sampling_rate_hz)
    centre = C_LIGHT * r.window_start_s / 2 + swath / 2
    if isinstance(pl, LinearPlatform):
        platform, height, speed = "airborne", pl.height_m, pl.velocity_mps
    elif isinstance(pl, OrbitPlatform):
        a = pl.elements.semi_major_axis_m
        platform, height, speed = "spaceborne", a - WGS84_A, math.sqrt(3.986004418e14 / a)
    else:
        k = len(pl.time) // 2
        platform = "spaceborne"
        height = float(np.linalg.norm(pl.position[k])) - WGS84_A
        speed = float(np.linalg.norm(pl.velocity[k]))
    p = DesignParams(platform=platform, carrier_frequency_hz=r.carrier_frequency_hz,
                     chirp_rate_hz_per_s=r.chirp_rate_hz_per_s, pulse_length_s=r.pulse_length_s,
                     altitude_m=height, velocity_mps=speed, look_angle_deg=math.degrees(ant.look_angle_rad),
                     look_angle_from="nadir", antenna_length_m=ant.length_m, swath_slant_m=swath,
                     slant_range_m=centre, prf_hz=(r.prf_hz,), source=Path(path).name)
    return validate(p, str(path))


def from_gbsar_scene(path: str | Path) -> DesignParams:
    """Design parameters of a ``sarcli gbsar simulate`` scene."""
    from sarcli.gbsar.scene import load_scene

    sc = load_scene(path)
    x = np.asarray(sc.positions_m)
    p = DesignParams(platform="gbsar", carrier_frequency_hz=sc.center_frequency_hz,
                     frequency_start_hz=sc.center_frequency_hz - sc.bandwidth_hz / 2,
                     frequency_stop_hz=sc.center_frequency_hz + sc.bandwidth_hz / 2, n_frequencies=int(sc.points),
                     rail_length_m=float(x[-1] - x[0]), rail_step_m=float(np.median(np.diff(x))),
                     antenna_length_m=sc.antenna.length_azimuth_m,
                     beamwidth_deg=math.degrees(sc.antenna.beamwidth_rad), antenna_height_m=sc.height_m,
                     source=Path(path).name)
    return validate(p, str(path))


def load(path: str | Path) -> DesignParams:
    """Design parameters from a design TOML, a stripmap or GB-SAR scene, a raw product or a GB-SAR scan."""
    path = Path(path)
    if not path.exists():
        raise ConfigError(f"{path}: no such file")
    if path.suffix.lower() == ".toml":
        doc = load_toml(path)
        if "design" in doc or not ("platform" in doc or "rail" in doc):
            return from_toml(path, doc)
        return from_stripmap_scene(path) if "platform" in doc else from_gbsar_scene(path)
    from sarcli.io.h5common import attr_str, open_product

    with open_product(path) as f:
        ptype = attr_str(f, "product_type")
    if ptype == "raw":
        return from_raw(path)
    if ptype == "gbsar_scan":
        return from_scan(path)
    raise ProductError(f"{path}: a '{ptype}' product carries no design; give a raw, gbsar_scan or design TOML")
