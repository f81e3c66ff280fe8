"""``gbsar_emulate``: the acquisition instruments emulated on pseudo-terminals until stopped: a
Prologix GPIB-USB adapter with an 8753ES (and an 11713A at GPIB 28) and a GRBL 1.1h rail
(:mod:`sarcli.acquire.emulator`). The VNA's S21 is the GB-SAR simulator's for the scene, at the rail
position the emulated GRBL is at (a calibrated thru, S21 = 1, without a scene). Needs no pyserial.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from sarcli.acquire.config import parse_duration
from sarcli.acquire.emulator import Emulator, scene_source
from sarcli.errors import ConfigError
from sarcli.gbsar.scene import load_scene
from sarcli.workflows.base import Progress, Report, using


@dataclass(frozen=True)
class Config:
    """scene: GB-SAR scene TOML the VNA measures; faults ``NAME@N[:ARG],...``; time_scale: sweep / move
    duration factor (0 = instant); switch: none | grbl | 11713a; pol: the fixed polarization without a
    switch; machine_zero_m: rail-frame position of GRBL X0 (default: the scene's first stop, else 0);
    height_m: antenna height (default: the scene's); max_travel_mm: GRBL $130; soft_limits: $20=1;
    scan_interval: the scene advances by this much per scan ("10m"; default: a static scene, see
    :class:`sarcli.acquire.emulator.SceneClock`); truth: JSON-lines file of what each scan simulated."""

    scene: Path | None = None
    faults: str = ""
    time_scale: float = 1.0
    switch: Literal["none", "grbl", "11713a"] = "none"
    pol: str = "VV"
    machine_zero_m: float | None = None
    height_m: float | None = None
    max_travel_mm: float = 4000.0
    soft_limits: bool = False
    scan_interval: str | None = None
    truth: Path | None = None

    def __post_init__(self) -> None:
        if self.pol.upper() not in ("VV", "VH", "HV", "HH"):
            raise ConfigError(f"--pol {self.pol}: use VV, VH, HV or HH")
        if (self.scan_interval is not None or self.truth is not None) and self.scene is None:
            raise ConfigError("--scan-interval and --truth need --scene (a scene that changes with time)")
        if self.truth is not None and self.scan_interval is None:
            raise ConfigError("--truth needs --scan-interval (the truth of a scene changing from scan to scan)")
        if self.scan_interval is not None and not parse_duration(self.scan_interval) > 0:
            raise ConfigError(f"--scan-interval must be > 0, got {self.scan_interval}")


@dataclass
class GbsarEmulateReport(Report):
    vna_port: str
    rail_port: str
    machine_zero_m: float
    faults_fired: list[str] = field(default_factory=list)

    def lines(self) -> list[str]:
        return [f"emulator stopped; faults fired: {', '.join(self.faults_fired) or 'none'}"]


def run(config: Config, provenance=None, progress: Progress | None = None,
        on_ready: Callable[[GbsarEmulateReport], None] | None = None,
        stop: threading.Event | None = None) -> GbsarEmulateReport:
    """Serve the emulated instruments until ``stop`` is set (default: until SIGINT or SIGTERM).
    ``on_ready`` gets the port paths as soon as they can be opened."""
    c = config
    with using(provenance):
        source, zero, h = None, c.machine_zero_m or 0.0, c.height_m or 0.0
        if c.scene is not None:
            sc = load_scene(c.scene)
            zero = float(sc.positions_m[0]) if c.machine_zero_m is None else c.machine_zero_m
            h = float(sc.rail_heights()[0]) if c.height_m is None else c.height_m
            interval = None if c.scan_interval is None else parse_duration(c.scan_interval)
            source = scene_source(str(c.scene), h, interval, None if c.truth is None else str(c.truth))
        settings = {130: c.max_travel_mm, 20: 1 if c.soft_limits else 0}
        done = stop or threading.Event()
        old = {}
        if stop is None and threading.current_thread() is threading.main_thread():
            old = {s: signal.signal(s, lambda *_: done.set()) for s in (signal.SIGINT, signal.SIGTERM)}
        try:
            with Emulator(source, c.faults, c.time_scale, c.switch, c.pol.upper(), settings,
                          machine_zero_m=zero) as emu:
                report = GbsarEmulateReport(vna_port=emu.vna_port, rail_port=emu.rail_port, machine_zero_m=zero)
                if on_ready is not None:
                    on_ready(report)
                while not done.wait(0.2):
                    pass
                report.faults_fired = list(emu.faults.fired)
        finally:
            for s, handler in old.items():
                signal.signal(s, handler)
        return report
