"""HP/Agilent 8753ES vector network analyzer in native HP-IB mnemonics, behind a Prologix adapter.

Commands end with ``;``; queries are the mnemonic plus ``?`` and answer one number + LF (parsed by
``strip()`` + ``float()``). ``OPC?;SING`` answers ``1`` LF when the single sweep is done; as the
adapter's ``++read`` gives up after its read timeout (<= 3 s), the host re-issues ``++read eoi``
until the ``1`` arrives or the sweep deadline passes. ``OUTPDATA`` returns the error-corrected data
array (re, im per point, start -> stop) in the current format:

- ``FORM4``: ASCII, per point ``<24 chars>,<24 chars>`` LF;
- ``FORM2`` / ``FORM3``: ``#A`` + uint16 big-endian byte count + float32 / float64 big-endian.

Every answer is validated (count of points, parsable numbers, finite values, block length) and
re-read up to ``retries`` times when it is garbled, short or missing.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sarcli.acquire.errors import GarbledData, InstrumentError, InstrumentTimeout
from sarcli.acquire.prologix import Prologix

ALLOWED_POINTS = (3, 11, 26, 51, 101, 201, 401, 801, 1601)
ALLOWED_IFBW_HZ = (10, 30, 100, 300, 1000, 3000, 3700, 6000)
MIN_FREQUENCY_HZ = 30e3
MAX_FREQUENCY_HZ = 3e9
MAX_FREQUENCY_OPT006_HZ = 6e9
#: depends on the attenuator range and options (uncertain, to verify on hardware); the readback check catches the rest
POWER_RANGE_DBM = (-85.0, 10.0)
PARAMETERS = ("S11", "S21", "S12", "S22")
BINARY_FORMATS = {"FORM2": ">f4", "FORM3": ">f8"}
DATA_FORMATS = ("FORM4", *BINARY_FORMATS)
#: sweep-time model for plans, s per point on top of 1/IFBW (fits the preset 201 pts at 3700 Hz
#: in 0.175 s); the scan itself uses the instrument's own ``SWET?``
SWEEP_OVERHEAD_PER_POINT_S = 6.0e-4


def estimated_sweep_time(points: int, if_bandwidth_hz: float) -> float:
    """Plan-level sweep time (s): N * (1/IFBW + overhead)."""
    return points * (1.0 / if_bandwidth_hz + SWEEP_OVERHEAD_PER_POINT_S)


@dataclass(frozen=True)
class VnaSettings:
    """One linear frequency sweep of one S-parameter (SI units)."""

    start_hz: float
    stop_hz: float
    points: int
    if_bandwidth_hz: float
    power_dbm: float
    parameter: str = "S21"
    data_format: str = "FORM2"

    def frequencies(self) -> np.ndarray:
        return np.linspace(self.start_hz, self.stop_hz, self.points)


class Prologix8753:
    """The analyzer at GPIB ``address`` behind ``gpib``."""

    def __init__(self, gpib: Prologix, address: int = 16, retries: int = 3, data_timeout_s: float = 5.0,
                 opc_read_tmo_ms: int = 3000):
        self.gpib, self.address, self.retries = gpib, int(address), int(retries)
        self.data_timeout_s = float(data_timeout_s)
        self.opc_read_tmo_ms = int(opc_read_tmo_ms)
        # sweep deadline: 1.5 x SWET + 4 OPC polls
        self.sweep_margin_s = 4 * (opc_read_tmo_ms / 1000.0 + gpib.read_margin_s)
        self.settings: VnaSettings | None = None
        self.sweep_time_s = 0.0
        self.retry_count = 0  # recoveries so far (reported in the scan file)

    # -- plumbing -----------------------------------------------------------------------------
    def send(self, command: str) -> None:
        """Send mnemonics (``;`` appended)."""
        self.gpib.select(self.address)
        self.gpib.write(command + ";")

    def _retrying(self, what: str, attempt_fn):
        last: InstrumentError | None = None
        for attempt in range(self.retries + 1):
            if attempt:
                self.retry_count += 1
            try:
                return attempt_fn()
            except (InstrumentTimeout, GarbledData) as e:
                last = e
                self.gpib.port.drain()
        raise type(last)(f"VNA: {what} failed after {self.retries + 1} attempts: {last}")

    def query(self, command: str) -> str:
        """One ASCII answer line (value or text) to ``command`` (e.g. ``POIN?``), retried on silence."""
        def attempt() -> str:
            self.gpib.port.discard_input()
            self.send(command)
            self.gpib.request_read()
            line = self.gpib.port.read_until(b"\n", time.monotonic() + self.gpib.read_window_s)
            text = line.decode("ascii", "replace").strip()
            if not text:
                raise GarbledData(f"empty answer to {command}")
            return text
        return self._retrying(command, attempt)

    def query_float(self, command: str) -> float:
        def attempt() -> float:
            text = self.query(command)
            try:
                return float(text)
            except ValueError:
                raise GarbledData(f"'{text[:30]}' is not a number (answer to {command})") from None
        return self._retrying(command, attempt)

    # -- identity and state -------------------------------------------------------------------
    def identify(self) -> dict[str, str]:
        """``IDN?`` -> maker, model, serial, firmware; ``OUTPOPTS`` -> installed options."""
        idn = self.query("IDN?")
        parts = [p.strip() for p in idn.split(",")]
        if len(parts) < 4:
            raise InstrumentError(f"VNA: unexpected identification '{idn[:60]}'")
        opts = self.query("OUTPOPTS")
        return {"idn": idn, "maker": parts[0], "model": parts[1], "serial": parts[2],
                "firmware": parts[3], "options": opts}

    def errors(self) -> list[str]:
        """Drain the error queue (``OUTPERRO`` until error number 0)."""
        out = []
        for _ in range(32):
            text = self.query("OUTPERRO")
            try:
                code = int(float(text.split(",")[0]))
            except ValueError:
                raise GarbledData(f"VNA: unreadable error queue entry '{text[:40]}'") from None
            if code == 0:
                break
            out.append(text)
        return out

    def wait_opc(self, command: str, timeout_s: float) -> None:
        """``OPC?;<command>`` and poll ``++read eoi`` until ``1`` arrives (or the deadline).

        The adapter's read timeout is raised to ``opc_read_tmo_ms`` (<= 3000) meanwhile, so that the
        ``1`` is passed on as soon as the sweep ends instead of after a host-side poll period.
        """
        normal = self.gpib.read_tmo_ms
        self.gpib.port.discard_input()
        self.send(f"OPC?;{command}")
        self.gpib.set_read_timeout(self.opc_read_tmo_ms)
        try:
            self._poll_opc(command, time.monotonic() + timeout_s)
        finally:
            self.gpib.set_read_timeout(normal)

    def _poll_opc(self, command: str, deadline: float) -> None:
        while True:
            self.gpib.request_read()
            try:
                line = self.gpib.port.read_until(b"\n", time.monotonic() + self.gpib.read_window_s)
            except InstrumentTimeout:
                if time.monotonic() > deadline:
                    raise InstrumentTimeout(f"VNA: {command} not complete in time (OPC? never answered)") from None
                continue
            if line.strip() == b"1":
                return
            if time.monotonic() > deadline:
                raise GarbledData(f"VNA: unexpected answer '{line[:30]!r}' while waiting for {command}")

    def preset(self) -> None:
        self.wait_opc("PRES", timeout_s=10.0)

    # -- configuration -------------------------------------------------------------------------
    def configure(self, s: VnaSettings) -> None:
        """Apply ``s``, read every setting back and check the error queue; mismatch -> InstrumentError."""
        self.send(f"CHAN1;LINFREQ;{s.parameter};POLA;HOLD;AVERO0;{s.data_format}")
        self.send(f"STAR {s.start_hz:.0f}HZ;STOP {s.stop_hz:.0f}HZ;POIN{s.points};"
                  f"IFBW{s.if_bandwidth_hz:.0f};POWE {s.power_dbm:g};SOUP1")
        errs = self.errors()
        if errs:
            raise InstrumentError(f"VNA refused the settings: {'; '.join(errs)}")
        checks = (("STAR?", s.start_hz, 1.0), ("STOP?", s.stop_hz, 1.0), ("POIN?", s.points, 0.5),
                  ("IFBW?", s.if_bandwidth_hz, 0.5), ("POWE?", s.power_dbm, 0.05))
        for cmd, want, tol in checks:
            got = self.query_float(cmd)
            if not math.isclose(got, want, abs_tol=tol):
                raise InstrumentError(f"VNA: {cmd} reads back {got:g}, expected {want:g}")
        if self.query(f"{s.parameter}?") != "1":
            raise InstrumentError(f"VNA: {s.parameter} is not the measured parameter after setting it")
        self.settings = s
        self.sweep_time_s = self.query_float("SWET?")

    # -- measurement -----------------------------------------------------------------------------
    def sweep(self) -> None:
        """One single sweep, returning when it is complete."""
        self.wait_opc("SING", timeout_s=1.5 * self.sweep_time_s + self.sweep_margin_s)

    def read_data(self) -> np.ndarray:
        """The last sweep's error-corrected data (``OUTPDATA``) as complex128 (points,)."""
        s = self._need_settings()
        if s.data_format == "FORM4":
            return self._retrying("OUTPDATA (FORM4)", lambda: self._read_form4(s.points))
        return self._retrying(f"OUTPDATA ({s.data_format})",
                              lambda: self._read_binary(s.points, BINARY_FORMATS[s.data_format]))

    def _need_settings(self) -> VnaSettings:
        if self.settings is None:
            raise InstrumentError("VNA: configure() before reading data")
        return self.settings

    def _data_deadline(self) -> float:
        return time.monotonic() + self.gpib.read_window_s + self.data_timeout_s

    def _read_form4(self, n: int) -> np.ndarray:
        self.gpib.port.discard_input()
        self.send("OUTPDATA")
        self.gpib.request_read()
        block = self.gpib.port.read_lines_until(n, b"\n", self._data_deadline())
        return parse_form4(block, n)

    def _read_binary(self, n: int, dtype: str) -> np.ndarray:
        self.gpib.port.discard_input()
        self.send("OUTPDATA")
        self.gpib.request_read()
        deadline = self._data_deadline()
        header = self.gpib.port.read_exact(4, deadline)
        nbytes = parse_binary_header(header, n * 2 * np.dtype(dtype).itemsize)
        return parse_binary(self.gpib.port.read_exact(nbytes, deadline), n, dtype)

    def upload_data(self, values: np.ndarray) -> None:
        """``INPUDATA``: send a complex (points,) array in the current binary format.

        The block goes through the adapter escaped (its bytes may include CR, LF, ESC and ``+``);
        uploading a known array and reading it back with ``OUTPDATA`` checks the whole link.
        """
        s = self._need_settings()
        if s.data_format not in BINARY_FORMATS:
            raise InstrumentError("VNA: INPUDATA upload needs FORM2 or FORM3")
        arr = np.empty((s.points, 2), BINARY_FORMATS[s.data_format])
        arr[:, 0], arr[:, 1] = values.real, values.imag
        payload = arr.tobytes()
        self.gpib.select(self.address)
        self.gpib.write(b"INPUDATA#A" + len(payload).to_bytes(2, "big") + payload + b";")


