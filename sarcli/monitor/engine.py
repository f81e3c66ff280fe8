"""One scan's update of a monitoring campaign: arrays in, arrays out (no files here).

Notation (code = docs/monitoring.md): image ``z_k`` (complex, one polarization, the campaign's fixed
grid: range R0 x azimuth x), scan time ``t_k`` (h after the first scan), wavelength ``lam``.

1. Wrapped increment ``w = arg(z_k z_{k-1}^*)`` and coherence ``gamma_k`` (boxcar) on the pixels with
   data in both scans; a scan whose measured points have a median coherence below the limit is
   rejected (decorrelated, e.g. rain, a vehicle, an instrument fault).
2. Prediction ``p = APS increment (fitted on the wrapped w of the stable points) - 4 pi v dt/lam``
   (v: each measured point's velocity); temporal unwrapping around it with the plausibility check,
   spatial unwrapping where it fails (:mod:`sarcli.monitor.unwrap`); otherwise the scan is rejected.
3. Cumulative phase ``phi_k = phi_{k-1} + delta_k`` (raw: it still holds the atmosphere).
4. Selection (running sums: amplitude dispersion, mean coherence) and stable points (user areas or
   automatic), APS of the cumulative phase fitted on them (:mod:`sarcli.monitor.aps`), LOS
   displacement ``d_k = -lam/(4 pi) (phi_k - APS_k)`` (mm, + = away from the radar: a scatterer
   moving away by d lengthens R by d and changes the phase ``-4 pi R/lam`` by ``-4 pi d/lam``).
   The APS residual is the RMS of d over the stable points; without APS (only the stable points'
   median removed) it is reported too.
5. Velocity and acceleration maps over the last scans (:mod:`sarcli.monitor.kinematics`), area
   medians over their measured points, alarm levels (:mod:`sarcli.monitor.alarms`), the
   inverse-velocity forecast, the watch points.

The state carried from scan to scan (:class:`State`) is a fixed number of maps (the last image, the
cumulative phase, the last W displacement maps, running sums) and bounded lists: its size does not
grow with the number of scans, so neither does the cost of an update.
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.gbsar.interferometry import coherence
from sarcli.model.gbsar import Site
from sarcli.monitor import aps as aps_mod
from sarcli.monitor.alarms import AlarmState, step
from sarcli.monitor.config import LEVELS, MonitorConfig
from sarcli.monitor.kinematics import acceleration_weights, inverse_velocity_forecast, slope_weights, weighted_sum
from sarcli.monitor.unwrap import unwrap_increment

CHART_CAPACITY = 600  # points per chart series kept for the page (older ones thinned by 2 when full)
RECENT_EVENTS = 50  # alarm events kept for the page (all of them are in alarms.csv)
PS, DS = 1, 2


def utc(posix_s: float) -> str:
    return dt.datetime.fromtimestamp(posix_s, dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


@dataclass
class Static:
    """What the first scan fixes: the grid, geometry, support, heights, areas and watch pixels."""

    ranges: np.ndarray
    azimuths: np.ndarray
    wavelength_m: float
    rail_height_m: float
    rail_centre_m: float
    rail_length_m: float
    site: Site
    pol: str
    geometry: dict[str, Any]
    t_ref: float  # POSIX s of the first scan
    support: np.ndarray  # bool (n_r, n_x)
    dz: np.ndarray | None  # float32 (n_r, n_x): pixel height - antenna height (with a DEM)
    areas: np.ndarray  # bool (n_areas, n_r, n_x)
    watch: np.ndarray  # int (n_watch, 2): row, column

    @property
    def shape(self) -> tuple[int, int]:
        return (self.ranges.size, self.azimuths.size)

    def slant_range(self) -> np.ndarray:
        """Range (m) of every pixel from the rail centre: ``sqrt(R0^2 + (x - x_c)^2)``."""
        return np.hypot(self.ranges[:, None], self.azimuths[None, :] - self.rail_centre_m)


@dataclass
class Chart:
    """Time series for the page, bounded: ``t`` (h) and one row of ``values`` per name."""

    names: list[str]
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    values: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    def append(self, t_h: float, row: dict[str, float]) -> None:
        if self.values.shape[0] != len(self.names):
            self.values = np.zeros((len(self.names), 0))
        col = np.array([[row.get(n, math.nan)] for n in self.names], np.float64)
        self.t = np.append(self.t, t_h)
        self.values = np.hstack([self.values, col])
        if self.t.size >= CHART_CAPACITY:  # thin the older half by 2: bounded, recent scans kept whole
            half = self.t.size // 2
            keep = np.r_[np.arange(0, half, 2), np.arange(half, self.t.size)]
            self.t, self.values = self.t[keep], self.values[:, keep]

    def series(self, name: str) -> np.ndarray:
        return self.values[self.names.index(name)] if self.values.size else np.zeros(0)


@dataclass
class AreaState:
    alarm: AlarmState = field(default_factory=AlarmState)
    run_t: list[float] = field(default_factory=list)  # the last forecast velocity samples (h, mm/h; NaN: none)
    run_v: list[float] = field(default_factory=list)


@dataclass
class State:
    """The campaign after its last recorded scan (module docstring)."""

    last_scan: int = 0
    n_accepted: int = 0
    n_rejected: int = 0
    n_failed: int = 0
    last_time_h: float = math.nan
    last_image: np.ndarray | None = None
    phase: np.ndarray | None = None
    ring_d: np.ndarray | None = None  # (W, n_r, n_x) float32, oldest first; ring_n valid (the last ones)
    ring_t: np.ndarray | None = None
    ring_n: int = 0
    sum_amp: np.ndarray | None = None
    sum_amp2: np.ndarray | None = None
    sum_coh: np.ndarray | None = None
    sum_cos: np.ndarray | None = None  # sum over increments of cos(the unexplained part r)
    n_coh: int = 0
    displacement: np.ndarray | None = None
    velocity: np.ndarray | None = None
    acceleration: np.ndarray | None = None
    coherence: np.ndarray | None = None
    selected: np.ndarray | None = None  # uint8: 0, PS, DS
    stable: np.ndarray | None = None  # bool
    aps: np.ndarray | None = None  # float32 mm
    areas: list[AreaState] = field(default_factory=list)
    chart: Chart | None = None
    recent_events: list[dict[str, Any]] = field(default_factory=list)
    last_record: dict[str, Any] = field(default_factory=dict)
    last_accepted_record: dict[str, Any] = field(default_factory=dict)
    alarms_csv_bytes: int = 0


@dataclass
class Outcome:
    """A scan's result: its record (the ``--json`` line), maps for its epoch file (accepted scans) and
    the alarm events it raised."""

    record: dict[str, Any]
    maps: dict[str, np.ndarray] | None
    events: list[dict[str, Any]]


def chart_names(cfg: MonitorConfig) -> list[str]:
    names = ["aps_residual_mm", "raw_stable_rms_mm", "coherence_median", "aps_refractivity_ppm",
             "meteo_refractivity_ppm"]
    names += [f"d:{w.name}" for w in cfg.watch]
    for a in cfg.areas:
        names += [f"d:{a.name}", f"v:{a.name}"]
    return names


def new_state(cfg: MonitorConfig) -> State:
    return State(areas=[AreaState() for _ in cfg.areas], chart=Chart(chart_names(cfg)))


def _median(x: np.ndarray) -> float:
    return float(np.median(x)) if x.size else math.nan


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x, dtype=np.float64)))) if x.size else math.nan


#: the percentile of |v| over the measured points reported as ``velocity_p95_mm_per_h``
VELOCITY_PERCENTILE = 95.0


def _f(x: float) -> float | None:
    return float(x) if x is not None and math.isfinite(x) else None


def base_record(index: int, time_posix: float, status: str, reason: str = "") -> dict[str, Any]:
    return {"scan": index, "time_utc": utc(time_posix), "status": status, "reason": reason or None}


def reject(state: State, index: int, time_posix: float, reason: str, failed: bool = False) -> Outcome:
    """Record a scan that is not used (``failed``: not acquired completely; else rejected by a check)."""
    rec = {**base_record(index, time_posix, "failed" if failed else "rejected", reason), "n_points": 0,
           "aps_residual_mm": None, "max_velocity_mm_per_h": None, "velocity_p95_mm_per_h": None,
           "alarm_velocity_mm_per_h": None, "alarm_level": state.last_accepted_record.get("alarm_level", "none"),
           "displacement_mm": {}}
    state.last_scan = index
    if failed:
        state.n_failed += 1
    else:
        state.n_rejected += 1
    state.last_record = rec
    return Outcome(rec, None, [])


def _selection(cfg: MonitorConfig, st: Static, s: State, n_amp: int) -> np.ndarray:
    sel = cfg.selection
    mean = s.sum_amp / n_amp
    var = np.maximum(s.sum_amp2 / n_amp - mean * mean, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        da = np.where(mean > 0, np.sqrt(var) / mean, np.inf)
    top = float(np.max(mean[st.support])) if st.support.any() else 0.0
    bright = st.support & (mean > 0) & (mean >= top * 10 ** (-sel.dynamic_range_db / 20))
    ps = bright & (n_amp >= sel.min_scans_dispersion) & (da <= sel.amplitude_dispersion)
    mean_coh = s.sum_coh / s.n_coh if s.n_coh else np.zeros(st.shape)
    ds = bright & ~ps & (mean_coh >= sel.coherence)
    if s.n_coh:
        steady = s.sum_cos / s.n_coh >= sel.increment_coherence
        ps, ds = ps & steady, ds & steady
    out = np.zeros(st.shape, np.uint8)
    out[ps], out[ds] = PS, DS
    return out


def _stable(cfg: MonitorConfig, st: Static, s: State, selected: np.ndarray) -> np.ndarray:
    measured = selected > 0
    user = [i for i, a in enumerate(cfg.areas) if a.stable]
    if user:
        return measured & np.logical_or.reduce([st.areas[i] for i in user])
    mean_coh = s.sum_coh / s.n_coh if s.n_coh else np.zeros(st.shape)
    out = measured & (mean_coh >= cfg.aps.stable_coherence)
    if s.ring_n >= 2 and s.velocity is not None:
        out &= np.abs(s.velocity) <= cfg.aps.stable_velocity_mm_per_h
    return out


def _forecast(cfg: MonitorConfig, st: Static, ast: AreaState, t_h: float) -> dict[str, Any] | None:
    """The inverse-velocity forecast of an area when its acceleration persists (ForecastSection); a
    negative ``time_to_failure_h`` means the line has already reached zero: failure is imminent."""
    fc = cfg.forecast
    v = np.array(ast.run_v)
    if v.size < fc.window_scans or not np.all(np.isfinite(v)) or not np.all(v >= fc.min_velocity_mm_per_h):
        return None
    res = inverse_velocity_forecast(np.array(ast.run_t), v)
    if res is None or res[2] < fc.min_r2:
        return None
    return {"failure_utc": utc(st.t_ref + res[0] * 3600), "failure_h": res[0], "time_to_failure_h": res[0] - t_h,
            "r2": res[2], "n_samples": int(v.size)}


def first_scan(cfg: MonitorConfig, st: Static, image: np.ndarray, index: int, time_posix: float,
               meteo: dict[str, float] | None) -> tuple[State, Outcome]:
    """The state after the campaign's first (reference) scan: displacement 0 everywhere."""
    s = new_state(cfg)
    w = max(cfg.velocity.window_scans, cfg.velocity.acceleration_window_scans, cfg.forecast.velocity_window_scans)
    amp = np.where(st.support, np.abs(image), 0.0)
    zero = np.zeros(st.shape, np.float32)
    s.last_image = np.asarray(image, np.complex64)
    s.phase = np.zeros(st.shape, np.float64)
    s.ring_d, s.ring_t, s.ring_n = np.zeros((w, *st.shape), np.float32), np.zeros(w), 1
    s.sum_amp, s.sum_amp2 = amp.astype(np.float64), (amp * amp).astype(np.float64)
    s.sum_coh, s.sum_cos, s.n_coh = np.zeros(st.shape), np.zeros(st.shape), 0
    s.displacement = np.where(st.support, zero, np.nan).astype(np.float32)
    s.velocity, s.acceleration = zero.copy(), zero.copy()
    s.coherence = np.full(st.shape, np.nan, np.float32)
    s.selected, s.stable = np.zeros(st.shape, np.uint8), np.zeros(st.shape, bool)
    s.aps = zero.copy()
    s.last_time_h = 0.0
    s.n_accepted, s.last_scan = 1, index
    rec = {**base_record(index, time_posix, "accepted"), "n_points": 0, "n_stable": 0,
           "aps_residual_mm": None, "raw_stable_rms_mm": None, "aps_refractivity_ppm": None, "aps_model": "none",
           "max_velocity_mm_per_h": None, "velocity_p95_mm_per_h": None, "alarm_velocity_mm_per_h": None,
           "alarm_level": "none", "alarm_area": None,
           "displacement_mm": {w.name: 0.0 for w in cfg.watch}, "velocity_mm_per_h": {w.name: None for w in cfg.watch},
           "areas": {a.name: {"level": "none", "n_points": 0, "displacement_mm": None, "velocity_mm_per_h": None,
                              "acceleration_mm_per_h2": None, "forecast": None} for a in cfg.areas},
           "unwrapping": "reference",
           "implausible_fraction": 0.0, "coherence_median": None, "time_h": 0.0, "meteo": meteo}
    s.chart.append(0.0, {"meteo_refractivity_ppm": (meteo or {}).get("refractivity_ppm", math.nan),
                         **{f"d:{w.name}": 0.0 for w in cfg.watch}})
    s.last_record = s.last_accepted_record = rec
    return s, Outcome(rec, _maps(s), [])


