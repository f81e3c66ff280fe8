"""Emulated GRBL 1.1h with one axis (X) on a pseudo-terminal.

Protocol modelled (gnea/grbl 1.1h): banner on soft reset; ``ok``/``error:N`` per line; empty line
-> ``ok``; real-time ``?`` ``!`` ``~`` 0x18 picked out of the stream anywhere; moves queue
(``ok`` at once) and run a trapezoid from ``$110``/``$120`` (times ``time_scale``; 0 = instant);
``G4`` and M-codes wait for the planner to empty; ``$X``, ``$H`` (needs ``$22=1``; this emulator
models a ``HOMING_FORCE_SET_ORIGIN`` build: home is X0), ``$$``, ``$I``, ``$G``, ``$n=v``;
soft limits (``$20=1``): a target beyond ``[0, $130]`` raises ALARM:2; alarms 1/2 lock everything
but 0x18 (``[MSG:Reset to continue]``); 0x18 in motion -> ALARM:3. Outputs: flood ``M8/M9`` and
spindle ``M3/M4/M5`` (drive the emulated polarization switch).
"""

from __future__ import annotations

import re

from sarcli.acquire.emulator.faults import FaultPlan
from sarcli.acquire.emulator.ptylink import PtyDevice
from sarcli.acquire.motion import move_time, position_at

BANNER = b"\r\nGrbl 1.1h ['$' for help]\r\n"
DEFAULT_SETTINGS = {0: 10, 1: 25, 2: 0, 3: 0, 4: 0, 5: 0, 6: 0, 10: 1, 11: 0.010, 12: 0.002, 13: 0,
                    20: 0, 21: 0, 22: 0, 23: 0, 24: 25.0, 25: 500.0, 26: 250, 27: 1.0, 30: 1000,
                    31: 0, 32: 0, 100: 250.0, 101: 250.0, 102: 250.0, 110: 500.0, 111: 500.0,
                    112: 500.0, 120: 10.0, 121: 10.0, 122: 10.0, 130: 200.0, 131: 200.0, 132: 200.0}
_WORD = re.compile(r"([A-Z])([-+]?(?:\d+\.?\d*|\.\d+))")
_REALTIME = frozenset(b"?!~\x18\x85")


