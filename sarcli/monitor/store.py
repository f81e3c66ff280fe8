"""The campaign store on disk: immutable per-scan epoch files and one small state file replaced
atomically (the commit point), with the alarm log; crash-safe and of flat per-scan cost.

Layout of a campaign folder::

    campaign.json           how the campaign was started (configuration, clock), written once
    scans/scan_00001.h5     the raw scans (gbsar_scan products), one per acquisition
    store/state.h5          gbsar_monitor_state: the grid and everything the next update needs
    store/epochs/scan_00001.h5  gbsar_monitor_epoch: one per scan (record; maps of accepted scans)
    alarms.csv              one line per alarm event (header first)
    index.html              the live page
    monitor.log             one line per scan and per event (not part of the store)

Commit protocol for scan k: (1) write ``epochs/scan_k.h5`` to a temporary name, fsync it, rename it,
fsync the folder; (2) append the scan's alarm lines to ``alarms.csv`` and fsync it; (3) run the hooks;
(4) write ``state.h5`` the same way as (1): it records k and the length of ``alarms.csv``. The state's
rename is the commit: a power cut before it leaves the previous state (its files untouched) and, at
most, an epoch file and alarm lines past it, which :meth:`Store.recover` deletes and truncates
before the scan is processed again; after it the scan is in. Nothing written earlier is ever opened
for writing again, and each commit writes one epoch file and one state file whose sizes do not depend
on the number of scans stored: the per-scan cost is flat (``bench/bench_monitor.py``).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import atomic_h5, attr_str, dataset, group, open_product, to_jsonable
from sarcli.model.gbsar import Site
from sarcli.monitor.alarms import AlarmState, csv_header
from sarcli.monitor.engine import AreaState, Chart, State, Static

STATE_TYPE, EPOCH_TYPE, SCHEMA_VERSION = "gbsar_monitor_state", "gbsar_monitor_epoch", "1"
_EPOCH_RE = re.compile(r"^scan_(\d+)\.h5$")
_STATE_ARRAYS = ("last_image", "phase", "ring_d", "ring_t", "sum_amp", "sum_amp2", "sum_coh", "sum_cos", "displacement",
                 "velocity", "acceleration", "coherence", "selected", "stable", "aps")
_STATE_SCALARS = ("last_scan", "n_accepted", "n_rejected", "n_failed", "last_time_h", "ring_n", "n_coh",
                  "recent_events", "last_record", "last_accepted_record", "alarms_csv_bytes")
_UNITS = {"displacement_mm": "mm", "velocity_mm_per_h": "mm/h", "acceleration_mm_per_h2": "mm/h^2",
          "coherence": "1", "selected": "0 none, 1 PS, 2 DS", "stable": "1", "aps_mm": "mm"}


def fsync_path(path: str | os.PathLike) -> None:
    """Flush a file's or a folder's data and metadata to the device."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def durable_h5(path: Path, product_type: str, parameters: dict[str, Any] | None = None) -> Iterator[h5py.File]:
    """A new product that appears at ``path`` complete and on the device, or not at all (the old file, if
    any, stays until the rename): written under a temporary name, fsynced, renamed, folder fsynced."""
    part = path.with_name(f".{path.name}.part")
    with atomic_h5(part, product_type, SCHEMA_VERSION, parameters) as f:
        yield f
    fsync_path(part)
    os.replace(part, path)
    fsync_path(path.parent)


def _json(obj: Any) -> str:
    return json.dumps(to_jsonable(obj), sort_keys=True)