def _maps(s: State) -> dict[str, np.ndarray]:
    return {"displacement_mm": s.displacement, "velocity_mm_per_h": s.velocity,
            "acceleration_mm_per_h2": s.acceleration, "coherence": s.coherence, "selected": s.selected,
            "stable": s.stable.astype(np.uint8), "aps_mm": s.aps}


def update(cfg: MonitorConfig, st: Static, s: State, image: np.ndarray, index: int, time_posix: float,
           meteo: dict[str, float] | None) -> tuple[State, Outcome]:
    """Advance the state by scan ``index`` (module docstring). ``s`` is not modified: a rejected scan
    leaves every map as it was."""
    lam = st.wavelength_m
    t_h = (time_posix - st.t_ref) / 3600.0
    dt_h = t_h - s.last_time_h
    new = State(**{k: getattr(s, k) for k in s.__dataclass_fields__})
    new.areas = [AreaState(AlarmState(a.alarm.level, a.alarm.below), list(a.run_t), list(a.run_v)) for a in s.areas]
    new.chart = Chart(list(s.chart.names), s.chart.t.copy(), s.chart.values.copy())
    new.recent_events = list(s.recent_events)
    if not dt_h > 0:
        return new, reject(new, index, time_posix, f"scan time {utc(time_posix)} is not after the previous scan's")
    z = np.asarray(image, np.complex64)
    valid = st.support & (z != 0) & (s.last_image != 0)
    w = np.angle(z * np.conj(s.last_image)).astype(np.float64)
    gamma = np.where(valid, coherence(s.last_image, z, cfg.processing.coherence_window), np.nan).astype(np.float32)
    measured_prev = (s.selected > 0) & valid
    coh_med = _median(gamma[measured_prev])
    if coh_med < cfg.unwrap.min_scan_coherence:
        return new, reject(new, index, time_posix, f"decorrelated: median coherence of the points {coh_med:.2f} "
                                                   f"< {cfg.unwrap.min_scan_coherence:g}")
    rng_map = st.slant_range()
    has_dz = st.dz is not None
    dz = st.dz if has_dz else None
    stab_prev = s.stable & valid & (np.isfinite(dz) if has_dz else True)
    kind = aps_mod.choose_kind(int(stab_prev.sum()), cfg.aps.min_stable_points, has_dz)
    inc = aps_mod.fit_wrapped(w[stab_prev], rng_map[stab_prev], dz[stab_prev] if has_dz else None, kind, lam,
                              cfg.aps.huber_k)
    dz0 = np.nan_to_num(dz) if has_dz else None
    pred = inc.evaluate(rng_map, dz0) - np.where(measured_prev, 4 * np.pi * s.velocity * 1e-3 * dt_h / lam, 0.0)
    reliable = measured_prev & (gamma >= cfg.unwrap.reliable_coherence)
    max_jump = 4 * np.pi * cfg.unwrap.max_velocity_mm_per_h * 1e-3 * dt_h / lam
    res = unwrap_increment(w, pred, reliable, stab_prev, valid, cfg.unwrap.max_implausible_fraction,
                           cfg.unwrap.spatial, max_jump)
    if not res.accepted:
        return new, reject(new, index, time_posix, res.reason)
    # accepted: every map advances
    amp = np.where(st.support, np.abs(z), 0.0)
    new.phase = s.phase + np.where(valid, res.delta, 0.0)
    new.last_image = z
    new.sum_amp, new.sum_amp2 = s.sum_amp + amp, s.sum_amp2 + amp * amp
    new.sum_coh, new.n_coh = s.sum_coh + np.nan_to_num(gamma), s.n_coh + 1
    new.sum_cos = s.sum_cos + np.where(valid, np.cos(res.delta - pred), 0.0)
    new.n_accepted, new.last_scan, new.last_time_h = s.n_accepted + 1, index, t_h
    new.selected = _selection(cfg, st, new, new.n_accepted)
    new.stable = _stable(cfg, st, new, new.selected) & st.support & (np.isfinite(dz) if has_dz else True)
    kind = aps_mod.choose_kind(int(new.stable.sum()), cfg.aps.min_stable_points, has_dz)
    model = aps_mod.fit(new.phase[new.stable], rng_map[new.stable], dz[new.stable] if has_dz else None, kind,
                        cfg.aps.huber_k)
    aps_phase = model.evaluate(rng_map, dz0)
    mm = -lam / (4 * np.pi) * 1e3
    new.aps = (mm * aps_phase).astype(np.float32)
    new.displacement = np.where(st.support, mm * (new.phase - aps_phase), np.nan).astype(np.float32)
    residual = _rms(new.displacement[new.stable])
    raw = _rms(mm * (new.phase[new.stable] - _median(new.phase[new.stable])))
    # velocity and acceleration over the last scans
    ring_d = np.concatenate([s.ring_d[1:], new.displacement[None]])
    ring_t = np.r_[s.ring_t[1:], t_h]
    new.ring_d, new.ring_t, new.ring_n = ring_d, ring_t, min(s.ring_n + 1, ring_d.shape[0])
    nv = min(new.ring_n, cfg.velocity.window_scans)
    na = cfg.velocity.acceleration_window_scans
    new.velocity = weighted_sum(slope_weights(ring_t[-nv:]), ring_d[-nv:])
    new.acceleration = (weighted_sum(acceleration_weights(ring_t[-na:]), ring_d[-na:]) if new.ring_n >= na
                        else np.zeros(st.shape, np.float32))
    new.coherence = gamma
    measured = new.selected > 0
    # areas, alarms, forecast
    events: list[dict[str, Any]] = []
    areas_out: dict[str, Any] = {}
    top, top_area = 0, None
    for i, area in enumerate(cfg.areas):
        pts = measured & st.areas[i]
        d_a = _median(new.displacement[pts])
        a_a = _median(new.acceleration[pts]) if new.ring_n >= na else math.nan
        v_a = _median(new.velocity[pts]) if new.ring_n >= cfg.velocity.window_scans else math.nan
        if math.isfinite(a_a):  # from the window's mean time to the scan's
            v_a += a_a * (t_h - float(np.mean(ring_t[-nv:])))
        ast = new.areas[i]
        nf = min(new.ring_n, cfg.forecast.velocity_window_scans)
        v_f = _median(weighted_sum(slope_weights(ring_t[-nf:]), ring_d[-nf:, pts])) if nf >= 2 else math.nan
        ast.run_t = (ast.run_t + [float(np.mean(ring_t[-nf:]))])[-cfg.forecast.window_scans:]
        ast.run_v = (ast.run_v + [abs(v_f)])[-cfg.forecast.window_scans:]
        forecast = _forecast(cfg, st, ast, t_h)
        ast.alarm, ev = step(ast.alarm, area, v_a, a_a)
        if ev is not None:
            ev = {"time_utc": utc(time_posix), "scan": index, "area": area.name, **ev, "velocity_mm_per_h": v_a,
                  "acceleration_mm_per_h2": a_a,
                  "forecast_failure_utc": forecast["failure_utc"] if forecast else None}
            events.append(ev)
        if ast.alarm.level > top:
            top, top_area = ast.alarm.level, area.name
        areas_out[area.name] = {"level": LEVELS[ast.alarm.level], "n_points": int(pts.sum()),
                                "displacement_mm": _f(d_a), "velocity_mm_per_h": _f(v_a),
                                "acceleration_mm_per_h2": _f(a_a), "forecast": forecast}
    new.recent_events = (new.recent_events + events)[-RECENT_EVENTS:]
    watch_d = {w.name: _f(float(new.displacement[r, c])) for w, (r, c) in zip(cfg.watch, st.watch, strict=True)}
    watch_v = {w.name: _f(float(new.velocity[r, c])) for w, (r, c) in zip(cfg.watch, st.watch, strict=True)}
    vel_pts = np.abs(new.velocity[measured])
    # robust statistics: one noisy pixel sets the maximum, not the 95th percentile (which needs
    # 5 % of the points) nor the areas' medians, which the alarms compare with their thresholds
    area_v = [abs(a["velocity_mm_per_h"]) for a in areas_out.values() if a["velocity_mm_per_h"] is not None]
    rec = {**base_record(index, time_posix, "accepted"), "n_points": int(measured.sum()),
           "n_stable": int(new.stable.sum()), "aps_residual_mm": _f(residual), "raw_stable_rms_mm": _f(raw),
           "aps_refractivity_ppm": _f(model.refractivity_ppm(lam)) if kind in ("range", "range-height") else None,
           "aps_model": kind, "max_velocity_mm_per_h": _f(float(vel_pts.max())) if vel_pts.size else None,
           "velocity_p95_mm_per_h": _f(float(np.percentile(vel_pts, VELOCITY_PERCENTILE))) if vel_pts.size else None,
           "alarm_velocity_mm_per_h": _f(max(area_v)) if area_v else None,
           "alarm_level": LEVELS[top], "alarm_area": top_area, "displacement_mm": watch_d,
           "velocity_mm_per_h": watch_v, "areas": areas_out, "unwrapping": res.method,
           "implausible_fraction": res.implausible_fraction, "coherence_median": _f(coh_med), "time_h": t_h,
           "meteo": meteo}
    row = {"aps_residual_mm": residual, "raw_stable_rms_mm": raw, "coherence_median": coh_med,
           "aps_refractivity_ppm": rec["aps_refractivity_ppm"] if rec["aps_refractivity_ppm"] is not None else math.nan,
           "meteo_refractivity_ppm": (meteo or {}).get("refractivity_ppm", math.nan)}
    row.update({f"d:{k}": (v if v is not None else math.nan) for k, v in watch_d.items()})
    for name, a in areas_out.items():
        row[f"d:{name}"] = a["displacement_mm"] if a["displacement_mm"] is not None else math.nan
        row[f"v:{name}"] = a["velocity_mm_per_h"] if a["velocity_mm_per_h"] is not None else math.nan
    new.chart.append(t_h, row)
    new.last_record = new.last_accepted_record = rec
    return new, Outcome(rec, _maps(new), events)
