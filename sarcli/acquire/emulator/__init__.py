"""Emulated GB-SAR instruments on pseudo-terminals: a Prologix + 8753ES (+ 11713A) and a GRBL rail.

:class:`Emulator` opens one ``os.openpty`` pair per instrument and serves both from one thread;
``vna_port`` / ``rail_port`` are the slave paths a client opens like real serial ports. The VNA's
S21 comes from a source function evaluated at the position the emulated rail is at when the sweep
starts, for the polarization the emulated switch is set to (GRBL flood/spindle pins, an 11713A's
S9/S0 drivers, or fixed). ``machine_zero_m`` is the rail-frame position of GRBL's X0.
``time_scale`` multiplies sweep, move and dwell durations (0 = instant, 1 = real time); the
Prologix read timeout is always real time, as on the real adapter.

**Simulated clock** (:class:`SceneClock`, ``scan_interval_s``): the scene changes with time (targets
moving by their laws, the atmosphere, decorrelating vegetation: :func:`sarcli.gbsar.scene.scene_at`)
and the emulator keeps its own scan clock: scan ``j`` (from 0) is the scene at ``j * scan_interval_s``
after its epoch, whatever the wall clock says. A new scan begins with the first sweep, and then with
every sweep at a rail position more than 0.1 mm *behind* the previous sweep's (the controller always
scans forward: a resumed scan continues forward, so it stays the same scan). What was simulated for
each scan is appended to a JSON-lines truth file when its first sweep is made.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from sarcli.acquire.emulator.faults import FaultPlan
from sarcli.acquire.emulator.grbl import EmulatedGrbl
from sarcli.acquire.emulator.ptylink import Service
from sarcli.acquire.emulator.vna import EmulatedVna, Source
from sarcli.acquire.polswitch import SWITCH_KINDS
from sarcli.errors import SarcliError


def thru_source(position_m: float, frequency_hz: np.ndarray, pol: str) -> np.ndarray:
    """No scene: a calibrated thru, S21 = 1 at every frequency, position and polarization."""
    return np.ones(frequency_hz.shape, np.complex128)


def scene_source(scene_path: str, height_m: float = 0.0, scan_interval_s: float | None = None,
                 truth_path: str | None = None) -> Source:
    """S21 from the GB-SAR simulator (:func:`sarcli.gbsar.simulate.simulate_stop`) for a scene file; with
    ``scan_interval_s`` the scene changes from scan to scan (:class:`SceneClock`)."""
    from sarcli.gbsar.scene import load_scene
    from sarcli.gbsar.simulate import simulate_stop

    scene = load_scene(scene_path)
    if scan_interval_s is not None:
        return SceneClock(scene, height_m, scan_interval_s, truth_path)

    def source(position_m: float, frequency_hz: np.ndarray, pol: str) -> np.ndarray:
        return np.asarray(simulate_stop(scene, position_m, height_m, frequency_hz, (pol,)))[0]
    return source


class SceneClock:
    """A :data:`Source` whose scene advances by ``interval_s`` per scan (module docstring); ``scan`` is the
    current scan index (-1 before the first sweep). ``truth_path``: JSON lines, one per scan
    (:func:`sarcli.gbsar.scene.scene_truth` plus ``scan`` from 1 and ``time_utc``)."""

    def __init__(self, scene, height_m: float, interval_s: float, truth_path: str | None = None):
        if not interval_s > 0:
            raise SarcliError("the emulator's scan interval must be > 0")
        self.base, self.height_m, self.interval_s = scene, float(height_m), float(interval_s)
        self.truth_path = truth_path
        self.scan = -1
        self.scene = scene
        self._last_position: float | None = None

    def warm_up(self) -> None:
        """Compile the simulator before serving (no scan is counted)."""
        from sarcli.gbsar.simulate import simulate_stop

        simulate_stop(self.base, float(self.base.positions_m[0]), self.height_m, np.array([5.0e9, 5.1e9]), ("VV",))

    def _next_scan(self) -> None:
        import datetime as dt
        import json

        from sarcli.gbsar.scene import scene_at, scene_truth

        self.scan += 1
        t = self.scan * self.interval_s
        self.scene = scene_at(self.base, t, self.scan)
        if self.truth_path is not None:
            epoch = dt.datetime.fromisoformat(self.base.epoch_utc.replace("Z", "+00:00"))
            when = (epoch + dt.timedelta(seconds=t)).strftime("%Y-%m-%dT%H:%M:%SZ")
            with open(self.truth_path, "a", encoding="utf-8") as fh:
                fh.write(json.dumps({"scan": self.scan + 1, "time_utc": when, **scene_truth(self.scene)}) + "\n")

    def __call__(self, position_m: float, frequency_hz: np.ndarray, pol: str) -> np.ndarray:
        from sarcli.gbsar.simulate import simulate_stop

        if self._last_position is None or position_m < self._last_position - 1e-4:
            self._next_scan()
        self._last_position = position_m
        return np.asarray(simulate_stop(self.scene, position_m, self.height_m, frequency_hz, (pol,)))[0]


class Emulator:
    """Both instruments; use as a context manager or call :meth:`start` / :meth:`stop`."""

    def __init__(self, source: Source | None = None, faults: str | FaultPlan | None = None,
                 time_scale: float = 0.0, switch: str = "none", polarization: str = "VV",
                 grbl_settings: dict[int, float] | None = None, start_locked: bool = False,
                 on_sweep: Callable[[int], None] | None = None, machine_zero_m: float = 0.0):
        if switch not in SWITCH_KINDS:
            raise SarcliError(f"emulated switch must be one of {', '.join(SWITCH_KINDS)}")
        if time_scale < 0:
            raise SarcliError("time scale must be >= 0")
        self.faults = faults if isinstance(faults, FaultPlan) else FaultPlan.parse(faults)
        self.switch, self.fixed_pol = switch, polarization
        self._pol_11713a = "VV"
        self.grbl = EmulatedGrbl(self.faults, time_scale, grbl_settings, start_locked)
        self.machine_zero_m = float(machine_zero_m)
        self.vna = EmulatedVna(source or thru_source, self.rail_position_m, self.polarization,
                               self.faults, time_scale, on_sweep=on_sweep, on_switch=self._set_11713a)
        self.service = Service([self.vna, self.grbl])

    @property
    def vna_port(self) -> str:
        return self.vna.path

    @property
    def rail_port(self) -> str:
        return self.grbl.path

    def rail_position_m(self) -> float:
        """Rail-frame position of the antenna: GRBL MPos X (mm) / 1000 + the frame offset of X0."""
        return self.grbl.position() / 1000.0 + self.machine_zero_m

    def _set_11713a(self, pol: str) -> None:
        self._pol_11713a = pol

    def polarization(self) -> str:
        """TX letter then RX letter, from the wired switch."""
        if self.switch == "grbl":
            return ("H" if self.grbl.flood else "V") + ("H" if self.grbl.spindle else "V")
        if self.switch == "11713a":
            return self._pol_11713a
        return self.fixed_pol

    def start(self) -> Emulator:
        # one evaluation first, so that a JIT-compiled source does not delay the first sweep's OPC
        warm_up = getattr(self.vna.source, "warm_up", None)
        if warm_up is not None:
            warm_up()
        else:
            self.vna.source(self.rail_position_m(), np.array([5.0e9, 5.1e9]), self.polarization())
        self.service.start()
        return self

    def stop(self) -> None:
        self.service.stop()
        if self.service.error is not None:
            raise self.service.error

    def __enter__(self) -> Emulator:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()
