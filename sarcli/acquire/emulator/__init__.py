"""Emulated GB-SAR instruments on pseudo-terminals: a Prologix + 8753ES (+ 11713A) and a GRBL rail.

:class:`Emulator` opens one ``os.openpty`` pair per instrument and serves both from one thread;
``vna_port`` / ``rail_port`` are the slave paths a client opens like real serial ports. The VNA's
S21 comes from a source function evaluated at the position the emulated rail is at when the sweep
starts, for the polarization the emulated switch is set to (GRBL flood/spindle pins, an 11713A's
S9/S0 drivers, or fixed). ``machine_zero_m`` is the rail-frame position of GRBL's X0.
``time_scale`` multiplies sweep, move and dwell durations (0 = instant, 1 = real time); the
Prologix read timeout is always real time, as on the real adapter.
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


def scene_source(scene_path: str, height_m: float = 0.0) -> Source:
    """S21 from the GB-SAR simulator (:func:`sarcli.gbsar.simulate.simulate_stop`) for a scene file."""
    from sarcli.gbsar.scene import load_scene
    from sarcli.gbsar.simulate import simulate_stop

    scene = load_scene(scene_path)

    def source(position_m: float, frequency_hz: np.ndarray, pol: str) -> np.ndarray:
        return np.asarray(simulate_stop(scene, position_m, height_m, frequency_hz, (pol,)))[0]
    return source


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
