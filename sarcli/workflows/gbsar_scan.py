"""``gbsar_scan``: acquire one GB-SAR scan (VNA 8753ES via Prologix + GRBL rail) into a scan product,
or check the plan and estimate its duration (``dry_run``, no instrument touched).

Settings come from the acquisition TOML (``config``) and the per-option overrides (these win);
everything is checked before a port is opened (:mod:`sarcli.acquire.config`). Every stop is written
and flushed before the rail moves on; a fault or Ctrl-C ends the scan with the completed stops kept
(:meth:`GbsarScanReport.raise_for_status` then raises the one-line error with the command that
continues the scan). The option fields are named like the ``sarcli gbsar scan`` flags
(``rail_start`` is ``--rail-start``): that is how the resume command is written.
"""

from __future__ import annotations

import shlex
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from sarcli.acquire.config import ScanConfig, load_config, parse_frequency
from sarcli.acquire.port import require_pyserial
from sarcli.acquire.session import StopGuard, acquire, failure, plan_summary
from sarcli.errors import ConfigError
from sarcli.workflows.base import Progress, Report, no_progress, using
from sarcli.workflows.gbsar_common import guard


@dataclass(frozen=True)
class Config:
    """ports (VNA, rail); ``config``: acquisition TOML; exactly one of ``output`` (a new scan) and
    ``resume`` (continue an interrupted one) unless ``dry_run``; the rest override the TOML
    (frequencies as text with units, e.g. "5.2GHz"; ``pol`` a comma list such as "VV,HH")."""

    port: str | None = None
    rail_port: str | None = None
    config: Path | None = None
    output: Path | None = None
    resume: Path | None = None
    dry_run: bool = False
    start: str | None = None
    stop: str | None = None
    points: int | None = None
    ifbw: float | None = None
    power: float | None = None
    data_format: str | None = None
    pol: str | None = None
    switch: str | None = None
    rail_start: float | None = None
    step: float | None = None
    count: int | None = None
    settle: float | None = None
    lat: float | None = None
    lon: float | None = None
    site_height: float | None = None
    heading: float | None = None

    def scan_config(self) -> ScanConfig:
        """The acquisition TOML with the overrides applied, checked."""
        return load_config(self.config, {
            "vna": {"start_hz": None if self.start is None else parse_frequency(self.start),
                    "stop_hz": None if self.stop is None else parse_frequency(self.stop), "points": self.points,
                    "if_bandwidth_hz": self.ifbw, "power_dbm": self.power, "data_format": self.data_format},
            "polarization": {"polarizations": None if self.pol is None else
                             [p.strip().upper() for p in self.pol.split(",")], "switch": self.switch},
            "rail": {"start_m": self.rail_start, "step_m": self.step, "count": self.count, "settle_s": self.settle},
            "site": {"latitude_deg": self.lat, "longitude_deg": self.lon, "height_m": self.site_height,
                     "heading_deg": self.heading},
        })

    def resume_command(self, target: str | Path) -> str:
        """The ``sarcli gbsar scan`` command line that continues ``target``: every option set here, with
        the output replaced by ``--resume target``."""
        parts = ["sarcli", "gbsar", "scan"]
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("output", "resume", "dry_run") or v is None:
                continue
            parts += ["--" + f.name.replace("_", "-"), str(v)]
        return shlex.join([*parts, "--resume", str(target)])


@dataclass
class GbsarPlanOnlyReport(Report):
    """``dry_run``: the plan (stops, sweeps, rail span, estimated durations in s)."""

    plan: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        return {"dry_run": True, **super().to_dict()["plan"]}

    def lines(self) -> list[str]:
        p = self.plan
        return [f"plan OK: {p['n_stops']} stops x {len(p['polarizations'])} pol x {p['points']} points, "
                f"rail {p['rail_m'][0]:g}..{p['rail_m'][1]:g} m, estimated {p['duration_s'] / 60:.1f} min "
                f"(sweep {p['sweep_s']:.2f} s, step move {p['move_s']:.2f} s); nothing moved"]


@dataclass
class GbsarScanReport(Report):
    """The acquisition summary (status, stops, retries, timing, instrument identities, error)."""

    summary: dict[str, Any]
    resume_command: str

    def to_dict(self) -> dict[str, Any]:
        return super().to_dict()["summary"]

    def raise_for_status(self) -> None:
        """The one-line error (instrument fault exit 3, Ctrl-C 130) unless the scan completed."""
        if self.summary["status"] != "complete":
            raise failure(self.summary, self.resume_command)

    def lines(self) -> list[str]:
        s = self.summary
        return [f"wrote {s['output']}: {s['n_complete']} stops, {s['elapsed_s']:.1f} s, {s['retries']} retries"]


def run(config: Config, provenance=None, progress: Progress | None = None,
        stop: Callable[[], bool] | None = None) -> GbsarPlanOnlyReport | GbsarScanReport:
    """Acquire (or plan) the scan. ``stop``: polled between reads to end the scan cleanly (default:
    a first Ctrl-C, see :class:`sarcli.acquire.session.StopGuard`)."""
    progress = progress or no_progress
    with using(provenance):
        cfg = config.scan_config()
        if config.dry_run:
            return GbsarPlanOnlyReport(plan=plan_summary(cfg))
        target = config.resume if config.resume is not None else config.output
        if target is None or (config.output is not None and config.resume is not None):
            raise ConfigError("give exactly one of -o OUTPUT (new scan) or --resume SCAN (continue one)")
        if not config.port or not config.rail_port:
            raise ConfigError("--port (VNA) and --rail-port (GRBL) are required unless --dry-run")
        require_pyserial()
        guard([config.config], [config.output])

        def on_stop(n: int, total: int) -> None:
            progress("stops", n, total)

        with StopGuard() as ctrl_c:
            summary = acquire(cfg, config.port, config.rail_port, target, config.resume is not None,
                              stop or ctrl_c, on_stop)
        return GbsarScanReport(summary=summary, resume_command=config.resume_command(target))
