"""``gbsar_monitor``: an unattended monitoring campaign: acquire a scan every ``every`` (as
``gbsar repeat``), focus it as soon as it is complete, update the campaign store, raise alarms and
rewrite the live page (:mod:`sarcli.monitor`, ``docs/monitoring.md``).

The campaign folder ``out`` holds ``campaign.json`` (the configuration and the clock, written when
the campaign starts), ``scans/scan_NNNNN.h5``, the store, ``alarms.csv``, ``index.html`` and
``monitor.log``. Running the same command again resumes: what a crash left past the last commit is
undone, complete scans not yet processed are processed, an interrupted scan is resumed from its next
stop, then the acquisitions go on up to ``count`` scans in all.

Clock: ``time_scale = 1``: scan k starts at ``start + (k-1) every`` on the wall clock (at once if
late) and carries its real time. ``time_scale < 1``: a simulated clock: scan k is stamped
``start + (k-1) every`` (``start``: ``start_utc`` or the campaign's creation) and the monitor waits
``every * time_scale`` of real time between scans (0: not at all), so a week of scans runs in minutes
with velocities in real units (``gbsar emulate --scan-interval`` keeps the same clock).
"""

from __future__ import annotations

import datetime as dt
import json
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sarcli.acquire.config import load_config, parse_duration
from sarcli.errors import ConfigError, Interrupted, ProductError, SarcliError
from sarcli.io.scan import read_scan
from sarcli.monitor.campaign import Campaign, read_campaign_json, scan_time
from sarcli.monitor.config import MonitorConfig, load_monitor_config, parse_monitor_config
from sarcli.monitor.store import fsync_path
from sarcli.workflows.base import Progress, no_progress, using
from sarcli.workflows.gbsar_common import parameters
from sarcli.workflows.gbsar_series import CampaignReport


@dataclass(frozen=True)
class Config:
    """out: the campaign folder; config: monitor TOML (required for a new campaign; when resuming it
    must be the one the campaign started with); ports of the VNA and the rail; every: interval between
    scan starts ("10m"); count: scans in the campaign (None: until Ctrl-C); time_scale (module
    docstring); start_utc: the simulated clock's first scan time (default: now); on_alarm: shell
    command run for each alarm event (the event as JSON on stdin); hook_timeout_s: its time limit."""

    out: Path
    config: Path | None = None
    port: str | None = None
    rail_port: str | None = None
    every: str = "10m"
    count: int | None = None
    time_scale: float = 1.0
    start_utc: str | None = None
    on_alarm: str | None = None
    hook_timeout_s: float = 30.0

    def __post_init__(self) -> None:
        if self.count is not None and self.count < 1:
            raise ConfigError("--count must be >= 1")
        if not 0.0 <= self.time_scale <= 1.0:
            raise ConfigError(f"--time-scale must be in [0, 1], got {self.time_scale:g}")
        if parse_duration(self.every) <= 0:
            raise ConfigError("--every must be > 0")
        if self.start_utc is not None:
            _posix(self.start_utc)
        if not self.hook_timeout_s > 0:
            raise ConfigError("--hook-timeout must be > 0")


def _posix(text: str) -> float:
    try:
        t = dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise ConfigError(f"cannot read the time '{text}' (ISO-8601 UTC, e.g. 2026-05-01T06:00:00Z)") from None
    return (t if t.tzinfo else t.replace(tzinfo=dt.UTC)).timestamp()


