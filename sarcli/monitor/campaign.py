"""A campaign being processed: scan file -> focused image on the campaign's grid -> update -> commit
(:mod:`sarcli.monitor.store`) -> alarm lines, log, hooks -> live page. The same object serves the
unattended ``gbsar monitor`` (one scan at a time, as they are acquired) and the offline ``gbsar series``
(every scan of a folder, focused in parallel): the numbers are the same because the update is.

The first complete scan fixes the grid (the focuser's default grid for ``[focus]``), the support, the
pixel heights (DEM), the area masks and the watch pixels; every later scan is focused on that grid and
must have the same sweep and rail (else it is rejected). Scan time: the file's epoch plus the mean
stop time.
"""

from __future__ import annotations

import datetime as dt
import json
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, ProductError, SarcliError
from sarcli.gbsar.focus import Grid, image_from_scan
from sarcli.gbsar.interferometry import support
from sarcli.io.atomic import atomic_path
from sarcli.io.scan import read_scan
from sarcli.model.gbsar import GbsarImage, Scan
from sarcli.monitor import engine
from sarcli.monitor.alarms import csv_line, describe, run_hook
from sarcli.monitor.config import MonitorConfig
from sarcli.monitor.geometry import area_masks, pixel_heights, watch_pixels
from sarcli.monitor.meteo import MeteoFile
from sarcli.monitor.page import render
from sarcli.monitor.store import Store

log = logging.getLogger("sarcli.monitor")
GEOMETRY_CHANGED = "the sweep or the rail differs from the first scan's"


def scan_time(scan: Scan) -> float:
    """POSIX seconds of a scan: epoch + mean stop time."""
    try:
        t0 = dt.datetime.fromisoformat(scan.epoch_utc.replace("Z", "+00:00")).timestamp()
    except ValueError:
        raise ProductError(f"unreadable scan epoch '{scan.epoch_utc}'") from None
    st = scan.stop_time if scan.stop_time is not None and scan.stop_time.size else np.zeros(1)
    return t0 + float(np.mean(st))


def scan_complete(scan: Scan) -> bool:
    return scan.status in ("complete", "simulated") and scan.n_stops >= (scan.n_planned or scan.n_stops)


def geometry(scan: Scan) -> dict[str, Any]:
    """What must not change from scan to scan: the sweep and the rail (positions to 0.1 mm, height)."""
    f = scan.frequency
    return {"n_freq": int(f.size), "f_first_hz": float(f[0]), "f_last_hz": float(f[-1]),
            "rail_m": [round(float(x), 4) for x in np.sort(scan.rail_position)],
            "rail_height_m": round(float(np.mean(scan.rail_height)), 4)}


def focus(scan: Scan, cfg: MonitorConfig, ranges: np.ndarray | None = None, azimuths: np.ndarray | None = None,
          pol: str | None = None) -> GbsarImage:
    """The scan focused with ``[focus]`` for the monitored polarization (on the given grid, if any)."""
    pol = (pol or cfg.processing.pol or scan.polarizations[0]).upper()
    scan.pol(pol)
    grid = Grid(ranges=ranges, azimuths=azimuths) if ranges is not None else None
    return image_from_scan(scan, cfg.focus, grid=grid, pols=(pol,))


def focus_file(path: str | os.PathLike, cfg: MonitorConfig, ranges: np.ndarray, azimuths: np.ndarray, pol: str,
               expected_geometry: dict[str, Any]) -> tuple[np.ndarray | None, float, str, bool]:
    """(image or None, time, reason, failed) of a later scan of the campaign, focused on its grid: what
    the offline rebuild runs in worker processes. No image: an incomplete scan (``failed``) or one the
    campaign cannot use (another sweep or rail, no such polarization: rejected)."""
    scan = read_scan(path)
    t = scan_time(scan)
    if not scan_complete(scan):
        return None, t, f"incomplete scan ({scan.n_stops} of {scan.n_planned} stops, {scan.status})", True
    if pol not in scan.polarizations:
        return None, t, f"no {pol} polarization in this scan", False
    if geometry(scan) != expected_geometry:
        return None, t, GEOMETRY_CHANGED, False
    img = focus(scan, cfg, ranges, azimuths, pol)
    return np.asarray(img.image[0], np.complex64), t, "", False