class Store:
    """The store of a campaign folder (module docstring)."""

    def __init__(self, root: str | os.PathLike):
        self.root = Path(root)
        self.dir = self.root / "store"
        self.epochs = self.dir / "epochs"
        self.state_path = self.dir / "state.h5"
        self.alarms = self.root / "alarms.csv"

    def epoch_path(self, index: int) -> Path:
        return self.epochs / f"scan_{index:05d}.h5"

    def create(self) -> None:
        """Empty store folders and the alarm log's header (nothing committed yet)."""
        self.epochs.mkdir(parents=True, exist_ok=True)
        if not self.alarms.exists() or self.alarms.stat().st_size < len(csv_header()):
            with open(self.alarms, "w", encoding="utf-8") as fh:
                fh.write(csv_header())
                fh.flush()
                os.fsync(fh.fileno())

    def recover(self, committed_scan: int, alarms_bytes: int) -> list[str]:
        """Undo what a crash left past the last commit: temporary files, epoch files after
        ``committed_scan``, alarm lines past ``alarms_bytes``. Returns what was removed."""
        self.create()
        removed = []
        for folder in (self.dir, self.epochs, self.root):
            for p in folder.iterdir():
                if p.name.startswith(".") and (p.name.endswith(".part") or p.name.endswith(".tmp")):
                    p.unlink()
                    removed.append(p.name)
        for p in self.epochs.iterdir():
            m = _EPOCH_RE.match(p.name)
            if m and int(m.group(1)) > committed_scan:
                p.unlink()
                removed.append(f"epochs/{p.name}")
        size = self.alarms.stat().st_size
        keep = max(alarms_bytes, len(csv_header()))
        if size > keep:
            with open(self.alarms, "r+b") as fh:
                fh.truncate(keep)
                os.fsync(fh.fileno())
            removed.append(f"alarms.csv past byte {keep}")
        return removed

    def append_alarms(self, lines: list[str]) -> int:
        """Append lines to ``alarms.csv`` (fsynced); returns its new length in bytes."""
        with open(self.alarms, "ab") as fh:
            if lines:
                fh.write("".join(lines).encode("utf-8"))
                fh.flush()
                os.fsync(fh.fileno())
            return fh.tell()

    # -- epoch files -------------------------------------------------------------------------------
    def write_epoch(self, record: dict[str, Any], maps: dict[str, np.ndarray] | None,
                    parameters: dict[str, Any] | None = None) -> Path:
        path = self.epoch_path(int(record["scan"]))
        with durable_h5(path, EPOCH_TYPE, parameters) as f:
            f.attrs["scan"] = int(record["scan"])
            f.attrs["time_utc"] = record["time_utc"]
            f.attrs["status"] = record["status"]
            f.attrs["record"] = _json(record)
            for name, arr in (maps or {}).items():
                dataset(f, name, arr, units=_UNITS.get(name), chunks=True, compression="gzip")
        return path

    def read_epoch(self, index: int) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(record, maps) of scan ``index``."""
        path = self.epoch_path(index)
        with open_product(path, EPOCH_TYPE) as f:
            rec = json.loads(attr_str(f, "record") or "{}")
            return rec, {k: f[k][()] for k in f if isinstance(f[k], h5py.Dataset)}

    def committed_epochs(self, last_scan: int) -> list[int]:
        """Indices of the epoch files up to ``last_scan`` (a listing: for reading, not for updates)."""
        out = []
        for p in self.epochs.iterdir():
            m = _EPOCH_RE.match(p.name)
            if m and int(m.group(1)) <= last_scan:
                out.append(int(m.group(1)))
        return sorted(out)

    # -- state ---------------------------------------------------------------------------------------
    def write_state(self, static: Static, state: State, parameters: dict[str, Any] | None = None) -> None:
        with durable_h5(self.state_path, STATE_TYPE, parameters) as f:
            g = group(f, "static")
            for name in ("ranges", "azimuths", "watch"):
                dataset(g, name, getattr(static, name))
            dataset(g, "support", static.support.astype(np.uint8))
            dataset(g, "areas", static.areas.astype(np.uint8))
            if static.dz is not None:
                dataset(g, "dz", static.dz, units="m")
            g.attrs["meta"] = _json({"wavelength_m": static.wavelength_m, "rail_height_m": static.rail_height_m,
                                     "rail_centre_m": static.rail_centre_m, "rail_length_m": static.rail_length_m,
                                     "site": vars(static.site), "pol": static.pol, "geometry": static.geometry,
                                     "t_ref": static.t_ref})
            for name in _STATE_ARRAYS:
                arr = getattr(state, name)
                dataset(f, name, arr.astype(np.uint8) if arr.dtype == bool else arr)
            dataset(f, "chart_t", state.chart.t)
            dataset(f, "chart_values", state.chart.values)
            meta = {k: getattr(state, k) for k in _STATE_SCALARS}
            meta["chart_names"] = state.chart.names
            meta["areas"] = [{"level": a.alarm.level, "below": a.alarm.below, "run_t": a.run_t, "run_v": a.run_v}
                             for a in state.areas]
            f.attrs["meta"] = _json(meta)
            f.attrs["last_scan"] = int(state.last_scan)

    def read_state(self) -> tuple[Static, State] | None:
        """The committed (static, state), or None before the first commit."""
        if not self.state_path.exists():
            return None
        with open_product(self.state_path, STATE_TYPE) as f:
            if attr_str(f, "schema_version") != SCHEMA_VERSION:
                raise ProductError(f"{self.state_path}: unsupported monitoring store version")
            g = f["static"]
            sm = json.loads(attr_str(g, "meta"))
            static = Static(ranges=g["ranges"][()], azimuths=g["azimuths"][()], wavelength_m=sm["wavelength_m"],
                            rail_height_m=sm["rail_height_m"], rail_centre_m=sm["rail_centre_m"],
                            rail_length_m=sm["rail_length_m"], site=Site(**sm["site"]), pol=sm["pol"],
                            geometry=sm["geometry"], t_ref=sm["t_ref"], support=g["support"][()].astype(bool),
                            dz=g["dz"][()] if "dz" in g else None, areas=g["areas"][()].astype(bool),
                            watch=g["watch"][()])
            meta = json.loads(attr_str(f, "meta"))
            arrays = {k: f[k][()] for k in _STATE_ARRAYS}
            arrays["stable"] = arrays["stable"].astype(bool)
            chart = Chart(meta.pop("chart_names"), f["chart_t"][()], f["chart_values"][()])
        areas = [AreaState(AlarmState(a["level"], a["below"]), a["run_t"], a["run_v"]) for a in meta.pop("areas")]
        last_time = meta.pop("last_time_h")
        state = State(**arrays, **meta, last_time_h=float("nan") if last_time is None else last_time,
                      areas=areas, chart=chart)
        return static, state
