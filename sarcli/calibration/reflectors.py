"""Corner-reflector CSV files and the reflector's position at the acquisition time.

Two formats (the columns are positional; header rows before the first reflector (rows whose numeric
columns hold no number) and ``#`` comment lines are skipped):

- NISAR (Corner Reflector Software Interface Specification, JPL D-107698 [NISAR-CR-SIS]; 12 columns):
  ``ID, latitude (deg), longitude (deg), height above the WGS-84 ellipsoid (m), azimuth (deg), tilt /
  elevation (deg), side length (m), survey date (ISO-8601 UTC), validity, velocity east, north, up (m/s)``.
  A reflector may appear once per survey; the survey used is the latest not after the acquisition
  (:func:`select`). Validity is a bit field: 1 = impulse response (IRW, PSLR, ISLR), 2 = radiometric
  and polarimetric, 4 = geometry; 0 = out of service (dropped).
- UAVSAR (older, 7 columns): the first seven of the above; no survey date, validity or velocity (taken
  as surveyed at the acquisition, valid for everything, not moving).

Position at the acquisition (:func:`position_at`): the surveyed point moved by its velocity over the
time from the survey to the acquisition, in the local east-north-up frame of the surveyed point:
``p = p_survey + dt (v_e e + v_n n + v_u u)`` (ECEF; tectonic velocities are centimetres per year, so
the ENU frame of the surveyed point is exact to far below a millimetre).
"""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sarcli.errors import FormatError, MissingFileError

NISAR_COLUMNS = ("id", "latitude_deg", "longitude_deg", "height_m", "azimuth_deg", "tilt_deg", "side_length_m",
                 "survey_utc", "validity", "velocity_east_mps", "velocity_north_mps", "velocity_up_mps")
UAVSAR_COLUMNS = NISAR_COLUMNS[:7]
VALIDITY_IPR, VALIDITY_RAD_POL, VALIDITY_GEOMETRY = 1, 2, 4


@dataclass(frozen=True)
class CornerReflector:
    """One survey of a corner reflector (module docstring). ``survey_utc`` None: UAVSAR format."""

    id: str
    latitude_deg: float
    longitude_deg: float
    height_m: float
    azimuth_deg: float
    tilt_deg: float
    side_length_m: float
    survey_utc: str | None = None
    validity: int = VALIDITY_IPR | VALIDITY_RAD_POL | VALIDITY_GEOMETRY
    velocity_enu_mps: tuple[float, float, float] = (0.0, 0.0, 0.0)
    line: int = 0