class Campaign:
    """A campaign folder being processed (module docstring).

    ``hook``: shell command run for each alarm event (JSON on stdin); ``on_record``: called with each
    scan's record; ``checkpoint_every``: commit the state every so many scans (1: after every scan, as
    the monitor does; the offline rebuild commits less often and always at the end); ``page``: rewrite
    ``index.html`` at each commit.
    """

    def __init__(self, root: str | os.PathLike, cfg: MonitorConfig, hook: str | None = None,
                 hook_timeout_s: float = 30.0, on_record: Callable[[dict[str, Any]], None] | None = None,
                 checkpoint_every: int = 1, page: bool = True, parameters: dict[str, Any] | None = None):
        self.root = Path(root)
        self.cfg = cfg
        self.hook, self.hook_timeout_s = hook, hook_timeout_s
        self.on_record = on_record
        self.checkpoint_every, self.page = max(1, checkpoint_every), page
        self.parameters = parameters
        self.store = Store(self.root)
        self.static: engine.Static | None = None
        self.state: engine.State | None = None
        self.meteo = MeteoFile(cfg.meteo) if cfg.meteo is not None else None
        self._dirty = 0
        self.records: list[dict[str, Any]] = []

    @property
    def next_index(self) -> int:
        return (self.state.last_scan if self.state is not None else 0) + 1

    def open(self) -> list[str]:
        """Load the committed state and undo what a crash left past it; returns what was removed."""
        self.store.create()
        loaded = self.store.read_state()
        if loaded is not None:
            self.static, self.state = loaded
        removed = self.store.recover(self.state.last_scan if self.state else 0,
                                     self.state.alarms_csv_bytes if self.state else 0)
        for r in removed:
            self._log(f"recovery: removed {r} (written after the last commit)")
        return removed

    def title(self) -> str:
        return self.cfg.page.title or self.root.resolve().name

    # -- scans -------------------------------------------------------------------------------------------
    def _make_static(self, img: GbsarImage, scan_geometry: dict[str, Any], t: float) -> engine.Static:
        cfg = self.cfg
        pol = img.polarizations[0]
        sup = support(img, pol)
        dz = None
        if cfg.aps.dem is not None:
            dz = (pixel_heights(cfg.aps.dem, img) - img.rail_height_m).astype(np.float32)
        masks = area_masks(cfg.areas, img)
        watch = watch_pixels(cfg.watch, img, np.abs(img.image[0]))
        return engine.Static(ranges=img.range_m, azimuths=img.azimuth_m, wavelength_m=img.wavelength_m,
                             rail_height_m=img.rail_height_m, rail_centre_m=img.rail_centre_m,
                             rail_length_m=img.rail_length_m, site=img.site, pol=pol, geometry=scan_geometry,
                             t_ref=t, support=sup, dz=dz, areas=masks, watch=watch)

    def process_file(self, index: int, path: str | os.PathLike) -> dict[str, Any]:
        """Process scan ``index`` from its file (focused here; the first complete one fixes the grid)."""
        if self.static is None:
            scan = read_scan(path)
            t = scan_time(scan)
            if not scan_complete(scan):
                return self.process(index, None, t, f"incomplete scan ({scan.n_stops} of {scan.n_planned} "
                                                    f"stops, {scan.status})")
            img = focus(scan, self.cfg)
            self.first_image(img, geometry(scan), t)
            return self.process(index, np.asarray(img.image[0], np.complex64), t)
        st = self.static
        return self.process(index, *focus_file(path, self.cfg, st.ranges, st.azimuths, st.pol, st.geometry))

    def first_image(self, img: GbsarImage, scan_geometry: dict[str, Any], t: float) -> None:
        """Fix the campaign's grid from its first complete scan, focused."""
        self.static = self._make_static(img, scan_geometry, t)

    def process(self, index: int, image: np.ndarray | None, t: float, reason: str = "",
                failed: bool = True) -> dict[str, Any]:
        """Update with scan ``index``; ``image`` None: a scan not used, ``reason`` why (``failed``: not
        acquired completely; otherwise rejected)."""
        if self.state is not None and index <= self.state.last_scan:
            raise SarcliError(f"scan {index} is already in the store (last scan {self.state.last_scan})")
        meteo = self.meteo.at(t) if self.meteo is not None else None
        if image is None or self.static is None:
            prev = self.state or engine.new_state(self.cfg)
            state = engine.State(**{k: getattr(prev, k) for k in prev.__dataclass_fields__})
            out = engine.reject(state, index, t, reason or "no usable image", failed=failed)
            self.state = state
        elif self.state is None or self.state.n_accepted == 0:
            prev = self.state
            self.state, out = engine.first_scan(self.cfg, self.static, image, index, t, meteo)
            if prev is not None:  # scans not used before the first usable one
                self.state.n_failed, self.state.n_rejected = prev.n_failed, prev.n_rejected
                self.state.alarms_csv_bytes = prev.alarms_csv_bytes
        else:
            self.state, out = engine.update(self.cfg, self.static, self.state, image, index, t, meteo)
        self._commit(out)
        return out.record

    # -- commit ----------------------------------------------------------------------------------------
    def _log(self, line: str, level: int = logging.INFO) -> None:
        log.log(level, line)
        stamp = dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
        with open(self.root / "monitor.log", "a", encoding="utf-8") as fh:
            fh.write(f"{stamp} {line}\n")

    def _commit(self, out: engine.Outcome) -> None:
        rec = out.record
        self.store.write_epoch(rec, out.maps, self.parameters)
        self.state.alarms_csv_bytes = self.store.append_alarms([csv_line(e) for e in out.events])
        if rec["status"] == "accepted":
            self._log(f"scan {rec['scan']} ({rec['time_utc']}): {rec['n_points']} points, APS residual "
                      f"{'-' if rec['aps_residual_mm'] is None else format(rec['aps_residual_mm'], '.3f')} mm, level "
                      f"{rec['alarm_level']}")
        else:
            self._log(f"scan {rec['scan']} ({rec['time_utc']}) {rec['status']}: {rec['reason']}", logging.WARNING)
        for ev in out.events:
            self._log(describe(ev), logging.WARNING)
            if self.hook:
                err = run_hook(self.hook, ev, self.hook_timeout_s)
                if err is not None:
                    self._log(f"the --on-alarm hook failed for {ev['area']} at scan {ev['scan']}: {err}",
                              logging.WARNING)
        self._dirty += 1
        if self._dirty >= self.checkpoint_every:
            self.checkpoint()
        self.records.append(rec)
        if self.on_record is not None:
            self.on_record(rec)

    def checkpoint(self) -> None:
        """Commit the state (and rewrite the page) if anything is not committed yet."""
        if self._dirty and self.state is not None and self.static is not None:
            self.store.write_state(self.static, self.state, self.parameters)
            self._dirty = 0
            if self.page:
                self.write_page()
        elif self._dirty and self.state is not None:  # only failed scans so far: nothing to show on a grid
            self._dirty = 0

    def write_page(self) -> None:
        if self.static is None or self.state is None or self.state.n_accepted == 0:
            return
        now = dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
        text = render(self.cfg, self.static, self.state, self.title(), now)
        with atomic_path(self.root / "index.html", ".html") as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)


def read_campaign_json(root: Path) -> dict[str, Any]:
    p = Path(root) / "campaign.json"
    try:
        return json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{root}: not a monitoring campaign (no campaign.json)") from None
    except json.JSONDecodeError as e:
        raise ProductError(f"{p}: unreadable ({e})") from None