def _iso(posix_s: float) -> str:
    return dt.datetime.fromtimestamp(posix_s, dt.UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


@dataclass
class GbsarMonitorReport(CampaignReport):
    """The campaign's summary (:class:`CampaignReport`), and whether this run was interrupted and what it
    recovered from an earlier one's interruption."""

    interrupted: bool = False
    recovered: list[str] = field(default_factory=list)

    def raise_for_status(self) -> None:
        if self.interrupted:
            raise Interrupted(f"interrupted; {self.out} keeps {self.n_scans} scans; run the same command to resume")


def start_campaign(root: Path, cfg: MonitorConfig, every_s: float, time_scale: float, start_utc: str | None,
                   kind: str) -> dict[str, Any]:
    """Create ``root/campaign.json`` (durably) or check it against this run: same configuration and clock."""
    root.mkdir(parents=True, exist_ok=True)
    (root / "scans").mkdir(exist_ok=True)
    path = root / "campaign.json"
    mine = {"config": cfg.to_mapping(), "every_s": every_s, "time_scale": time_scale}
    if path.exists():
        doc = read_campaign_json(root)
        for key, value in mine.items():
            if json.loads(json.dumps(doc.get(key))) != json.loads(json.dumps(value)):
                raise ConfigError(f"{root} was started with another {key.replace('_', ' ')}: resume it with the "
                                  f"same -c/--every/--time-scale, or choose another --out")
        return doc
    doc = {**mine, "kind": kind, "start_utc": start_utc or _iso(time.time()),
           "created_utc": _iso(time.time())}
    tmp = root / ".campaign.json.part"
    tmp.write_text(json.dumps(doc, indent=1, sort_keys=True), encoding="utf-8")
    fsync_path(tmp)
    os.replace(tmp, path)
    fsync_path(root)
    return doc


def _status(path: Path) -> str:
    from sarcli.io.h5common import attr_str, open_product

    with open_product(path, "gbsar_scan") as f:
        status = attr_str(f, "status")
    return "unknown" if status is None else status


def run(config: Config, provenance=None, progress: Progress | None = None,
        on_record: Callable[[dict[str, Any]], None] | None = None) -> GbsarMonitorReport:
    """Run (or resume) the campaign (module docstring); ``on_record`` gets each scan's record."""
    from sarcli.acquire.port import require_pyserial
    from sarcli.acquire.session import StopGuard, acquire

    c = config
    progress = progress or no_progress
    with using(provenance):
        root = c.out
        if (root / "campaign.json").exists():
            stored = read_campaign_json(root)
            cfg = load_monitor_config(c.config) if c.config is not None else \
                parse_monitor_config(stored["config"], f"{root}/campaign.json")
        elif c.config is None:
            raise ConfigError("a new campaign needs -c monitor.toml")
        else:
            cfg = load_monitor_config(c.config)
        every = parse_duration(c.every)
        doc = start_campaign(root, cfg, every, c.time_scale, c.start_utc, "monitor")
        start = _posix(doc["start_utc"])
        scan_cfg = load_config(None, cfg.acquisition)
        camp = Campaign(root, cfg, hook=c.on_alarm, hook_timeout_s=c.hook_timeout_s, on_record=on_record,
                        parameters=parameters(c))
        report = GbsarMonitorReport(out=str(root))
        report.recovered = camp.open()
        total = c.count
        real_start = time.monotonic()
        first_slot = camp.next_index
        with StopGuard() as ctrl_c:
            k = camp.next_index
            while total is None or k <= total:
                path = root / "scans" / f"scan_{k:05d}.h5"
                status = _status(path) if path.exists() else None
                if status not in ("complete", "simulated"):
                    if not c.port or not c.rail_port:
                        raise ConfigError("--port and --rail-port are needed to acquire the next scan")
                    require_pyserial()
                    slot = start + (k - 1) * every
                    if status is None:  # a new scan: wait for its slot
                        wait = slot - time.time() if c.time_scale == 1.0 else \
                            (k - first_slot) * every * c.time_scale - (time.monotonic() - real_start)
                        end = time.monotonic() + max(0.0, wait)
                        while time.monotonic() < end and not ctrl_c():
                            time.sleep(min(0.2, max(end - time.monotonic(), 0.0)))
                        if ctrl_c():
                            break
                    resume = status is not None
                    epoch = None if c.time_scale == 1.0 else _iso(slot)
                    clock = _clock(c.time_scale, _scan_epoch(path) if resume else slot)
                    try:
                        summary = acquire(scan_cfg, c.port, c.rail_port, path, resume, ctrl_c, epoch_utc=epoch,
                                          clock=clock)
                    except SarcliError as e:  # the instruments did not answer at this slot
                        summary = {"status": "failed", "error": str(e), "interrupted": False}
                    if summary.get("interrupted") or ctrl_c():
                        report.interrupted = True
                        break
                    if summary["status"] != "complete":
                        t = scan_time(read_scan(path)) if path.exists() else \
                            (slot if c.time_scale < 1.0 else time.time())
                        report.records.append(camp.process(k, None, t, f"acquisition failed: {summary['error']}"))
                        k += 1
                        continue
                report.records.append(camp.process_file(k, path))
                progress("scans", k, total or k)
                k += 1
            report.interrupted = report.interrupted or ctrl_c.requested
        camp.checkpoint()
        report.count(camp)
        return report


def _clock(time_scale: float, base: float) -> Callable[[], float] | None:
    """Stop-time clock of a scan on the simulated clock (None: the wall clock): ``base`` plus the real
    time elapsed divided by the time scale (nothing at scale 0)."""
    if time_scale == 1.0:
        return None
    m0 = time.monotonic()
    return lambda: base + ((time.monotonic() - m0) / time_scale if time_scale > 0 else 0.0)


def _scan_epoch(path: Path) -> float:
    from sarcli.io.h5common import attr_str, open_product

    with open_product(path, "gbsar_scan") as f:
        epoch = attr_str(f, "epoch_utc")
    if epoch is None:
        raise ProductError(f"{path}: malformed product, attribute 'epoch_utc' missing")
    return _posix(epoch)
