"""Epochs and time scales.

Times in products are float64 seconds after an epoch stored once as an ISO-8601 UTC string.
UT1 is taken equal to UTC (|UT1-UTC| < 0.9 s, i.e. < 0.4 km of equatorial rotation at worst; the
difference is a documented part of the GMST-only model error, see ``orbit.frames``).
"""

from __future__ import annotations

import datetime as _dt

J2000_JD = 2451545.0
SECONDS_PER_DAY = 86400.0


def parse_utc(epoch_utc: str) -> _dt.datetime:
    """Parse an ISO-8601 UTC string ('2002-06-16T15:41:00.123456Z' or with +00:00) to an aware datetime."""
    s = epoch_utc.strip()
    if s.endswith("Z"):
        s = s[:-1] + "+00:00"
    try:
        t = _dt.datetime.fromisoformat(s)
    except ValueError:
        raise ValueError(f"not an ISO-8601 UTC time: {epoch_utc!r}") from None
    if t.tzinfo is None:
        t = t.replace(tzinfo=_dt.UTC)
    return t.astimezone(_dt.UTC)


def format_utc(t: _dt.datetime) -> str:
    """ISO-8601 UTC with microseconds and a trailing Z."""
    return t.astimezone(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def julian_date_parts(epoch_utc: str) -> tuple[float, float]:
    """(JD of 0h UTC of the epoch's day, seconds of day) — split to keep float64 precision."""
    t = parse_utc(epoch_utc)
    midnight = t.replace(hour=0, minute=0, second=0, microsecond=0)
    jd0 = midnight.toordinal() + 1721424.5  # proleptic Gregorian ordinal -> JD at 0h
    sod = (t - midnight).total_seconds()
    return float(jd0), float(sod)


def add_seconds(epoch_utc: str, seconds: float) -> str:
    """Epoch shifted by ``seconds`` (microsecond resolution)."""
    return format_utc(parse_utc(epoch_utc) + _dt.timedelta(seconds=float(seconds)))
