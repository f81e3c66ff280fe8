"""``gbsar_series``: rebuild a campaign store from scans already on disk, from scratch, with the same
processing (and so the same numbers) as ``gbsar monitor`` (:mod:`sarcli.monitor`).

Input: a campaign folder (its ``scans/scan_NNNNN.h5`` and ``campaign.json``'s configuration) or scan
files in time order with ``-c monitor.toml`` (scan k is the k-th file). Output: the store,
``alarms.csv`` and ``index.html`` in ``out`` (default: the campaign folder, whose old store is
replaced). The scans are focused ``jobs`` at a time in worker processes (the focusing of one scan
does not depend on the others) while the update, which is sequential by nature, consumes them in
order; at most ``2 jobs`` images wait in memory. The state is committed every ``checkpoint_every``
scans and at the end, the page written at the end. Alarm hooks run only with ``on_alarm``.
"""

from __future__ import annotations

import os
import re
import shutil
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.io.scan import read_scan
from sarcli.monitor.campaign import Campaign, focus, focus_file, geometry, read_campaign_json, scan_complete, scan_time
from sarcli.monitor.config import MonitorConfig, load_monitor_config, parse_monitor_config
from sarcli.workflows.base import Progress, Report, no_progress, refuse_overwriting_inputs, using
from sarcli.workflows.gbsar_common import parameters

_SCAN = re.compile(r"^scan_(\d+)\.h5$")


@dataclass(frozen=True)
class Config:
    """inputs: one campaign folder, or scan files in time order; config: monitor TOML (default: the
    campaign's); out: output folder (default: the campaign folder); jobs: worker processes focusing
    scans (0: one per core); checkpoint_every: scans between state commits; on_alarm: hook command."""

    inputs: tuple[Path, ...]
    config: Path | None = None
    out: Path | None = None
    jobs: int = 0
    checkpoint_every: int = 50
    on_alarm: str | None = None
    hook_timeout_s: float = 30.0

    def __post_init__(self) -> None:
        if not self.inputs:
            raise ConfigError("give a campaign folder or scan files")
        if self.jobs < 0 or self.checkpoint_every < 1:
            raise ConfigError("--jobs must be >= 0 and --checkpoint-every >= 1")


@dataclass
class CampaignReport(Report):
    """A campaign's summary (``gbsar monitor`` and ``gbsar series``): its scans by outcome, from the
    campaign's state, and the alarm level of the last accepted scan; ``records``: the scans this run
    processed."""

    out: str
    n_scans: int = 0
    n_accepted: int = 0
    n_rejected: int = 0
    n_failed: int = 0
    alarm_level: str = "none"
    records: list[dict[str, Any]] = field(default_factory=list)

    def count(self, camp: Campaign) -> None:
        """Take the counts and the alarm level from the campaign's state (none yet: unchanged)."""
        s = camp.state
        if s is not None:
            self.n_scans, self.n_accepted, self.n_rejected, self.n_failed = (s.last_scan, s.n_accepted,
                                                                             s.n_rejected, s.n_failed)
            self.alarm_level = s.last_accepted_record.get("alarm_level", "none")

    def lines(self) -> list[str]:
        return [f"{self.out}: {self.n_scans} scans ({self.n_accepted} accepted, {self.n_rejected} rejected, "
                f"{self.n_failed} failed), alarm level {self.alarm_level}"]


@dataclass
class GbsarSeriesReport(CampaignReport):
    def lines(self) -> list[str]:
        return ["rebuilt " + line for line in super().lines()]


def campaign_scans(folder: Path) -> list[Path]:
    """``folder/scans/scan_NNNNN.h5`` in index order; a gap in the numbering is refused."""
    found = sorted((int(m.group(1)), p) for p in (folder / "scans").glob("scan_*.h5") if (m := _SCAN.match(p.name)))
    if not found:
        raise ConfigError(f"{folder}/scans holds no scan_NNNNN.h5")
    missing = sorted(set(range(1, found[-1][0] + 1)) - {k for k, _ in found})
    if missing:
        raise ConfigError(f"{folder}/scans: scan(s) {missing[:5]} missing from the numbering")
    return [p for _, p in found]


