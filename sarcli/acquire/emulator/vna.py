"""Emulated Prologix GPIB-USB adapter with an 8753ES at address 16 and an 11713A at address 28.

Adapter: host lines split at unescaped CR/LF, ESC escapes removed; ``++`` lines are adapter
commands; data lines go to the addressed instrument with LF appended (``++eos 2``). Instrument
output is held until ``++read`` (``++auto 0``) and released one message at a time; with nothing to
say the adapter stays silent for ``++read_tmo_ms``. A new command to the VNA discards unread output.

VNA: the subset of native mnemonics listed in the module docs of :mod:`..vna8753`; numbers are
emitted as ``f"{v: .15E}"`` right-justified in 24 characters. ``SING`` takes the modelled sweep time
(times ``time_scale``) and measures S21 at the rail position the emulated GRBL reports at that
moment, for the polarization the switch is set to.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np

from sarcli.acquire.emulator.faults import FaultPlan
from sarcli.acquire.emulator.ptylink import PtyDevice
from sarcli.acquire.prologix import unescape_split
from sarcli.acquire.vna8753 import (
    ALLOWED_IFBW_HZ,
    ALLOWED_POINTS,
    BINARY_FORMATS,
    MAX_FREQUENCY_OPT006_HZ,
    MIN_FREQUENCY_HZ,
    estimated_sweep_time,
)

PROLOGIX_VERSION = "Prologix GPIB-USB Controller version 6.107"
IDN = "HEWLETT PACKARD,8753ES,MY40001541,7.74"
OPTIONS = "1D5 002 006 010"
_UNITS = {"": 1.0, "HZ": 1.0, "KHZ": 1e3, "MHZ": 1e6, "GHZ": 1e9, "DB": 1.0, "S": 1.0, "MS": 1e-3,
          "US": 1e-6, "NS": 1e-9}
_NUMERIC = ("STAR", "STOP", "CENT", "SPAN", "POIN", "IFBW", "POWE", "SWET", "AVERFACT", "NUMG")
_FLAGS = {  # mnemonic -> (state key, value)
    "S11": ("param", "S11"), "S21": ("param", "S21"), "S12": ("param", "S12"), "S22": ("param", "S22"),
    "LINFREQ": ("sweep_type", "LINFREQ"), "LOGFREQ": ("sweep_type", "LOGFREQ"),
    "SOUP1": ("rf_on", 1), "SOUP0": ("rf_on", 0), "SOUPON": ("rf_on", 1), "SOUPOFF": ("rf_on", 0),
    "AVERO1": ("averaging", 1), "AVERO0": ("averaging", 0), "AVEROON": ("averaging", 1),
    "AVEROOFF": ("averaging", 0), "CHAN1": ("channel", 1), "CHAN2": ("channel", 2),
    "HOLD": ("trigger", "HOLD"), "CONT": ("trigger", "CONT"),
    "FORM2": ("form", "FORM2"), "FORM3": ("form", "FORM3"), "FORM4": ("form", "FORM4"),
    "FORM5": ("form", "FORM5"),
}
_IGNORED = {"LOGM", "PHAS", "DELA", "SMIC", "POLA", "LINM", "REAL", "IMAG", "SWR", "WAIT", "CLES",
            "SWEA", "OPC"}
_NUM_RE = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:E[-+]?\d+)?)\s*([A-Z]*)\s*$")

#: S21 source: (rail position m, frequencies Hz, polarization) -> complex (n_freq,)
Source = Callable[[float, np.ndarray, str], np.ndarray]


def fmt_number(v: float) -> str:
    """The 8753's 24-character numeric field."""
    return f"{v: .15E}".rjust(24)


def form4_block(values: np.ndarray) -> bytes:
    """``re,im`` LF per point, each number as :func:`fmt_number` (one %-format call for speed)."""
    flat = np.empty(2 * values.size, np.float64)
    flat[0::2], flat[1::2] = values.real, values.imag
    return (("%24.15E,%24.15E\n" * values.size) % tuple(flat.tolist())).encode("ascii")


