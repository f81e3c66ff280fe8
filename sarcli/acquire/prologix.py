"""Prologix GPIB-USB controller (firmware 6.x) as seen from the host serial port.

Host -> adapter: lines ended by LF. A line starting with an unescaped ``++`` is an adapter command;
anything else is sent to the instrument at ``++addr`` with the ``++eos`` terminator appended. Inside
instrument data, CR, LF, ESC (27) and ``+`` must each be preceded by ESC, otherwise the adapter
treats them as line ends or commands (binary uploads). Instrument -> host bytes pass unchanged;
with ``++auto 0`` the instrument talks only after ``++read eoi``, which gives up after
``++read_tmo_ms`` (1..3000 ms) of silence.
"""

from __future__ import annotations

import time

from sarcli.acquire.errors import InstrumentError, InstrumentTimeout
from sarcli.acquire.port import Port

ESC = 0x1B
_SPECIAL = frozenset(b"\r\n\x1b+")
#: default margin (s) added to the adapter's own read timeout before the host gives up on a ``++read``
READ_MARGIN_S = 0.25


def escape(data: bytes) -> bytes:
    """Precede every CR, LF, ESC and ``+`` of instrument data with ESC (Prologix manual, 'escaping')."""
    if not _SPECIAL.intersection(data):
        return data
    out = bytearray()
    for b in data:
        if b in _SPECIAL:
            out.append(ESC)
        out.append(b)
    return bytes(out)


def unescape_split(stream: bytes) -> tuple[list[tuple[bytes, bool]], bytes]:
    """Split a host byte stream into lines at unescaped CR/LF, removing the escapes.

    Returns ``([(line, is_adapter_command), ...], rest)`` where ``rest`` is an incomplete tail.
    The adapter side of the protocol (used by the emulator, and by tests as the reference decoder).
    """
    lines: list[tuple[bytes, bool]] = []
    cur = bytearray()
    escaped_start = False
    i, n = 0, len(stream)
    last_end = 0
    while i < n:
        b = stream[i]
        if b == ESC:
            if i + 1 >= n:
                break
            if not cur:
                escaped_start = True
            cur.append(stream[i + 1])
            i += 2
            continue
        if b in (10, 13):
            if cur:
                lines.append((bytes(cur), bytes(cur[:2]) == b"++" and not escaped_start))
            cur.clear()
            escaped_start = False
            i += 1
            last_end = i
            continue
        cur.append(b)
        i += 1
    return lines, stream[last_end:]


class Prologix:
    """The adapter in controller mode, ``++auto 0``, EOI on, LF appended to instrument data."""

    def __init__(self, port: Port, address: int = 16, read_tmo_ms: int = 500, retries: int = 3,
                 read_margin_s: float = READ_MARGIN_S):
        if not 1 <= read_tmo_ms <= 3000:
            raise InstrumentError(f"Prologix read timeout must be 1..3000 ms, got {read_tmo_ms}")
        self.port, self.read_tmo_ms, self.retries = port, int(read_tmo_ms), int(retries)
        self.read_margin_s = float(read_margin_s)
        self.home_address = int(address)
        self.address: int | None = None
        self.version = ""

    @property
    def read_window_s(self) -> float:
        """How long the host waits for the first byte after ``++read``."""
        return self.read_tmo_ms / 1000.0 + self.read_margin_s

    def adapter(self, command: str) -> None:
        """Send one ``++`` command (no escaping: it is for the adapter)."""
        self.port.write(b"++" + command.encode("ascii") + b"\n")

    def adapter_query(self, command: str) -> str:
        """An adapter query; its reply ends with CR LF. Retried on silence."""
        for attempt in range(self.retries + 1):
            self.port.discard_input()
            self.adapter(command)
            try:
                return self.port.read_until(b"\n", time.monotonic() + self.read_window_s).decode(
                    "ascii", "replace").strip()
            except InstrumentTimeout:
                if attempt == self.retries:
                    raise InstrumentTimeout(
                        f"no Prologix GPIB-USB adapter answered '++{command}' on {self.port.path}; "
                        "is this the VNA port?") from None
        raise AssertionError("unreachable")

    def init(self) -> str:
        """Configure the adapter and return its ``++ver`` string (identification)."""
        self.adapter("savecfg 0")  # first, so that the following settings are not written to EEPROM
        for cmd in ("mode 1", "auto 0", "eoi 1", "eos 2", f"read_tmo_ms {self.read_tmo_ms}"):
            self.adapter(cmd)
        self.select(self.home_address, force=True)
        self.version = self.adapter_query("ver")
        if "prologix" not in self.version.lower():
            raise InstrumentError(
                f"{self.port.path}: expected a Prologix GPIB-USB controller, '++ver' answered "
                f"'{self.version[:60]}'")
        return self.version

    def set_read_timeout(self, ms: int) -> None:
        """Change ``++read_tmo_ms`` (1..3000) if it differs from the current value."""
        ms = int(min(max(ms, 1), 3000))
        if ms != self.read_tmo_ms:
            self.adapter(f"read_tmo_ms {ms}")
            self.read_tmo_ms = ms

    def select(self, address: int, force: bool = False) -> None:
        """Address another GPIB device (``++addr``) if it is not the current one."""
        if force or address != self.address:
            if not 0 <= address <= 30:
                raise InstrumentError(f"GPIB address must be 0..30, got {address}")
            self.adapter(f"addr {address}")
            self.address = address

    def write(self, data: bytes | str) -> None:
        """Send instrument data (escaped) followed by the line end."""
        raw = data.encode("ascii") if isinstance(data, str) else data
        self.port.write(escape(raw) + b"\n")

    def request_read(self) -> None:
        """Let the instrument talk until EOI."""
        self.adapter("read eoi")