def _number(text: str, what: str, where: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise FormatError(f"{where}: {what} {text.strip()!r} is not a number") from None
    if not math.isfinite(v):
        raise FormatError(f"{where}: {what} is {text.strip()}, not a finite number")
    return v


def _is_header(row: list[str]) -> bool:
    """A header row: none of the six numeric columns after the ID (latitude ... side length) is a number
    (``ID,lat,lon,...``, ``"Corner reflector ID","Latitude (deg)",...``, a row of units)."""

    def number(text: str) -> bool:
        try:
            float(text)
        except ValueError:
            return False
        return True

    return not any(number(x) for x in row[1:7])


def parse_reflectors(path: str | os.PathLike) -> list[CornerReflector]:
    """Every row of a NISAR or UAVSAR corner-reflector CSV (module docstring); one line on a bad row."""
    from orbit.timeutil import format_utc, parse_utc

    path = Path(path)
    if not path.is_file():
        raise MissingFileError(f"{path}: no such file")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise FormatError(f"{path}: not a text (UTF-8) CSV file") from None
    out: list[CornerReflector] = []
    for k, row in enumerate(csv.reader(io.StringIO(text)), start=1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#") or (not out and _is_header(row)):
            continue  # blank, comment, or a header row before the first reflector
        where = f"{path} line {k}"
        if len(row) not in (len(NISAR_COLUMNS), len(UAVSAR_COLUMNS)):
            raise FormatError(f"{where}: {len(row)} columns; a NISAR corner-reflector CSV has 12, the UAVSAR one 7")
        cid = row[0].strip().strip('"')
        if not cid:
            raise FormatError(f"{where}: empty corner reflector ID")
        lat, lon, h, az, tilt, side = (_number(row[i], UAVSAR_COLUMNS[i], where) for i in range(1, 7))
        if not -90.0 <= lat <= 90.0:
            raise FormatError(f"{where}: latitude {lat} is outside [-90, 90] degrees")
        if not -360.0 <= lon <= 360.0:
            raise FormatError(f"{where}: longitude {lon} is outside [-360, 360] degrees")
        if not side > 0:
            raise FormatError(f"{where}: side length {side} m must be positive")
        survey, validity, vel = None, VALIDITY_IPR | VALIDITY_RAD_POL | VALIDITY_GEOMETRY, (0.0, 0.0, 0.0)
        if len(row) == len(NISAR_COLUMNS):
            try:
                survey = format_utc(parse_utc(row[7].strip()))
            except ValueError:
                raise FormatError(f"{where}: survey date {row[7].strip()!r} is not ISO-8601 UTC") from None
            v = _number(row[8], "validity", where)
            if v != int(v) or not 0 <= v <= 7:
                raise FormatError(f"{where}: validity {row[8].strip()} is not a flag value 0..7")
            validity = int(v)
            vel = tuple(_number(row[i], NISAR_COLUMNS[i], where) for i in range(9, 12))  # type: ignore[assignment]
        out.append(CornerReflector(cid, lat, lon, h, az, tilt, side, survey, validity, vel, k))
    if not out:
        raise FormatError(f"{path}: no corner reflector in the file")
    return out


def select(reflectors: list[CornerReflector], acquisition_utc: str,
           need: int = 0) -> tuple[list[CornerReflector], list[str]]:
    """For each ID the latest survey not after the acquisition; out-of-service ones (validity 0) and
    those lacking the flags ``need`` (e.g. VALIDITY_GEOMETRY) dropped. Returns (kept, notes)."""
    from orbit.timeutil import parse_utc

    t_acq = parse_utc(acquisition_utc)
    latest: dict[str, CornerReflector] = {}
    later = set()
    for cr in reflectors:
        if cr.survey_utc is not None and parse_utc(cr.survey_utc) > t_acq:
            later.add(cr.id)
            continue
        old = latest.get(cr.id)
        if old is None or (cr.survey_utc or "") > (old.survey_utc or ""):
            latest[cr.id] = cr
    notes = []
    never = sorted(later - set(latest))
    if never:
        notes.append(f"surveyed only after the acquisition, not used: {', '.join(never)}")
    kept = []
    for cr in latest.values():
        if cr.validity == 0:
            notes.append(f"{cr.id}: out of service (validity 0) at the acquisition, not used")
        elif need and not cr.validity & need:
            notes.append(f"{cr.id}: validity {cr.validity} lacks flag {need}, not used")
        else:
            kept.append(cr)
    return kept, notes


def enu_basis(lat_deg: float, lon_deg: float) -> np.ndarray:
    """(3, 3) columns east, north, up (ECEF components) at a geodetic latitude/longitude."""
    la, lo = math.radians(lat_deg), math.radians(lon_deg)
    return np.array([[-math.sin(lo), -math.sin(la) * math.cos(lo), math.cos(la) * math.cos(lo)],
                     [math.cos(lo), -math.sin(la) * math.sin(lo), math.cos(la) * math.sin(lo)],
                     [0.0, math.cos(la), math.sin(la)]])


def position_at(cr: CornerReflector, acquisition_utc: str) -> tuple[np.ndarray, float]:
    """(ECEF position at the acquisition (m), seconds from the survey to the acquisition)."""
    from orbit.geodetic import geodetic_to_ecef
    from sarcli.io.nisar.h5util import seconds_between

    p = np.asarray(geodetic_to_ecef(cr.latitude_deg, cr.longitude_deg, cr.height_m), np.float64).reshape(3)
    if cr.survey_utc is None:
        return p, 0.0
    dt = seconds_between(acquisition_utc, cr.survey_utc)
    return p + dt * (enu_basis(cr.latitude_deg, cr.longitude_deg) @ np.asarray(cr.velocity_enu_mps)), dt


def write_reflectors(path: str | os.PathLike, reflectors: list[CornerReflector]) -> None:
    """A NISAR-format CSV (header and 12 columns), written atomically; survey date defaults to the epoch."""
    from sarcli.io.atomic import atomic_path

    header = ("Corner reflector ID,Latitude (deg),Longitude (deg),Height above ellipsoid (m),Azimuth (deg),"
              "Tilt / Elevation (deg),Side length (m),Survey Date,Validity,Velocity East (m/s),"
              "Velocity North (m/s),Velocity Up (m/s)")
    lines = [header]
    for cr in reflectors:
        ve, vn, vu = cr.velocity_enu_mps
        lines.append(f"{cr.id},{cr.latitude_deg!r},{cr.longitude_deg!r},{cr.height_m!r},{cr.azimuth_deg!r},"
                     f"{cr.tilt_deg!r},{cr.side_length_m!r},{(cr.survey_utc or '1970-01-01T00:00:00.000000Z')[:26]},"
                     f"{cr.validity},{ve!r},{vn!r},{vu!r}")
    with atomic_path(path, ".csv") as tmp:
        Path(tmp).write_text("\n".join(lines) + "\n", encoding="utf-8")
