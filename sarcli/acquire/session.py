"""One acquisition from the command line's point of view: plan, create or resume the file, connect,
scan, summarise; and the Ctrl-C guard that turns SIGINT into a clean stop between two reads.
"""

from __future__ import annotations

import datetime as dt
import os
import signal
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.acquire.config import ScanConfig, estimate
from sarcli.acquire.controller import check_resume, connect, run_scan, scan_template
from sarcli.acquire.errors import InstrumentError, Interrupted
from sarcli.errors import ConfigError, SarcliError
from sarcli.io.scan import ScanWriter


class StopGuard:
    """While active, the first Ctrl-C only sets :attr:`requested` (the scan stops cleanly at the next
    read, within ~20 ms); a second Ctrl-C interrupts at once. A no-op outside the main thread."""

    def __init__(self) -> None:
        self.requested = False
        self._old: Any = None

    def __call__(self) -> bool:
        return self.requested

    def _handler(self, signum, frame) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> StopGuard:
        if threading.current_thread() is threading.main_thread():
            self._old = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc) -> None:
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)


def utc_now() -> str:
    return dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def plan_summary(cfg: ScanConfig, remaining: int | None = None) -> dict[str, Any]:
    e = estimate(cfg, remaining)
    return {"n_stops": e.n_stops, "n_sweeps": e.n_sweeps, "polarizations": list(cfg.polarization.polarizations),
            "points": cfg.vna.points, "frequency_hz": [cfg.vna.start_hz, cfg.vna.stop_hz],
            "rail_m": list(e.travel_m), "sweep_s": e.sweep_s, "move_s": e.move_s,
            "duration_s": e.duration_s}


def acquire(cfg: ScanConfig, vna_port: str, rail_port: str, output: str | os.PathLike, resume: bool,
            stop: Callable[[], bool], on_stop: Callable[[int, int], None] | None = None,
            epoch_utc: str | None = None, clock: Callable[[], float] | None = None) -> dict[str, Any]:
    """Run (or resume) one scan into ``output``; returns a summary. Faults after the file exists
    raise SarcliError *after* the file has been closed with every completed stop in it.
    ``epoch_utc`` (a new scan's epoch, default now) and ``clock`` (POSIX seconds for the stop times,
    default ``time.time``) let a simulated campaign clock (``gbsar monitor --time-scale``) stamp the scan."""
    output = str(output)
    if resume:
        n_done, epoch = check_resume(output, cfg)
    else:
        if Path(output).exists():
            raise ConfigError(f"{output} exists; continue it with --resume {output} or choose another name")
        n_done, epoch = 0, epoch_utc or utc_now()
    inst = connect(cfg, vna_port, rail_port, stop_requested=stop)
    try:
        if resume:
            writer = ScanWriter.resume(output)
            if writer.n_complete != n_done:
                writer.close()
                raise SarcliError(f"{output} changed while resuming")
        else:
            writer = ScanWriter.create(output, scan_template(cfg, inst.identity, epoch), cfg.rail.count,
                                       parameters={"config": cfg.identity()})
        if on_stop is not None:
            on_stop(writer.n_complete, cfg.rail.count)
        res = run_scan(cfg, inst, writer, epoch,
                       on_stop=None if on_stop is None else (lambda n: on_stop(n, cfg.rail.count)),
                       stop_requested=stop, clock=clock)
    finally:
        inst.close()
    summary = {"output": output, "status": res.status, "n_complete": res.n_complete,
               "n_planned": res.n_planned, "resumed_from": n_done if resume else None,
               "elapsed_s": res.elapsed_s, "retries": res.retries,
               "overhead_per_stop_ms": float(np.mean(res.overhead_s) * 1e3) if res.overhead_s else None,
               "vna": inst.identity.get("vna_idn"), "rail": inst.identity.get("rail_banner"),
               "error": res.error or None, "interrupted": res.interrupted}
    return summary


def failure(summary: dict[str, Any], resume_command: str | None = None) -> SarcliError:
    """The one-line error for an acquisition that ended early (file kept, --resume hint).

    ``resume_command``: the full command line that continues the scan (the caller knows its options).
    """
    n, total, out = summary["n_complete"], summary["n_planned"], summary["output"]
    hint = resume_command or f"sarcli gbsar scan --port VNA_PORT --rail-port RAIL_PORT -c CONFIG --resume {out}"
    kind = Interrupted if summary.get("interrupted") else InstrumentError
    return kind(f"{summary['error']}; {out} keeps {n} of {total} stops; continue with: {hint}")
