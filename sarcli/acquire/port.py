"""A serial port with deadlines: pyserial underneath, a private buffer on top.

pyserial's own ``timeout`` is kept short and fixed (``poll_s``); every read here takes an absolute
deadline (``time.monotonic()`` seconds) instead, so a caller can wait long (a sweep) while still
checking a stop flag (Ctrl-C) every ``poll_s``. Any OS-level failure of the port (USB unplugged,
pseudo-terminal closed) becomes :class:`~sarcli.acquire.errors.Disconnected`.

pyserial is the optional dependency of the ``acquire`` extra (``pip install 'sarcli[acquire]'``; see
docs/acquisition.md for why): without it this module still imports, and :func:`require_pyserial`
(called before any work by the acquisition workflows, and by :class:`Port`) refuses in one line.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from sarcli.acquire.errors import Disconnected, InstrumentError, InstrumentTimeout, Interrupted
from sarcli.errors import ConfigError

try:
    import serial
except ImportError:  # the acquire extra is not installed: processing still works
    serial = None


def require_pyserial() -> None:
    """One :class:`ConfigError` line when pyserial (the ``acquire`` extra) is not installed."""
    if serial is None:
        raise ConfigError("talking to instruments needs pyserial, which is not installed: "
                          "pip install 'sarcli[acquire]' (or pip install pyserial)")


class Port:
    """Byte stream to one instrument. ``name`` is used in error messages ("VNA", "rail")."""

    def __init__(self, path: str, name: str, baudrate: int = 115200, poll_s: float = 0.02,
                 stop_requested: Callable[[], bool] | None = None):
        require_pyserial()
        self.path, self.name = path, name
        self._buf = bytearray()
        self._stop = stop_requested or (lambda: False)
        try:
            self.ser = serial.Serial(path, baudrate=baudrate, timeout=poll_s, write_timeout=5.0)
        except (serial.SerialException, OSError, ValueError) as e:
            raise InstrumentError(f"cannot open the {name} port {path}: {_reason(e)}") from None
        self.sent: list[bytes] = []  # wire log of everything written (protocol conformance tests)
        self.log_writes = False

    # -- writing ----------------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if self.log_writes:
            self.sent.append(bytes(data))
        try:
            self.ser.write(data)
        except (serial.SerialException, OSError) as e:
            raise Disconnected(f"{self.name} port {self.path} disconnected ({_reason(e)})") from None

    # -- reading ----------------------------------------------------------------------------
    def _fill(self) -> None:
        if self._stop():
            raise Interrupted("interrupted by the user")
        try:
            n = self.ser.in_waiting
            chunk = self.ser.read(n if n > 0 else 1)
        except (serial.SerialException, OSError) as e:
            raise Disconnected(f"{self.name} port {self.path} disconnected ({_reason(e)})") from None
        self._buf += chunk

    def read_until(self, terminator: bytes, deadline: float) -> bytes:
        """Bytes up to and including ``terminator``; InstrumentTimeout at the deadline."""
        start = 0
        while True:
            i = self._buf.find(terminator, start)
            if i >= 0:
                out = bytes(self._buf[: i + len(terminator)])
                del self._buf[: i + len(terminator)]
                return out
            start = max(0, len(self._buf) - len(terminator) + 1)
            if time.monotonic() > deadline:
                raise InstrumentTimeout(f"{self.name} at {self.path} did not answer in time")
            self._fill()

    def read_exact(self, n: int, deadline: float) -> bytes:
        """Exactly ``n`` bytes; InstrumentTimeout (short block) at the deadline."""
        while len(self._buf) < n:
            if time.monotonic() > deadline:
                raise InstrumentTimeout(
                    f"{self.name} at {self.path} sent {len(self._buf)} of {n} expected bytes")
            self._fill()
        out = bytes(self._buf[:n])
        del self._buf[:n]
        return out

    def read_lines_until(self, n_terminators: int, terminator: bytes, deadline: float) -> bytes:
        """Everything up to the ``n_terminators``-th ``terminator`` (one block, for long ASCII arrays)."""
        count, pos = 0, 0
        while True:
            while count < n_terminators:
                i = self._buf.find(terminator, pos)
                if i < 0:
                    break
                count, pos = count + 1, i + len(terminator)
            if count == n_terminators:
                out = bytes(self._buf[:pos])
                del self._buf[:pos]
                return out
            if time.monotonic() > deadline:
                raise InstrumentTimeout(
                    f"{self.name} at {self.path} sent {count} of {n_terminators} expected lines")
            self._fill()

    def discard_input(self) -> None:
        """Drop everything received so far (stale answers after a timeout or a garbled block)."""
        self._buf.clear()
        try:
            self.ser.reset_input_buffer()
        except (serial.SerialException, OSError) as e:
            raise Disconnected(f"{self.name} port {self.path} disconnected ({_reason(e)})") from None

    def drain(self, quiet_s: float = 0.05, limit_s: float = 2.0) -> None:
        """Discard input until the line has been quiet for ``quiet_s`` (the tail of a bad block)."""
        self.discard_input()
        end = time.monotonic() + limit_s
        quiet_until = time.monotonic() + quiet_s
        while time.monotonic() < min(quiet_until, end):
            before = len(self._buf)
            self._fill()
            if len(self._buf) > before:
                self._buf.clear()
                quiet_until = time.monotonic() + quiet_s

    def close(self) -> None:
        try:
            self.ser.close()
        except (serial.SerialException, OSError):
            pass


def _reason(e: BaseException) -> str:
    text = str(e).strip() or type(e).__name__
    return text.splitlines()[0]