class EmulatedGrbl(PtyDevice):
    name = "rail"

    def __init__(self, faults: FaultPlan, time_scale: float = 0.0, settings: dict[int, float] | None = None,
                 start_locked: bool = False):
        super().__init__()
        self.faults, self.time_scale = faults, float(time_scale)
        self.settings = {**DEFAULT_SETTINGS, **(settings or {})}
        self.x = 0.0
        self.move: tuple[float, float, float, float, float] | None = None  # x0, x1, t0, v, a
        self.fault_stop: tuple[str, float] | None = None  # ("alarm"/"stall", arg) at move half way
        self.state = "Alarm" if start_locked else "Idle"
        self.critical = False  # after ALARM 1/2: only 0x18 is served
        self.buf = bytearray()
        self.pending: list[str] = []
        self.dwell_until: float | None = None
        self.feed_rate = 0.0
        self.flood = False
        self.spindle = False
        self.n_status = 0
        self.log: list[str] = []  # lines and real-time bytes (as 1-char strings) in arrival order
        self.send(BANNER + (b"[MSG:'$H'|'$X' to unlock]\r\n" if start_locked else b""))

    # -- time ----------------------------------------------------------------------------------------
    def position(self) -> float:
        if self.move is None:
            return self.x
        x0, x1, t0, v, a = self.move
        t = (self.now - t0) / self.time_scale if self.time_scale > 0 else float("inf")
        return position_at(t, x0, x1, v, a)

    def _move_end(self) -> float:
        x0, x1, t0, v, a = self.move
        return t0 + move_time(x1 - x0, v, a) * self.time_scale

    def tick(self) -> None:
        if self.move is not None and self.now >= self._move_end():
            self.x = self.move[1]
            self.move = None
            self.state = "Idle" if self.state == "Run" else self.state
            if self.fault_stop is not None:
                self._fault_stop()
        if self.dwell_until is not None and self.now >= self.dwell_until:
            self.dwell_until = None
            self.send(b"ok\r\n")
        while self.pending and not self.critical and self.dwell_until is None:
            if self.move is not None and self.pending[0].strip():
                break  # one move at a time: the next non-empty line waits for it
            self._line(self.pending.pop(0))

    def wakeup_s(self) -> float:
        times = []
        if self.move is not None:
            times.append(self._move_end())
        if self.dwell_until is not None:
            times.append(self.dwell_until)
        return max(0.0, min(times) - self.now) if times else 0.1

    def _fault_stop(self) -> None:
        kind, arg = self.fault_stop
        self.fault_stop = None
        if kind == "alarm":
            self._alarm(int(arg))
        # "stall": the move simply ended half way and reports Idle

    def _alarm(self, code: int) -> None:
        self.state = "Alarm"
        self.move = None
        self.pending.clear()
        self.dwell_until = None
        self.send(f"ALARM:{code}\r\n".encode())
        if code in (1, 2):
            self.critical = True
            self.send(b"[MSG:Reset to continue]\r\n")

    # -- input -----------------------------------------------------------------------------------------
    def feed(self, data: bytes) -> None:
        for b in data:
            if b in _REALTIME:
                self._realtime(b)
            elif b in (10, 13):
                line = self.buf.decode("ascii", "replace")
                self.buf.clear()
                self.log.append(line)
                if not self.critical:
                    self.pending.append(line)
            else:
                self.buf.append(b)
        self.tick()

    def _realtime(self, b: int) -> None:
        self.log.append(chr(b))
        if b == ord("?"):
            self._status()
        elif b == 0x18:
            if self.move is not None:
                self.x = self.position()
                self._alarm(3)
            self.move = None
            self.critical = False
            self.pending.clear()
            self.buf.clear()
            self.dwell_until = None
            self.flood = self.spindle = False
            if self.state != "Alarm":
                self.state = "Idle"
            self.send(BANNER + (b"[MSG:'$H'|'$X' to unlock]\r\n" if self.state == "Alarm" else b""))
        elif b == ord("!") and self.move is not None:
            self.x = self.position()  # stops at once (deceleration not modelled)
            self.move = None
            self.state = "Hold:0"
        elif b == ord("~") and self.state.startswith("Hold"):
            self.state = "Idle"

    def _status(self) -> None:
        self.n_status += 1
        fields = f"<{self.state}|MPos:{self.position():.3f},0.000,0.000|FS:{self.feed_rate if self.move else 0:.0f},0"
        if self.n_status % 10 == 1:
            fields += "|WCO:0.000,0.000,0.000"
        elif self.n_status % 10 == 5:
            fields += "|Ov:100,100,100"
        text = (fields + ">\r\n").encode()
        if "status-garble" in self.faults.event("status"):
            text = text[: len(text) // 2] + b"\r\n"
        self.send(text)

    # -- lines -------------------------------------------------------------------------------------------
    def _ok(self) -> None:
        self.send(b"ok\r\n")

    def _err(self, code: int) -> None:
        self.send(f"error:{code}\r\n".encode())

    def _line(self, raw: str) -> None:
        line = raw.strip().upper().replace(" ", "")
        if len(raw) > 80:
            return self._err(11)
        if not line:
            return self._ok()
        if line.startswith("$"):
            return self._dollar(line)
        if self.state == "Alarm":
            return self._err(9)
        words = _WORD.findall(line)
        if "".join(f"{k}{v}" for k, v in words) != line or not words:
            return self._err(1 if not line[0].isalpha() else 2)
        g = [float(v) for k, v in words if k == "G"]
        m = [float(v) for k, v in words if k == "M"]
        vals = {k: float(v) for k, v in words if k not in "GM"}
        if "F" in vals:
            self.feed_rate = vals["F"]
        for code in m:
            if code == 8:
                self.flood = True
            elif code == 9:
                self.flood = False
            elif code in (3, 4):
                self.spindle = True
            elif code == 5:
                self.spindle = False
            else:
                return self._err(20)
        if any(code not in (0, 1, 4, 17, 21, 90, 94) for code in g):
            return self._err(20)  # G91 (relative) and the rest are not modelled
        if 4 in g:
            self.dwell_until = self.now + vals.get("P", 0.0) * self.time_scale
            return self.tick()
        if "X" in vals:
            return self._start_move(vals["X"], rapid=0 in g and 1 not in g)
        return self._ok()

    def _start_move(self, target: float, rapid: bool) -> None:
        due = self.faults.event("move")
        if "rail-unplug" in due:
            self.unplug()
            return
        if "grbl-error" in due:
            return self._err(int(due["grbl-error"]))
        s = self.settings
        if s[20] and not 0.0 <= target <= s[130]:
            return self._alarm(2)
        feed = s[110] if rapid else self.feed_rate
        if feed <= 0:
            return self._err(22)
        x0 = self.position()
        if "alarm" in due or "stall" in due:
            kind = "alarm" if "alarm" in due else "stall"
            self.fault_stop = (kind, due.get(kind, 0.0))
            target = x0 + 0.5 * (target - x0)
        self.move = (x0, target, self.now, min(feed, s[110]) / 60.0, s[120])
        self.state = "Run"
        if "lost-ok" not in due:
            self._ok()
        self.tick()

    def _dollar(self, line: str) -> None:
        s = self.settings
        if line == "$$":
            text = "".join(f"${k}={v:g}\r\n" if k not in (11, 12) else f"${k}={v:.3f}\r\n"
                           for k, v in sorted(s.items()))
            self.send(text.encode())
            return self._ok()
        if line == "$I":
            self.send(b"[VER:1.1h.20190830:]\r\n[OPT:V,15,128]\r\n")
            return self._ok()
        if line == "$G":
            self.send(f"[GC:G0 G54 G17 G21 G90 G94 M{3 if self.spindle else 5} M{8 if self.flood else 9} "
                      f"T0 F{self.feed_rate:g} S0]\r\n".encode())
            return self._ok()
        if line == "$X":
            if self.state == "Alarm":
                self.send(b"[MSG:Caution: Unlocked]\r\n")
                self.state = "Idle"
            return self._ok()
        if line == "$H":
            if not s[22]:
                return self._err(5)
            x0 = self.position()
            self.move = (x0, 0.0, self.now, s[25] / 60.0, s[120])
            self.state = "Run"
            self.pending.insert(0, "G4P0")  # answer after the cycle
            return None
        m = re.match(r"^\$(\d+)=([-+0-9.]+)$", line)
        if m:
            if self.move is not None:
                return self._err(8)
            s[int(m.group(1))] = float(m.group(2))
            return self._ok()
        return self._err(3)
