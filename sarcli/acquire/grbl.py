"""A single-axis (X) rail on a GRBL 1.1 controller.

Lines end with LF and are answered by ``ok`` or ``error:N``; an ``ok`` for a move means *queued*.
The move-finished check is GRBL's official synchronisation: ``G4 P0.01`` (a 10 ms dwell) is only
acknowledged after the planner has emptied, then one ``?`` status report must show ``Idle`` and
MPos equal to the target (3 decimals). Real-time bytes (``?`` status, ``!`` feed hold, 0x18 soft
reset) need no line end. ``ALARM:N`` anywhere stops everything (:class:`RailAlarm`).
Positions here are machine X in mm; :class:`GrblRail` converts from the scan's metres.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field

from sarcli.acquire.errors import (
    GRBL_ERROR_TEXT,
    GarbledData,
    InstrumentError,
    InstrumentTimeout,
    RailAlarm,
)
from sarcli.acquire.motion import move_time
from sarcli.acquire.port import Port

POSITION_TOLERANCE_MM = 0.0015  # MPos is reported with 3 decimals
_STATUS = re.compile(r"^<([A-Za-z]+(?::\d)?)\|(.*)>$")


class GrblError(InstrumentError):
    """GRBL answered ``error:N``."""

    def __init__(self, code: int, line: str):
        self.code = code
        super().__init__(f"GRBL rejected '{line}': error:{code} ({GRBL_ERROR_TEXT.get(code, 'unknown')})")


@dataclass
class Status:
    """A parsed ``<State|MPos:x,y,z|...>`` report (mm)."""

    state: str
    x_mm: float
    fields: dict[str, str] = field(default_factory=dict)


def parse_status(line: str) -> Status:
    m = _STATUS.match(line.strip())
    if not m:
        raise GarbledData(f"GRBL status report '{line.strip()[:60]}' is malformed")
    fields = {}
    for part in m.group(2).split("|"):
        key, _, value = part.partition(":")
        fields[key] = value
    pos = fields.get("MPos", fields.get("WPos"))
    try:
        x = float(pos.split(",")[0])
    except (AttributeError, ValueError):
        raise GarbledData(f"GRBL status report '{line.strip()[:60]}' has no readable position") from None
    return Status(m.group(1), x, fields)


class GrblRail:
    """The rail on ``port``. ``retries`` bounds re-sends of a rejected/garbled exchange."""

    def __init__(self, port: Port, retries: int = 2, timeout_s: float = 2.0, boot_timeout_s: float = 3.0):
        self.port, self.retries = port, int(retries)
        self.timeout_s, self.boot_timeout_s = float(timeout_s), float(boot_timeout_s)
        self.banner = ""
        self.version = ""
        self.settings: dict[int, float] = {}
        self.messages: list[str] = []
        self.retry_count = 0
        self.in_motion = False  # between a move command and its confirmation

    # -- line exchange -------------------------------------------------------------------------
    def _line(self, deadline: float) -> str:
        return self.port.read_until(b"\n", deadline).decode("ascii", "replace").strip()

    def command(self, line: str, timeout_s: float | None = None) -> list[str]:
        """Send one line, return the informational lines before its ``ok``."""
        self.port.write(line.encode("ascii") + b"\n")
        deadline = time.monotonic() + (self.timeout_s if timeout_s is None else timeout_s)
        info: list[str] = []
        while True:
            try:
                text = self._line(deadline)
            except InstrumentTimeout:
                raise InstrumentTimeout(f"rail: no 'ok' for '{line}' from {self.port.path}") from None
            if text == "ok":
                return info
            if text.startswith("error:"):
                raise GrblError(_code(text), line)
            if text.startswith("ALARM:"):
                raise RailAlarm(_code(text))
            if text:
                if text.startswith("[MSG:"):
                    self.messages.append(text)
                info.append(text)

    def status(self) -> Status:
        """One ``?`` report (re-asked when garbled or missing)."""
        last: Exception | None = None
        for _ in range(self.retries + 1):
            self.port.write(b"?")
            deadline = time.monotonic() + self.timeout_s
            try:
                while True:
                    text = self._line(deadline)
                    if text.startswith("ALARM:"):
                        raise RailAlarm(_code(text))
                    if text.startswith("<"):
                        return parse_status(text)
            except (InstrumentTimeout, GarbledData) as e:
                last = e
                self.retry_count += 1
        raise InstrumentError(f"rail: no valid status report after {self.retries + 1} tries: {last}")

    # -- connection ------------------------------------------------------------------------------
    def connect(self) -> str:
        """Soft-reset, wait for the ``Grbl 1.1x`` banner and check ``$I``; returns the version."""
        self.port.discard_input()
        self.soft_reset()
        deadline = time.monotonic() + self.boot_timeout_s
        while True:
            try:
                text = self._line(deadline)
            except InstrumentTimeout:
                raise InstrumentError(
                    f"no GRBL banner from {self.port.path} after a soft reset; is this the rail port?") from None
            if text.startswith("Grbl "):
                self.banner = text
                break
        if not self.banner.startswith("Grbl 1.1"):
            raise InstrumentError(f"rail: expected GRBL 1.1, the banner is '{self.banner[:40]}'")
        st = self.status()
        if st.state == "Alarm":
            self.unlock()
        ver = [t for t in self.command("$I") if t.startswith("[VER:")]
        if not ver or not ver[0].startswith("[VER:1.1"):
            raise InstrumentError(f"rail: '$I' did not report a GRBL 1.1 version ({ver[:1]})")
        self.version = ver[0][5:].rstrip("]").rstrip(":")
        self.settings = self.read_settings()
        self.command("G21 G90")
        return self.version

    def read_settings(self) -> dict[int, float]:
        out = {}
        for text in self.command("$$"):
            m = re.match(r"^\$(\d+)=([-+0-9.]+)", text)
            if m:
                out[int(m.group(1))] = float(m.group(2))
        return out

    def unlock(self) -> None:
        self.command("$X")

    def home(self, timeout_s: float = 120.0) -> None:
        self.command("$H", timeout_s=timeout_s)

    def soft_reset(self) -> None:
        """0x18; after a reset in motion GRBL raises ALARM:3 and the position is lost."""
        self.port.write(b"\x18")

    def feed_hold(self) -> None:
        self.port.write(b"!")

    # -- motion ----------------------------------------------------------------------------------
    @property
    def max_rate_mm_min(self) -> float:
        return self.settings.get(110, 500.0)

    @property
    def accel_mm_s2(self) -> float:
        return self.settings.get(120, 10.0)

    @property
    def max_travel_mm(self) -> float:
        return self.settings.get(130, 200.0)

    def move_to(self, x_mm: float, feed_mm_min: float) -> Status:
        """Absolute move to ``x_mm`` and wait until it is finished and confirmed by MPos.

        A lost ``ok`` for the move line is not fatal: the ``G4`` dwell and the read-back decide
        whether the move was taken (a move that was not is sent again, it is absolute).
        """
        feed = min(feed_mm_min, self.max_rate_mm_min)
        self.in_motion = True
        for attempt in range(self.retries + 1):
            start = self.status().x_mm
            duration = move_time(x_mm - start, feed / 60.0, self.accel_mm_s2)
            deadline = time.monotonic() + 2.0 * duration + self.timeout_s
            try:
                try:
                    self.command(f"G1 X{x_mm:.3f} F{feed:.0f}")
                except InstrumentTimeout:
                    self.retry_count += 1
                self.command("G4 P0.01", timeout_s=2.0 * duration + self.timeout_s)
            except GrblError as e:
                if attempt == self.retries or e.code in (9, 33):  # locked / impossible: do not insist
                    raise
                self.retry_count += 1
                continue
            st = self.wait_idle(deadline)
            if st.state == "Idle" and abs(st.x_mm - x_mm) <= POSITION_TOLERANCE_MM:
                self.in_motion = False
                return st
            self.retry_count += 1
        raise InstrumentError(
            f"rail: move to X{x_mm:.3f} mm not confirmed (state {st.state}, MPos X{st.x_mm:.3f})")

    def wait_idle(self, deadline: float, poll_s: float = 0.05) -> Status:
        """Status reports until the axis is no longer running (or the deadline)."""
        while True:
            st = self.status()
            if st.state not in ("Run", "Jog", "Home") or time.monotonic() > deadline:
                return st
            time.sleep(poll_s)


def _code(text: str) -> int:
    try:
        return int(text.split(":", 1)[1])
    except (IndexError, ValueError):
        return -1
