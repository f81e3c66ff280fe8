"""``gbsar_repeat``: a series of acquisitions (a DInSAR / PS time series), ``count`` scans, one every
``every``, each its own product named by the ``output`` pattern (``{index}`` from 1, ``{utc}`` the
start time).

Scan k starts at t0 + k * every (or at once if the previous scan ran late). A scan that fails is
kept as an interrupted product (one warning line) and the series goes on; Ctrl-C stops the series.
"""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sarcli.acquire.config import load_config, parse_duration
from sarcli.acquire.port import require_pyserial
from sarcli.acquire.session import StopGuard, acquire, failure
from sarcli.errors import ConfigError, InstrumentError, Interrupted, SarcliError
from sarcli.workflows.base import Progress, Report, no_progress, refuse_overwriting_inputs, using

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Config:
    """every: interval between scan starts ("30m", "1h30m", "90s"); count: number of scans; ports;
    config: acquisition TOML; output: file name pattern with {index} and/or {utc}."""

    every: str
    count: int
    port: str
    rail_port: str
    config: Path
    output: str

    def __post_init__(self) -> None:
        if self.count < 1 or self.period_s() < 0:
            raise ConfigError("--count must be >= 1 and --every >= 0")
        if "{index" not in self.output and "{utc" not in self.output:
            raise ConfigError("--output must contain {index} or {utc} so that every scan is its own product")

    def period_s(self) -> float:
        return parse_duration(self.every)

    def resume_command(self, target: str) -> str:
        """The ``sarcli gbsar scan`` command line that continues scan ``target`` of the series."""
        import shlex

        return shlex.join(["sarcli", "gbsar", "scan", "--port", self.port, "--rail-port", self.rail_port,
                           "--config", str(self.config), "--resume", str(target)])


@dataclass
class GbsarRepeatReport(Report):
    """One acquisition summary per scan started; ``interrupted``: the series was stopped by Ctrl-C."""

    count: int
    scans: list[dict[str, Any]] = field(default_factory=list)
    interrupted: bool = False
    resume_command: str = ""

    def to_dict(self) -> Any:
        """The list of the scans' summaries (the ``--json`` output)."""
        return super().to_dict()["scans"]

    def raise_for_status(self) -> None:
        if self.interrupted:
            last = self.scans[-1] if self.scans else {}
            if "n_complete" in last:
                raise failure(last, self.resume_command)
            raise Interrupted("interrupted")
        failed = sum(s["status"] != "complete" for s in self.scans)
        if failed:
            raise InstrumentError(f"{failed} of {self.count} scans did not complete (see above)")

    def lines(self) -> list[str]:
        return [f"{self.count} scans written"]


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarRepeatReport:
    c = config
    progress = progress or no_progress
    with using(provenance):
        require_pyserial()
        cfg = load_config(c.config)
        period = c.period_s()
        report = GbsarRepeatReport(count=c.count)
        t0 = time.monotonic()
        with StopGuard() as ctrl_c:
            for k in range(c.count):
                wait_until = t0 + k * period
                while time.monotonic() < wait_until and not ctrl_c():
                    time.sleep(min(0.2, wait_until - time.monotonic()))
                if ctrl_c():
                    break
                utc = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
                try:
                    path = c.output.format(index=k + 1, utc=utc)
                except (KeyError, ValueError, IndexError) as e:
                    raise ConfigError(f"bad --output pattern '{c.output}': {e}") from None
                refuse_overwriting_inputs([c.config], [path])
                Path(path).parent.mkdir(parents=True, exist_ok=True)
                log.info("scan %d/%d -> %s", k + 1, c.count, path)
                try:
                    s = acquire(cfg, c.port, c.rail_port, path, False, ctrl_c)
                except SarcliError as e:  # e.g. instruments not answering at this slot
                    s = {"output": path, "status": "failed", "error": str(e)}
                if s["status"] != "complete":
                    warnings.warn(f"scan {k + 1} ({path}) did not complete: {s['error']}", stacklevel=2)
                report.scans.append(s)
                progress("scans", k + 1, c.count)
                if ctrl_c():
                    break
            report.interrupted = ctrl_c.requested
        if report.scans:
            report.resume_command = c.resume_command(report.scans[-1]["output"])
        return report