def _inputs(c: Config) -> tuple[list[Path], MonitorConfig, Path]:
    if len(c.inputs) == 1 and c.inputs[0].is_dir():
        folder = c.inputs[0]
        scans = campaign_scans(folder)
        if c.config is not None:
            cfg = load_monitor_config(c.config)
        else:
            cfg = parse_monitor_config(read_campaign_json(folder)["config"], f"{folder}/campaign.json")
        return scans, cfg, c.out or folder
    if c.config is None or c.out is None:
        raise ConfigError("with scan files, give -c monitor.toml and --out FOLDER")
    return list(c.inputs), load_monitor_config(c.config), c.out


def _clear(out: Path) -> None:
    """Remove a previous store, alarm log, page and log from ``out`` (they are rebuilt)."""
    if (out / "store").exists():
        shutil.rmtree(out / "store")
    for name in ("alarms.csv", "index.html", "monitor.log"):
        (out / name).unlink(missing_ok=True)


def run(config: Config, provenance=None, progress: Progress | None = None,
        on_record: Callable[[dict[str, Any]], None] | None = None) -> GbsarSeriesReport:
    c = config
    progress = progress or no_progress
    with using(provenance):
        scans, cfg, out = _inputs(c)
        refuse_overwriting_inputs(scans, [out / "alarms.csv", out / "index.html", out / "store" / "state.h5"])
        if any(out.resolve() / "store" in p.resolve().parents for p in scans):
            raise ConfigError(f"the scans are inside {out}/store, which the rebuild replaces: choose another --out")
        out.mkdir(parents=True, exist_ok=True)
        _clear(out)
        camp = Campaign(out, cfg, hook=c.on_alarm, hook_timeout_s=c.hook_timeout_s, on_record=on_record,
                        checkpoint_every=c.checkpoint_every, page=False, parameters=parameters(c))
        camp.open()
        n = len(scans)
        k = 0
        while k < n and camp.static is None:  # the first complete scan fixes the grid (in this process)
            scan = read_scan(scans[k])
            if scan_complete(scan):
                img = focus(scan, cfg)
                camp.first_image(img, geometry(scan), scan_time(scan))
                camp.process(k + 1, img.image[0], scan_time(scan))
            else:
                camp.process(k + 1, None, scan_time(scan), f"incomplete scan ({scan.n_stops} of {scan.n_planned} "
                                                          f"stops, {scan.status})")
            progress("scans", k + 1, n)
            k += 1
        rest = list(range(k, n))
        st = camp.static
        grid = (st.ranges, st.azimuths, st.pol, st.geometry) if st is not None else ()
        jobs = c.jobs or os.cpu_count() or 1
        if jobs == 1 or len(rest) < 2:
            for i in rest:
                camp.process(i + 1, *focus_file(str(scans[i]), cfg, *grid))
                progress("scans", i + 1, n)
        else:
            import multiprocessing

            # forkserver: a fork of a process that ran OpenMP (numba, BLAS) is unsafe; spawn where no forkserver
            ctx = multiprocessing.get_context("forkserver" if "forkserver" in multiprocessing.get_all_start_methods()
                                              else "spawn")
            with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as pool:
                pending: deque[tuple[int, Future]] = deque()
                todo = iter(rest)
                for i in todo:
                    pending.append((i, pool.submit(focus_file, str(scans[i]), cfg, *grid)))
                    if len(pending) >= 2 * jobs:
                        break
                while pending:
                    i, fut = pending.popleft()
                    camp.process(i + 1, *fut.result())
                    progress("scans", i + 1, n)
                    nxt = next(todo, None)
                    if nxt is not None:
                        pending.append((nxt, pool.submit(focus_file, str(scans[nxt]), cfg, *grid)))
        camp.checkpoint()
        camp.write_page()
        rep = GbsarSeriesReport(out=str(out), records=camp.records)
        rep.count(camp)
        return rep

