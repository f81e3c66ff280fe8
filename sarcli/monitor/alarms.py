"""Alarm levels per area with hysteresis, the alarm events, and the ``--on-alarm`` hook.

Levels: 0 none, 1 attention, 2 pre-alarm, 3 alarm. An area's level from a quantity is the highest
threshold its value reaches (velocity: ``|v|``; acceleration: along the velocity, ``a sign(v)``, so a
slope that slows down raises nothing); the area's level is the higher of the two. Rising is
immediate (an alarm must not wait); falling is hysteretic: the level drops only after ``clear_scans``
consecutive scans whose level, with every threshold lowered by the factor ``1 - hysteresis``, stays
below the current one, so one noisy scan neither raises and drops an alarm in turn nor clears it. A
scan without a value (no measured point in the area) changes nothing.

Each change of level is an event: a line in ``alarms.csv``, a log line and, when a hook command is
given, the command run by the shell with the event as JSON on its standard input. A hook that fails,
hangs past its timeout or cannot start is logged and the campaign goes on.
"""

from __future__ import annotations

import json
import logging
import math
import subprocess
from dataclasses import dataclass
from typing import Any

from sarcli.io.h5common import to_jsonable
from sarcli.monitor.config import LEVELS, AreaEntry

log = logging.getLogger("sarcli.monitor")

CSV_COLUMNS = ("time_utc", "scan", "area", "event", "level", "previous_level", "trigger", "value", "threshold",
               "velocity_mm_per_h", "acceleration_mm_per_h2", "forecast_failure_utc")


def level_of(value: float, thresholds: tuple[float, float, float] | None, factor: float = 1.0) -> int:
    """Highest level whose threshold (times ``factor``) ``value`` reaches (0 below all, or no thresholds)."""
    if thresholds is None or not math.isfinite(value):
        return 0
    return sum(value >= factor * t for t in thresholds)


@dataclass
class AlarmState:
    """An area's current level and the count of consecutive scans satisfying the clear condition."""

    level: int = 0
    below: int = 0


def step(state: AlarmState, area: AreaEntry, velocity: float, acceleration: float
         ) -> tuple[AlarmState, dict[str, Any] | None]:
    """Advance ``state`` by one scan; returns the new state and the event (None: no change of level)."""
    if not math.isfinite(velocity):
        return state, None
    a_along = acceleration * math.copysign(1.0, velocity) if math.isfinite(acceleration) else math.nan
    lv = level_of(abs(velocity), area.velocity_mm_per_h)
    la = level_of(a_along, area.acceleration_mm_per_h2)
    target = max(lv, la)
    if target > state.level:
        trig = ("velocity", abs(velocity), area.velocity_mm_per_h) if lv >= la else \
            ("acceleration", a_along, area.acceleration_mm_per_h2)
        thr = trig[2][target - 1] if trig[2] is not None else math.nan
        return AlarmState(target, 0), {"event": "raised", "level": LEVELS[target],
                                       "previous_level": LEVELS[state.level], "trigger": trig[0],
                                       "value": trig[1], "threshold": thr}
    f = 1.0 - area.hysteresis
    low = max(level_of(abs(velocity), area.velocity_mm_per_h, f), level_of(a_along, area.acceleration_mm_per_h2, f))
    if low >= state.level:
        return AlarmState(state.level, 0), None
    below = state.below + 1
    if below < area.clear_scans:
        return AlarmState(state.level, below), None
    return AlarmState(low, 0), {"event": "lowered", "level": LEVELS[low], "previous_level": LEVELS[state.level],
                                "trigger": "velocity" if lv >= la else "acceleration",
                                "value": abs(velocity) if lv >= la else a_along, "threshold": math.nan}


def csv_line(event: dict[str, Any]) -> str:
    """One ``alarms.csv`` line (no quoting needed: names are checked not to hold commas)."""
    def fmt(v: Any) -> str:
        if v is None or (isinstance(v, float) and not math.isfinite(v)):
            return ""
        return f"{v:.4f}" if isinstance(v, float) else str(v)
    return ",".join(fmt(event.get(k)) for k in CSV_COLUMNS) + "\n"


def csv_header() -> str:
    return ",".join(CSV_COLUMNS) + "\n"


def describe(event: dict[str, Any]) -> str:
    """The log line of an event."""
    fc = f", failure forecast {event['forecast_failure_utc']}" if event.get("forecast_failure_utc") else ""
    return (f"ALARM {event['area']}: {event['previous_level']} -> {event['level']} at scan {event['scan']} "
            f"({event['time_utc']}; v = {event['velocity_mm_per_h']:.3f} mm/h, "
            f"a = {event['acceleration_mm_per_h2']:.3f} mm/h^2{fc})")


def run_hook(command: str, event: dict[str, Any], timeout_s: float) -> str | None:
    """Run ``command`` through the shell with ``event`` as JSON on stdin; the failure as text, or None."""
    try:
        r = subprocess.run(command, shell=True, input=json.dumps(to_jsonable(event), default=str),
                           capture_output=True, text=True, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return f"timed out after {timeout_s:g} s"
    except (OSError, ValueError) as e:
        return str(e)
    if r.returncode != 0:
        err = (r.stderr or "").strip().splitlines()
        return f"exit status {r.returncode}" + (f": {err[-1]}" if err else "")
    return None
