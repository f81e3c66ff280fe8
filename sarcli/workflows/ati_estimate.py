"""Workflow ``ati_estimate``: detect movers, then estimate vx, vy, x0, y0 (and R0) of each, with 1-sigma
uncertainties (sub-image cut, inverse azimuth compression, range bin, phase unwrapping, weighted LS fit
with covariance, then the chosen route; ``sarcli.ati``). Positions x0, y0 are relative to the platform
at the reference time t_ref (scene centre); x_local_m, y_local_m are in the LOCAL frame.

Shared with ``ati_compensate``: :class:`EstimationOptions` and :func:`estimate_movers`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.workflows import base
from sarcli.workflows.ati_detect import cfar_knobs, check_pfa, load_two_channel, write_product


def check_choices(**values: str) -> None:
    """Refuse an unknown route, unwrap, bin or method value before any heavy work."""
    from sarcli.ati.estimate import ROUTES
    from sarcli.ati.pipeline import BIN_MODES, COMPENSATIONS
    from sarcli.ati.unwrap import METHODS

    allowed = {"route": ROUTES, "unwrap": METHODS, "bin": BIN_MODES, "method": COMPENSATIONS}
    for name, v in values.items():
        if v not in allowed[name]:
            raise ConfigError(f"{name} {v!r}: choose one of {', '.join(allowed[name])}")


@dataclass(frozen=True)
class Config:
    """raw: two-channel raw product; output: write an ATI product with the movers table; route: exact
    (closed-form geometry), nonlinear (full fit of the exact histories) or seed (the chain of [Ryu2017]);
    unwrap: dechirp (model-guided) or itoh; bin: track (per-line peak near the ANV bin) or anv (one bin);
    pfa: false-alarm probability per pixel of each CFAR test."""

    raw: Path
    output: Path | None = None
    route: str = "exact"
    unwrap: str = "dechirp"
    bin: str = "track"
    pfa: float = 1e-6

    def __post_init__(self) -> None:
        check_choices(route=self.route, unwrap=self.unwrap, bin=self.bin)
        check_pfa(self.pfa)


def mover_line(d: dict[str, Any]) -> str:
    flags = [k for k in ("ati_ambiguous", "vy_degenerate") if d[k]]
    return (f"mover {d['id']}: vx {d['vx_mps']:+.3f} +- {d['vx_mps_sigma']:.3f} m/s, vy {d['vy_mps']:+.3f} +- "
            f"{d['vy_mps_sigma']:.3f} m/s, x0 {d['x0_m']:.2f} +- {d['x0_m_sigma']:.2f} m, y0 {d['y0_m']:.2f} +- "
            f"{d['y0_m_sigma']:.2f} m, R0 {d['r0_m']:.2f} m" + (f" [{', '.join(flags)}]" if flags else ""))


def failure_lines(summary: dict[str, Any]) -> list[str]:
    return [f"mover {f['id']}: estimation failed: {f['error']}" for f in summary["estimation_failures"]]


@dataclass
class Report(base.Report):
    """movers: one dict per estimated mover (``--json`` prints this list); summary: the detection summary
    with ``estimation_failures``."""

    movers: list[dict[str, Any]]
    summary: dict[str, Any]
    output: str | None = None

    def lines(self) -> list[str]:
        return (failure_lines(self.summary) + [mover_line(d) for d in self.movers]
                + ([f"wrote {self.output}"] if self.output else []))


def estimate_movers(raw_path: Path, route: str, unwrap: str, bin_mode: str, pfa: float) -> tuple[Any, Any, dict, list]:
    """(raw, pair, summary, results): load, focus, detect and estimate every candidate."""
    from sarcli.ati.pipeline import process

    raw = load_two_channel(raw_path)
    pair, summary, results = process(raw, route, unwrap, bin_mode, cfar_knobs(pfa))
    return raw, pair, summary, results


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Detect and estimate (module docstring)."""
    with base.using(provenance):
        base.refuse_overwriting_inputs([config.raw], [config.output])
        _, pair, summary, results = estimate_movers(config.raw, config.route, config.unwrap, config.bin, config.pfa)
        movers = [r.as_dict() for r in results]
        if config.output is not None:
            write_product(config.output, config.raw, pair, summary, movers, "ati_estimate", config)
        return Report(movers, summary, None if config.output is None else str(config.output))