def binary_block(values: np.ndarray, form: str) -> bytes:
    arr = np.empty((values.size, 2), BINARY_FORMATS.get(form, "<f4" if form == "FORM5" else ">f4"))
    arr[:, 0], arr[:, 1] = values.real, values.imag
    payload = arr.tobytes()
    return b"#A" + len(payload).to_bytes(2, "big") + payload


class EmulatedVna(PtyDevice):
    name = "VNA"

    def __init__(self, source: Source, position_m: Callable[[], float], polarization: Callable[[], str],
                 faults: FaultPlan, time_scale: float = 0.0, on_sweep: Callable[[int], None] | None = None,
                 on_switch: Callable[[str], None] | None = None):
        super().__init__()
        self.source, self.position_m, self.polarization = source, position_m, polarization
        self.faults, self.time_scale = faults, float(time_scale)
        self.on_sweep, self.on_switch = on_sweep, on_switch
        self.rest = b""
        self.lines: list[tuple[bytes, bool]] = []
        self.adapter = {"mode": 1, "addr": 16, "auto": 0, "eoi": 1, "eos": 0, "eot_enable": 0,
                        "eot_char": 0, "read_tmo_ms": 500, "savecfg": 1}
        self.read_deadline: float | None = None
        self.outq: list[list] = []  # [ready_time, bytes]
        self.log: list[bytes] = []  # b"++cmd" adapter lines and unescaped instrument data, in order
        self.n_sweeps = 0
        self.opc_pending = False
        self.switch_drivers: dict[str, bool] = {}
        self.preset()

    # -- instrument state ------------------------------------------------------------------------
    def preset(self) -> None:
        self.st = {"start": MIN_FREQUENCY_HZ, "stop": 3e9, "points": 201, "ifbw": 3700.0, "power": 0.0,
                   "param": "S11", "sweep_type": "LINFREQ", "rf_on": 1, "averaging": 0, "channel": 1,
                   "trigger": "CONT", "form": "FORM4", "swet": None}
        self.errors: list[str] = []
        self.esr = 0
        self.data = np.zeros(201, np.complex128)
        self.busy_until = self.now

    def _error(self, text: str, number: int) -> None:
        self.errors.append(f'{number},"{text}"')
        self.esr |= 32  # command error bit

    def sweep_time(self) -> float:
        if self.st["swet"] is not None:
            return self.st["swet"]
        return estimated_sweep_time(self.st["points"], self.st["ifbw"])

    # -- host side ---------------------------------------------------------------------------------
    def feed(self, data: bytes) -> None:
        lines, self.rest = unescape_split(self.rest + data)
        self.lines.extend(lines)
        self._process()

    def _process(self) -> None:
        while self.lines and self.read_deadline is None:
            line, is_adapter = self.lines.pop(0)
            if is_adapter:
                self._adapter(line[2:].decode("ascii", "replace").strip())
            else:
                self._instrument(line + b"\n")

    def _adapter(self, cmd: str) -> None:
        self.log.append(b"++" + cmd.encode())
        name, _, arg = cmd.partition(" ")
        arg = arg.strip()
        if name == "ver":
            self.send(PROLOGIX_VERSION.encode() + b"\r\n")
        elif name == "read":
            self.read_deadline = self.now + self.adapter["read_tmo_ms"] / 1000.0
            self.tick()
        elif name == "clr":
            self.outq.clear()
        elif name in ("ifc", "loc", "llo", "trg", "rst"):
            pass
        elif name == "spoll":
            self.send(f"{(8 if self.errors else 0) | (32 if self.esr else 0)}\r\n".encode())
        elif name in self.adapter:
            if arg:
                self.adapter[name] = int(arg.split()[0])
            else:
                self.send(f"{self.adapter[name]}\r\n".encode())

    def tick(self) -> None:
        if self.read_deadline is None:
            return
        if self.outq and self.outq[0][0] <= self.now:
            self.send(self.outq.pop(0)[1])
            self.read_deadline = None
        elif self.now >= self.read_deadline:
            self.read_deadline = None  # silence: nothing to say within read_tmo_ms
        if self.read_deadline is None:
            self._process()

    def wakeup_s(self) -> float:
        if self.read_deadline is None:
            return 0.1
        t = self.read_deadline
        if self.outq:
            t = min(t, self.outq[0][0])
        return max(0.0, t - self.now)

    def _queue(self, data: bytes, ready: float | None = None) -> None:
        self.outq.append([self.now if ready is None else ready, data])

    # -- instrument side -----------------------------------------------------------------------------
    def _instrument(self, data: bytes) -> None:
        self.log.append(data)
        addr = self.adapter["addr"]
        if addr == 28:
            self._switch_11713a(data.decode("ascii", "replace"))
            return
        if addr != 16:
            return  # nobody listens there
        self.outq.clear()  # a new command discards unread output
        i, n = 0, len(data)
        while i < n:
            if data[i] in b"; \r\n\t":
                i += 1
                continue
            j = i
            while j < n and data[j] not in b";\n":
                j += 1
            token = data[i:j].decode("ascii", "replace").strip().upper()
            if token.startswith("INPUDATA#A") and j - i >= 12:
                count = int.from_bytes(data[i + 10:i + 12], "big")
                self._inpudata(data[i + 12:i + 12 + count])
                j = i + 12 + count
            else:
                self._execute(token)
            i = j + 1

    def _execute(self, tok: str) -> None:
        st = self.st
        if tok in ("IDN?", "*IDN?", "OUTPIDEN"):
            self._queue(IDN.encode() + b"\n")
        elif tok == "OUTPOPTS":
            self._queue(OPTIONS.encode() + b"\n")
        elif tok == "OUTPSERN":
            self._queue(IDN.split(",")[2].encode() + b"\n")
        elif tok in ("PRES", "*RST"):
            self.preset()
        elif tok == "OPC?":
            self.opc_pending = True
            return
        elif tok == "SING":
            self._sing()
        elif tok in ("OUTPDATA", "OUTPFORM", "OUTPRAW1"):
            self._output_data()
        elif tok == "OUTPERRO":
            msg = self.errors.pop(0) if self.errors else '0,"NO ERRORS"'
            self._queue(msg.encode() + b"\n")
        elif tok == "ESR?":
            self._queue(f"{self.esr}\n".encode())
            self.esr = 0
        elif tok in _FLAGS:
            key, value = _FLAGS[tok]
            st[key] = value
        elif tok.endswith("?") and tok[:-1] in _FLAGS:
            key, value = _FLAGS[tok[:-1]]
            self._queue(b"1\n" if st[key] == value else b"0\n")
        elif tok in _IGNORED:
            pass
        else:
            self._numeric(tok)
        if self.opc_pending and tok in ("PRES", "*RST"):
            self.opc_pending = False
            self._queue(b"1\n")

    def _numeric(self, tok: str) -> None:
        st = self.st
        base = next((m for m in _NUMERIC if tok.startswith(m)), None)
        if base is None:
            self._error(f"SYNTAX ERROR: {tok[:20]}", 1)
            return
        rest = tok[len(base):]
        if rest == "?":
            value = {"STAR": st["start"], "STOP": st["stop"], "CENT": (st["start"] + st["stop"]) / 2,
                     "SPAN": st["stop"] - st["start"], "POIN": st["points"], "IFBW": st["ifbw"],
                     "POWE": st["power"], "SWET": self.sweep_time(), "AVERFACT": 1, "NUMG": 1}[base]
            self._queue(fmt_number(float(value)).encode() + b"\n")
            return
        m = _NUM_RE.match(rest)
        if not m or m.group(2) not in _UNITS:
            self._error(f"SYNTAX ERROR: {tok[:20]}", 1)
            return
        v = float(m.group(1)) * _UNITS[m.group(2)]
        fmin, fmax = MIN_FREQUENCY_HZ, MAX_FREQUENCY_OPT006_HZ
        if base in ("STAR", "STOP", "CENT", "SPAN"):
            start, stop = st["start"], st["stop"]
            if base == "STAR":
                start = v
            elif base == "STOP":
                stop = v
            elif base == "CENT":
                half = (stop - start) / 2
                start, stop = v - half, v + half
            else:
                c = (start + stop) / 2
                start, stop = c - v / 2, c + v / 2
            st["start"], st["stop"] = min(max(start, fmin), fmax), min(max(stop, fmin), fmax)  # clamps
            if st["stop"] < st["start"]:
                st["stop"] = st["start"]
        elif base == "POIN":
            if int(v) in ALLOWED_POINTS:
                st["points"] = int(v)
            else:
                self._error("INVALID NUMBER OF POINTS", 2)
        elif base == "IFBW":
            if v in ALLOWED_IFBW_HZ:
                st["ifbw"] = v
            else:
                self._error("INVALID IF BANDWIDTH", 3)
        elif base == "POWE":
            st["power"] = min(max(v, -85.0), 10.0)
        elif base == "SWET":
            st["swet"] = v
        elif base == "NUMG":
            self._sing()

    def _sing(self) -> None:
        self.n_sweeps += 1
        if self.on_sweep is not None:
            self.on_sweep(self.n_sweeps)
        due = self.faults.event("sweep")
        if "vna-unplug" in due:
            self.unplug()
            return
        duration = due.get("slow-sweep", self.sweep_time() * self.time_scale)
        st = self.st
        freq = np.linspace(st["start"], st["stop"], st["points"])
        if st["rf_on"] and st["param"] == "S21":
            self.data = np.asarray(self.source(self.position_m(), freq, self.polarization()), np.complex128)
        else:
            self.data = np.zeros(st["points"], np.complex128)
        self.st["trigger"] = "HOLD"
        done = self.now + duration
        if self.opc_pending:
            self.opc_pending = False
            self._queue(b"1\n", ready=done)

    def _output_data(self) -> None:
        form = self.st["form"]
        block = form4_block(self.data) if form == "FORM4" else binary_block(self.data, form)
        due = self.faults.event("data")
        if "vna-timeout" in due:
            return
        if "garble" in due:
            b = bytearray(block)
            k = len(b) // 2 if form == "FORM4" else 0
            while form == "FORM4" and not chr(b[k]).isdigit():
                k += 1
            b[k:k + 1] = b"?" if form == "FORM4" else b"%"
            block = bytes(b)
        if "truncate" in due:
            block = block[: int(0.6 * len(block))]
        self._queue(block)

    def _inpudata(self, payload: bytes) -> None:
        form = self.st["form"]
        if form not in BINARY_FORMATS:
            self._error("INPUDATA NEEDS A BINARY FORMAT", 4)
            return
        vals = np.frombuffer(payload, BINARY_FORMATS[form]).astype(np.float64)
        if vals.size != 2 * self.st["points"]:
            self._error("INPUDATA LENGTH", 5)
            return
        self.data = vals[0::2] + 1j * vals[1::2]

    # -- 11713A (listen only) ----------------------------------------------------------------------
    def _switch_11713a(self, text: str) -> None:
        for on_off, digits in re.findall(r"([AB])([0-9]+)", text.upper()):
            for d in digits:
                self.switch_drivers[d] = on_off == "A"
        if self.on_switch is not None:
            self.on_switch(("H" if self.switch_drivers.get("9") else "V")
                           + ("H" if self.switch_drivers.get("0") else "V"))
