"""Workflow ``orbit_interpolate``: Hermite-interpolate a raw product's state vectors at given times.

Positions, velocities and accelerations (SI) in the requested frame, in ECEF also the geodetic latitude,
longitude and height (WGS-84). Times outside the state-vector span are refused unless ``extrapolate``
allows them (then a warning names them). ``csv`` also writes the table (atomically).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.workflows import base
from sarcli.workflows.orbit_info import state_vectors

FRAMES = ("native", "eci", "ecef")
MAX_TIMES = 10_000_000


@dataclass(frozen=True)
class Config:
    """raw: raw product with /orbit; times: seconds after the product epoch ('0,10.5', 'start:stop:step')
    and/or ISO-8601 UTC instants, as one string or a list; frame: native (as stored), eci or ecef;
    n_nodes: Hermite nodes (2..16, default from the table); extrapolate: seconds allowed outside the span;
    csv: also write the table here."""

    raw: Path
    times: str | tuple[float | str, ...]
    frame: str = "native"
    n_nodes: int | None = None
    extrapolate: float = 0.0
    csv: Path | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "frame", self.frame.lower())
        if self.frame not in FRAMES:
            raise ConfigError(f"frame must be native, eci or ecef, got {self.frame!r}")
        if not self.extrapolate >= 0:
            raise ConfigError(f"extrapolate must be >= 0 s, got {self.extrapolate}")


def parse_times(spec: str | tuple[float | str, ...], epoch_utc: str) -> list[float]:
    """'0,12.5,30' (seconds after the epoch), ranges 'start:stop:step' (stop included if on the grid) and
    ISO-8601 UTC instants ('2002-06-16T15:41:02.5Z'), mixed freely; a list holds such items."""
    import numpy as np

    from orbit.timeutil import parse_utc

    items = spec.split(",") if isinstance(spec, str) else [str(x) for x in spec]
    out: list[float] = []
    for item in (s.strip() for s in items):
        if not item:
            continue
        try:
            if "T" in item:
                out.append((parse_utc(item) - parse_utc(epoch_utc)).total_seconds())
            elif ":" in item:
                a, b, c = (float(x) for x in item.split(":"))
                if c <= 0 or b < a:
                    raise ValueError
                n = int(np.floor((b - a) / c + 1e-9)) + 1
                if n > MAX_TIMES:
                    raise ConfigError(f"times: range {item!r} has {n} points (max 10 000 000)")
                out.extend((a + c * np.arange(n)).tolist())
            else:
                out.append(float(item))
        except ValueError:
            raise ConfigError(f"times: cannot read {item!r}; use numbers (s after the epoch), "
                              "start:stop:step with step > 0, or ISO-8601 UTC times") from None
    if not out:
        raise ConfigError("times: no time given")
    return out


@dataclass
class Report(base.Report):
    """The table (``columns``: time_s, x_m .. az_mps2, and lat_deg, lon_deg, h_m in ECEF) and its context."""

    path: str
    frame: str
    epoch_utc: str
    n_nodes: int
    span_s: list[float]
    extrapolated_time_s: list[float]
    utc: list[str] | None
    columns: dict[str, Any]
    csv: str | None

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        d.update(d.pop("columns"))
        d.pop("csv")
        return d

    def lines(self) -> list[str]:
        cols = self.columns
        t = cols["time_s"]
        if self.csv is not None:  # the table is in the file: one summary line, not the rows again
            return [f"wrote {self.csv}: {t.size} row(s), {self.frame}, Hermite N = {self.n_nodes}, "
                    f"t {t.min():.6f}..{t.max():.6f} s, columns {', '.join(cols)}"]
        head = list(cols)
        out = [f"{self.frame}, Hermite N = {self.n_nodes}, {t.size} time(s)", " ".join(f"{h:>16}" for h in head)]
        for i in range(min(t.size, 1000)):
            out.append(" ".join(f"{cols[h][i]:16.6f}" for h in head))
        if t.size > 1000:
            out.append(f"... {t.size - 1000} more rows (use --csv or --json)")
        return out


def _write_csv(path: Path, cols: dict) -> None:
    import numpy as np

    from sarcli.io.atomic import atomic_path

    table = np.column_stack(list(cols.values()))
    with atomic_path(path, ".csv") as tmp:
        np.savetxt(tmp, table, delimiter=",", header=",".join(cols), comments="", fmt="%.10f")


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Interpolate at the requested times (module docstring)."""
    import numpy as np

    from orbit.errors import InterpolationRangeError
    from orbit.geodetic import ecef_to_geodetic
    from orbit.timeutil import add_seconds

    with base.using(provenance):
        base.refuse_overwriting_inputs([config.raw], [config.csv])
        raw, sv = state_vectors(config.raw)
        if config.frame == "ecef":
            sv = sv.to_ecef()
        elif config.frame == "eci":
            sv = sv.to_eci()
        t = np.array(parse_times(config.times, raw.epoch_utc))
        try:
            p, v, a = sv.interpolate(t, config.n_nodes, max_extrapolation_s=config.extrapolate)
        except InterpolationRangeError as e:
            hint = "" if config.extrapolate else " (use --extrapolate SECONDS to allow a bounded extrapolation)"
            raise ConfigError(str(e).split(" (pass ")[0] + hint) from None
        cols = {"time_s": t, "x_m": p[:, 0], "y_m": p[:, 1], "z_m": p[:, 2], "vx_mps": v[:, 0], "vy_mps": v[:, 1],
                "vz_mps": v[:, 2], "ax_mps2": a[:, 0], "ay_mps2": a[:, 1], "az_mps2": a[:, 2]}
        if sv.frame == "ECEF":
            cols["lat_deg"], cols["lon_deg"], cols["h_m"] = ecef_to_geodetic(p)
        t0, t1 = sv.span
        outside = np.flatnonzero((t < t0) | (t > t1))
        if outside.size:
            shown = ", ".join(f"{x:.6f}" for x in t[outside[:8]]) + (", ..." if outside.size > 8 else "")
            warnings.warn(f"extrapolated {outside.size} of {t.size} time(s) beyond the state-vector span "
                          f"[{t0:.6f}, {t1:.6f}] s: {shown}", stacklevel=2)
        if config.csv is not None:
            _write_csv(config.csv, cols)
        return Report(path=str(config.raw), frame=sv.frame, epoch_utc=raw.epoch_utc,
                      n_nodes=sv.default_n_nodes() if config.n_nodes is None else config.n_nodes,
                      span_s=[t0, t1], extrapolated_time_s=t[outside].tolist(),
                      utc=[add_seconds(raw.epoch_utc, x) for x in t] if t.size <= 10000 else None,
                      columns=cols, csv=None if config.csv is None else str(config.csv))