def parse_form4(block: bytes, n: int) -> np.ndarray:
    """``n`` lines of ``re,im`` -> complex128 (n,); GarbledData if anything is off."""
    fields = block.replace(b"\n", b",").split(b",")
    if fields and fields[-1].strip() == b"":
        fields.pop()
    if len(fields) != 2 * n:
        raise GarbledData(f"FORM4 block has {len(fields)} numbers, expected {2 * n}")
    try:
        vals = np.array(fields).astype(np.float64)
    except ValueError:
        raise GarbledData("FORM4 block has an unreadable number") from None
    if not np.all(np.isfinite(vals)):
        raise GarbledData("FORM4 block has a non-finite number")
    return vals[0::2] + 1j * vals[1::2]


def parse_binary_header(header: bytes, expected: int) -> int:
    """``#A`` + uint16 big-endian byte count; the count must be ``expected``."""
    if header[:2] != b"#A":
        raise GarbledData(f"binary block starts with {header[:2]!r}, expected b'#A'")
    nbytes = int.from_bytes(header[2:4], "big")
    if nbytes != expected:
        raise GarbledData(f"binary block announces {nbytes} bytes, expected {expected}")
    return nbytes


def parse_binary(payload: bytes, n: int, dtype: str) -> np.ndarray:
    vals = np.frombuffer(payload, dtype).astype(np.float64)
    if vals.size != 2 * n or not np.all(np.isfinite(vals)):
        raise GarbledData("binary block has a wrong length or non-finite values")
    return vals[0::2] + 1j * vals[1::2]
