"""Quality workflow: point-target metrics of an SLC product (IRW, PSLR, ISLR, position error).

The targets are given (zero-Doppler time s, slant range m) or, for a simulated product, taken from
its truth: ``quality`` is the one place besides the simulator that reads the truth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError, ProductError
from sarcli.workflows.base import Progress, Provenance, Report, refuse_overwriting_inputs, using


@dataclass(frozen=True)
class Config:
    """slc: the focused image (a sarcli SLC, or a NISAR RSLC: ``frequency``/``polarization`` choose its
    layer); at: targets as (zero-Doppler time s, slant range m); empty: the truth's; plot: a PNG of the
    targets' impulse responses (range and azimuth cuts, 2-D contours)."""

    slc: Path
    at: tuple[tuple[float, float], ...] = ()
    frequency: str | None = None
    polarization: str | None = None
    plot: Path | None = None

    def __post_init__(self) -> None:
        for t, r in self.at:
            if not (math.isfinite(t) and math.isfinite(r)):
                raise ConfigError(f"--at {t},{r}: the time and range must be finite numbers")


@dataclass
class QualityReport(Report):
    """One dict per target (metres, dB; ``position_error_*`` against the truth)."""

    targets: list[dict[str, Any]] = field(default_factory=list)
    plot: str | None = None

    def lines(self) -> list[str]:
        out = []
        for i, m in enumerate(self.targets):
            err = f", position error {m['position_error_m']:.3f} m" if "position_error_m" in m else ""
            out.append(f"target {i}: t {m['azimuth_time_s']:.6f} s, R {m['range_m']:.2f} m; IRW rg "
                       f"{m['irw_range_m']:.2f} m, az {m['irw_azimuth_m']:.2f} m; PSLR rg {m['pslr_range_db']:.2f} dB, "
                       f"az {m['pslr_azimuth_db']:.2f} dB; ISLR rg {m['islr_range_db']:.2f} dB, az "
                       f"{m['islr_azimuth_db']:.2f} dB{err}")
        if self.plot is not None:
            out.append(f"wrote {self.plot}")
        return out


def run(config: Config, provenance: Provenance | None = None, progress: Progress | None = None) -> QualityReport:
    """Measure the targets of ``config`` in the SLC (reads only)."""
    from sarcli.focus.quality import measure_targets, truth_targets
    from sarcli.io.nisar.rslc import read_image

    refuse_overwriting_inputs([config.slc], [config.plot] if config.plot is not None else [])
    with using(provenance):
        slc = read_image(config.slc, config.frequency, config.polarization)
        if slc.azimuth_time.size < 2 or slc.slant_range.size < 2:
            raise ProductError(f"{config.slc}: image too small to measure")
        positions = list(config.at) if config.at else truth_targets(slc.truth)
        if not positions:
            raise ConfigError(f"{config.slc}: no truth targets in the product; give positions with "
                              "--at TIME_S,RANGE_M")
        targets = measure_targets(slc, positions, truth_known=not config.at)
        if config.plot is not None:
            from sarcli.calibration.plots import plot_point_targets
            from sarcli.focus.quality import azimuth_ground_spacing

            plot_point_targets(config.plot, slc.image, targets, float(slc.slant_range[1] - slc.slant_range[0]),
                               azimuth_ground_spacing(slc), title=f"{Path(config.slc).name}: point-target "
                               "impulse responses (ground along-track, slant range)")
        return QualityReport(targets, None if config.plot is None else str(config.plot))
