"""Meteorological inputs: a CSV of temperature, humidity and pressure, interpolated at the scan times,
and the radio refractivity they give.

CSV (header required, other columns ignored): ``time_utc`` (ISO-8601), ``temperature_c`` (deg C),
``humidity_percent`` (relative humidity, %), ``pressure_hpa`` (hPa). Values are interpolated linearly
at a scan's time between the two nearest rows; a scan more than ``max_gap_s`` from every row has none.
A logger may append to the file during a campaign: only the bytes added since the last read are parsed.

Refractivity [SmithWeintraub1953]: ``N = 77.6 P/T + 3.73e5 e/T^2`` (ppm; P and the water-vapour
pressure e in hPa, T in K), with ``e = RH/100 * 6.1121 exp(17.502 t/(240.97 + t))`` (t in deg C)
[Buck1981]. It is stored beside the APS's range coefficient expressed as a refractivity change, so
the two can be compared on the page (the APS itself is estimated from the stable points only).
"""

from __future__ import annotations

import bisect
import csv
import datetime as dt
import io
import math
import os
from pathlib import Path

from sarcli.errors import MissingFileError, ProductError

COLUMNS = ("time_utc", "temperature_c", "humidity_percent", "pressure_hpa")


def refractivity_ppm(temperature_c: float, humidity_percent: float, pressure_hpa: float) -> float:
    """Radio refractivity N (ppm) of moist air [SmithWeintraub1953], vapour pressure from [Buck1981]."""
    t_k = temperature_c + 273.15
    e = humidity_percent / 100.0 * 6.1121 * math.exp(17.502 * temperature_c / (240.97 + temperature_c))
    return 77.6 * pressure_hpa / t_k + 3.73e5 * e / (t_k * t_k)


def _posix(text: str, where: str) -> float:
    try:
        t = dt.datetime.fromisoformat(text.strip().replace("Z", "+00:00"))
    except ValueError:
        raise ProductError(f"{where}: unreadable time_utc '{text}'") from None
    if t.tzinfo is None:
        t = t.replace(tzinfo=dt.UTC)
    return t.timestamp()


class MeteoFile:
    """Rows of a meteo CSV, sorted by time, re-read incrementally as the file grows."""

    def __init__(self, path: str | os.PathLike, max_gap_s: float = 3600.0):
        self.path, self.max_gap_s = Path(path), max_gap_s
        self.offset = 0
        self.header: list[str] | None = None
        self.times: list[float] = []
        self.rows: list[tuple[float, float, float]] = []
        self._tail = ""

    def _refresh(self) -> None:
        if not self.path.exists():
            raise MissingFileError(f"{self.path}: meteo file not found")
        if self.path.stat().st_size < self.offset:  # replaced by a shorter file: read it again
            self.offset, self.header, self.times, self.rows, self._tail = 0, None, [], [], ""
        with open(self.path, encoding="utf-8") as fh:
            fh.seek(self.offset)
            text = self._tail + fh.read()
            self.offset = fh.tell()
        complete, _, self._tail = text.rpartition("\n")
        if not complete:
            return
        lines = list(csv.reader(io.StringIO(complete)))
        if self.header is None:
            self.header = [h.strip() for h in lines.pop(0)] if lines else None
            missing = [c for c in COLUMNS if self.header is None or c not in self.header]
            if missing:
                raise ProductError(f"{self.path}: meteo CSV needs the columns {', '.join(COLUMNS)} "
                                   f"(missing {', '.join(missing)})")
        idx = [self.header.index(c) for c in COLUMNS]
        for n, line in enumerate(lines):
            if not line or not "".join(line).strip():
                continue
            where = f"{self.path} row {len(self.times) + n + 2}"
            try:
                t = _posix(line[idx[0]], where)
                vals = tuple(float(line[i]) for i in idx[1:])
            except (IndexError, ValueError):
                raise ProductError(f"{where}: expected {', '.join(COLUMNS)}") from None
            k = bisect.bisect(self.times, t)
            self.times.insert(k, t)
            self.rows.insert(k, vals)

    def at(self, posix_s: float) -> dict[str, float] | None:
        """Interpolated values and refractivity at ``posix_s``, or None without rows near it."""
        self._refresh()
        if not self.times:
            return None
        k = bisect.bisect(self.times, posix_s)
        lo, hi = max(k - 1, 0), min(k, len(self.times) - 1)
        if min(abs(posix_s - self.times[lo]), abs(posix_s - self.times[hi])) > self.max_gap_s:
            return None
        if hi == lo or self.times[hi] == self.times[lo]:
            vals = self.rows[lo] if abs(posix_s - self.times[lo]) <= abs(posix_s - self.times[hi]) else self.rows[hi]
        else:
            f = min(max((posix_s - self.times[lo]) / (self.times[hi] - self.times[lo]), 0.0), 1.0)
            vals = tuple(a + f * (b - a) for a, b in zip(self.rows[lo], self.rows[hi], strict=True))
        t, rh, p = vals
        return {"temperature_c": t, "humidity_percent": rh, "pressure_hpa": p,
                "refractivity_ppm": refractivity_ppm(t, rh, p)}
