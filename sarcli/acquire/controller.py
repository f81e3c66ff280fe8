"""The scan controller: connect, identify, configure, then stop by stop move -> settle -> sweep
each polarization -> append + flush -> next.

Invariants: a stop is appended to the scan file (and flushed) before the rail moves on; any
instrument failure, alarm, unplugged port or Ctrl-C ends the loop with every completed stop in the
file (status "interrupted"), so ``--resume`` can continue from the next stop. A resumed scan
re-checks that the file's measurement settings equal the configuration.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.acquire.config import ScanConfig, to_attrs, validate
from sarcli.acquire.errors import InstrumentError, Interrupted
from sarcli.acquire.grbl import GrblRail
from sarcli.acquire.polswitch import GrblPinSwitch, PolSwitch, SinglePolarization, Switch11713A
from sarcli.acquire.port import Port
from sarcli.acquire.prologix import Prologix
from sarcli.acquire.vna8753 import MAX_FREQUENCY_HZ, MAX_FREQUENCY_OPT006_HZ, Prologix8753
from sarcli.errors import ConfigError, SarcliError
from sarcli.io.h5common import open_product
from sarcli.io.scan import PRODUCT_TYPE, ScanWriter
from sarcli.model.gbsar import Scan


@dataclass
class Instruments:
    vna: Prologix8753
    rail: GrblRail
    switch: PolSwitch
    ports: list[Port]
    identity: dict[str, Any] = field(default_factory=dict)

    def close(self) -> None:
        for p in self.ports:
            p.close()


def connect(cfg: ScanConfig, vna_port: str, rail_port: str,
            stop_requested: Callable[[], bool] | None = None) -> Instruments:
    """Open both ports, identify both instruments (refusing a mismatch), configure the VNA."""
    ports: list[Port] = []
    try:
        vp = Port(vna_port, "VNA", stop_requested=stop_requested)
        ports.append(vp)
        rp = Port(rail_port, "rail", stop_requested=stop_requested)
        ports.append(rp)
        gpib = Prologix(vp, cfg.vna.gpib_address, cfg.vna.read_timeout_ms, cfg.vna.retries, cfg.vna.read_margin_s)
        ident: dict[str, Any] = {"prologix_version": gpib.init()}
        vna = Prologix8753(gpib, cfg.vna.gpib_address, cfg.vna.retries, cfg.vna.data_timeout_s,
                           cfg.vna.opc_read_timeout_ms)
        vid = vna.identify()
        if vid["model"].upper() != cfg.vna.model.upper():
            raise InstrumentError(f"the VNA at {vna_port} identifies as '{vid['idn']}', "
                                  f"not the configured model {cfg.vna.model}")
        ident.update({f"vna_{k}": v for k, v in vid.items()})
        fmax = MAX_FREQUENCY_OPT006_HZ if "006" in vid["options"].split() else MAX_FREQUENCY_HZ
        rail = GrblRail(rp, cfg.rail.retries, cfg.rail.timeout_s)
        ident["rail_version"] = rail.connect()
        ident["rail_banner"] = rail.banner
        validate(cfg, max_frequency_hz=fmax, max_travel_mm=rail.max_travel_mm)
        if cfg.rail.home:
            rail.home()
        if cfg.vna.preset:
            vna.preset()
        vna.configure(cfg.vna_settings())
        ident["vna_sweep_time_s"] = vna.sweep_time_s
        switch = make_switch(cfg, rail, gpib)
        return Instruments(vna, rail, switch, ports, ident)
    except BaseException:
        for p in ports:
            p.close()
        raise


def make_switch(cfg: ScanConfig, rail: GrblRail, gpib: Prologix) -> PolSwitch:
    p = cfg.polarization
    if p.switch == "grbl":
        return GrblPinSwitch(rail, settle_s=p.settle_s)
    if p.switch == "11713a":
        return Switch11713A(gpib, p.address, p.settle_s)
    return SinglePolarization(p.polarizations[0])


def scan_template(cfg: ScanConfig, identity: dict[str, Any], epoch_utc: str) -> Scan:
    """An empty scan carrying the frequency axis, polarizations, site and settings."""
    n_pol, n_f = len(cfg.polarization.polarizations), cfg.vna.points
    instrument = {**to_attrs(cfg), **{k: v for k, v in identity.items() if v is not None},
                  "pol_convention": "TX letter then RX letter",
                  **{f"identity_{k}": v for k, v in cfg.identity().items()}}
    return Scan(s21=np.zeros((n_pol, 0, n_f), np.complex64), frequency=cfg.vna_settings().frequencies(),
                rail_position=np.zeros(0), rail_height=np.zeros(0),
                polarizations=tuple(cfg.polarization.polarizations), epoch_utc=epoch_utc, site=cfg.site,
                antenna=cfg.antenna, instrument=instrument, source="measured", status="interrupted",
                n_planned=cfg.rail.count)


def check_resume(path: str, cfg: ScanConfig) -> tuple[int, str]:
    """(n_complete, epoch_utc) of an interrupted scan whose settings equal ``cfg``'s."""
    with open_product(path, PRODUCT_TYPE) as f:
        if f.attrs.get("source") not in ("measured", b"measured"):
            raise ConfigError(f"{path} is not a measured scan; only 'sarcli gbsar scan' files can be resumed")
        inst = f["instrument"].attrs if "instrument" in f else {}
        for key, want in cfg.identity().items():
            got = inst.get(f"identity_{key}")
            got = got.decode() if isinstance(got, bytes) else got
            got = got.item() if hasattr(got, "item") else got
            if got != want:
                raise ConfigError(f"cannot resume {path}: {key} is {got!r} in the file but {want!r} now")
        n = int(f.attrs["n_complete"])
        epoch = f.attrs["epoch_utc"]
        status = f.attrs.get("status")
    epoch = epoch.decode() if isinstance(epoch, bytes) else str(epoch)
    status = status.decode() if isinstance(status, bytes) else status
    if status == "complete" or n >= cfg.rail.count:
        raise ConfigError(f"{path} is already complete ({n} of {cfg.rail.count} stops)")
    return n, epoch


