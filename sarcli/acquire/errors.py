"""Instrument errors: kinds of :class:`sarcli.errors.InstrumentError` (the CLI prints one line, exit 3).

``Interrupted`` (Ctrl-C, exit 130) is :class:`sarcli.errors.Interrupted`, re-exported here.
"""

from __future__ import annotations

from sarcli.errors import InstrumentError, Interrupted

__all__ = ["ALARM_TEXT", "GRBL_ERROR_TEXT", "Disconnected", "GarbledData", "InstrumentError", "InstrumentTimeout",
           "Interrupted", "RailAlarm"]


class InstrumentTimeout(InstrumentError):
    """No (complete) answer before the deadline."""


class GarbledData(InstrumentError):
    """An answer arrived but could not be parsed (garbled digit, wrong length, short block)."""


class Disconnected(InstrumentError):
    """The serial port went away (USB unplugged, emulator closed)."""


class RailAlarm(InstrumentError):
    """GRBL raised ``ALARM:N``; motion is stopped and the position may be lost."""

    def __init__(self, code: int, message: str = ""):
        self.code = code
        super().__init__(message or f"GRBL ALARM:{code} ({ALARM_TEXT.get(code, 'unknown alarm')})")


ALARM_TEXT = {
    1: "hard limit triggered", 2: "soft limit: target beyond travel", 3: "reset while in motion",
    4: "probe fail", 5: "probe fail", 6: "homing fail: reset during cycle", 7: "homing fail: door",
    8: "homing fail: pull-off did not clear the switch", 9: "homing fail: limit switch not found",
}

GRBL_ERROR_TEXT = {
    1: "expected command letter", 2: "bad number format", 3: "invalid $ statement",
    5: "homing not enabled", 8: "not idle", 9: "G-code locked out during alarm or jog",
    10: "soft limits need homing", 11: "line too long", 15: "jog beyond travel",
    20: "unsupported command", 22: "undefined feed rate", 33: "invalid target",
}
