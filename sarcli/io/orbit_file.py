"""State-vector files -> :class:`~sarcli.model.raw.Orbit` (WGS-84 ECEF), to give an orbit to raw data that
carries none (a Cumming & Wong MATLAB block: ``sarcli ingest --matlab ... --orbit FILE``).

Two formats, told apart by their first bytes:

- **CSV**, one state vector per row: ``time_utc, x, y, z, vx, vy, vz``: the time ISO-8601 UTC
  (``2002-06-16T14:50:12.5Z``), positions in metres and velocities in m/s in the Earth-fixed frame
  (WGS-84 / ITRF, the frame of CEOS leaders and ESA orbit files). Header rows (a first field that is not a
  time) before the first vector, blank and ``#`` lines are skipped.
- **ESA Earth Explorer orbit file** (``.EOF``, XML; e.g. Sentinel-1 precise and restituted orbits)
  [ESA-EOF]: ``Data_Block/List_of_OSVs/OSV`` elements with ``UTC`` (``UTC=2020-06-15T16:22:09.000000``),
  ``X``, ``Y``, ``Z`` (m) and ``VX``, ``VY``, ``VZ`` (m/s), Earth-fixed.

Times become seconds after the product's epoch (``epoch_utc``). The vectors are then checked by
:meth:`Orbit.validate` (an Earth orbit, times increasing, chord and velocity consistent): a wrong unit
(km) or a wrong frame is refused in one line, as is any row that is not a state vector.
"""

from __future__ import annotations

import csv
import io
import math
import os
from pathlib import Path

import numpy as np

from orbit.timeutil import parse_utc
from sarcli.errors import FormatError, MissingFileError
from sarcli.model.raw import Orbit

COLUMNS = ("time_utc", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps")


def _seconds(text: str, epoch: str, where: str) -> float:
    try:
        t = parse_utc(text.strip().removeprefix("UTC="))
    except ValueError:
        raise FormatError(f"{where}: {text.strip()!r} is not an ISO-8601 UTC time") from None
    return (t - parse_utc(epoch)).total_seconds()


def _number(text: str, what: str, where: str) -> float:
    try:
        v = float(text)
    except (TypeError, ValueError):
        raise FormatError(f"{where}: {what} {str(text).strip()!r} is not a number") from None
    if not math.isfinite(v):
        raise FormatError(f"{where}: {what} is {str(text).strip()}, not a finite number")
    return v


def _is_time(text: str) -> bool:
    try:
        parse_utc(text)
    except ValueError:
        return False
    return True


def _read_csv(path: Path, text: str, epoch: str) -> list[list[float]]:
    rows: list[list[float]] = []
    for k, row in enumerate(csv.reader(io.StringIO(text)), start=1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        if not rows and not _is_time(row[0]):
            continue  # a header row
        where = f"{path} line {k}"
        if len(row) != len(COLUMNS):
            raise FormatError(f"{where}: {len(row)} columns; a state vector is {', '.join(COLUMNS)}")
        rows.append([_seconds(row[0], epoch, where)] + [_number(row[i], COLUMNS[i], where) for i in range(1, 7)])
    return rows


def _read_eof(path: Path, text: str, epoch: str) -> list[list[float]]:
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise FormatError(f"{path}: not a readable XML orbit file ({e})") from None
    rows = []
    for k, osv in enumerate(root.iter("OSV"), start=1):
        where = f"{path} OSV {k}"
        values = {}
        for tag in ("UTC", "X", "Y", "Z", "VX", "VY", "VZ"):
            node = osv.find(tag)
            if node is None or node.text is None:
                raise FormatError(f"{where}: no <{tag}>")
            values[tag] = node.text
        rows.append([_seconds(values["UTC"], epoch, where)] +
                    [_number(values[t], t, where) for t in ("X", "Y", "Z", "VX", "VY", "VZ")])
    return rows


def read_orbit_file(path: str | os.PathLike, epoch_utc: str) -> Orbit:
    """The state vectors of a CSV or ESA orbit file (module docstring), times in seconds after
    ``epoch_utc``, frame ECEF, validated."""
    path = Path(path)
    if not path.is_file():
        raise MissingFileError(f"{path}: no such file")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise FormatError(f"{path}: not a text orbit file (CSV or ESA XML)") from None
    rows = _read_eof(path, text, epoch_utc) if text.lstrip().startswith("<") else _read_csv(path, text, epoch_utc)
    if len(rows) < 2:
        raise FormatError(f"{path}: {len(rows)} state vector(s); an orbit needs at least two")
    a = np.array(rows, np.float64)
    orbit = Orbit(time=a[:, 0], position=a[:, 1:4], velocity=a[:, 4:7], frame="ECEF")
    orbit.validate(str(path))
    return orbit