def _epoch_seconds(epoch_utc: str) -> float:
    from datetime import datetime
    return datetime.fromisoformat(epoch_utc.replace("Z", "+00:00")).timestamp()


@dataclass
class ScanResult:
    n_complete: int
    n_planned: int
    status: str
    elapsed_s: float
    overhead_s: list[float] = field(default_factory=list)  # per stop: time not spent in sweep/move
    retries: int = 0
    error: str = ""
    interrupted: bool = False


def run_scan(cfg: ScanConfig, inst: Instruments, writer: ScanWriter, epoch_utc: str,
             on_stop: Callable[[int], None] | None = None,
             stop_requested: Callable[[], bool] | None = None,
             clock: Callable[[], float] | None = None) -> ScanResult:
    """Measure stops ``writer.n_complete .. count-1``; returns how it ended (never raises on faults).
    ``clock``: POSIX seconds stamping each stop (default ``time.time``; a simulated campaign clock)."""
    r, pols = cfg.rail, cfg.polarization.polarizations
    positions = r.positions()
    t_epoch = _epoch_seconds(epoch_utc)
    stop = stop_requested or (lambda: False)
    clock = clock or time.time
    t0 = time.perf_counter()
    res = ScanResult(writer.n_complete, r.count, "interrupted", 0.0)
    data = np.empty((len(pols), cfg.vna.points), np.complex64)
    try:
        for k in range(writer.n_complete, r.count):
            if stop():
                raise Interrupted("interrupted by the user")
            ts = time.perf_counter()
            st = inst.rail.move_to(r.machine_mm(positions[k]), r.feed_mm_min)
            t_move = time.perf_counter() - ts
            _sleep(r.settle_s, stop)
            stamp = clock() - t_epoch
            t_sweep = 0.0
            for i, pol in enumerate(pols):
                inst.switch.select(pol)
                tw = time.perf_counter()
                inst.vna.sweep()
                t_sweep += time.perf_counter() - tw
                data[i] = inst.vna.read_data()
            writer.append(data, st.x_mm / 1000.0 + r.machine_zero_m, r.height_m, stamp)
            res.overhead_s.append(time.perf_counter() - ts - t_move - t_sweep - r.settle_s)
            res.n_complete = writer.n_complete
            if on_stop is not None:
                on_stop(writer.n_complete)
        res.status = "complete"
        if r.return_to_start:
            inst.rail.move_to(r.machine_mm(positions[0]), r.feed_mm_min)
    except (InstrumentError, Interrupted) as e:
        res.error, res.interrupted = str(e), isinstance(e, Interrupted)
        if inst.rail.in_motion:
            _safe_hold(inst)
    finally:
        res.elapsed_s = time.perf_counter() - t0
        res.retries = inst.vna.retry_count + inst.rail.retry_count
        writer.f.attrs["n_retries"] = int(writer.f.attrs.get("n_retries", 0)) + res.retries
        writer.finish(res.status)
    return res


def _safe_hold(inst: Instruments) -> None:
    """Best effort feed hold after a failure (the port may be gone)."""
    try:
        inst.rail.feed_hold()
    except SarcliError:
        pass


def _sleep(seconds: float, stop: Callable[[], bool]) -> None:
    end = time.monotonic() + seconds
    while (left := end - time.monotonic()) > 0:
        if stop():
            raise Interrupted("interrupted by the user")
        time.sleep(min(left, 0.05))
