"""``gbsar_interfere``: two GB-SAR images (or scans) -> interferogram product (+ GeoTIFFs and PNGs).

``B * conj(A)`` with the model phase of ``mode`` removed and converted ([LeeGBSAR-I-2007, §3.2-3.5]; see
:mod:`sarcli.gbsar.interferometry`): dinsar -> LOS displacement (mm), crosstrack / combined -> height
(m), deltaf -> range offset (m). A scan is focused with ``auto`` first, the secondary on the
reference's grid. Pixels outside the common support are NaN; the converted value is also NaN where
the coherence is below ``min_coherence``.
"""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sarcli.errors import ConfigError
from sarcli.gbsar.interferometry import MODES, interfere
from sarcli.io.interferogram import write_interferogram
from sarcli.workflows.base import Progress, Report, using
from sarcli.workflows.gbsar_common import guard, is_scan, load_image, map_outputs, parameters

_log = logging.getLogger(__name__)
#: the stages of an interferogram, in order (``timings_s`` keys, progress steps)
STAGES = ("reference", "secondary", "interferogram", "product", "pictures")


@dataclass(frozen=True)
class Config:
    """The ``sarcli gbsar interfere`` options: reference A, secondary B, output; ``pol`` default: A's
    first; ``window``: coherence boxcar (pixels); ``ground_height_m``: the model's surface height;
    GeoTIFF / PNG outputs of the residual phase (PNG: hue = phase, brightness = coherence), of the
    converted value (from the unwrapped residual) and of the coherence."""

    reference: Path
    secondary: Path
    output: Path
    mode: Literal["dinsar", "crosstrack", "deltaf", "combined"] = "dinsar"
    pol: str | None = None
    window: int = 5
    ground_height_m: float = 0.0
    min_coherence: float = 0.5
    geotiff: Path | None = None
    png: Path | None = None
    value_png: Path | None = None
    value_geotiff: Path | None = None
    coherence_png: Path | None = None
    coherence_geotiff: Path | None = None
    map_pixel_m: float | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ConfigError(f"unknown interferometric mode '{self.mode}' (use {', '.join(MODES)})")
        if self.window < 1:
            raise ConfigError(f"the coherence window (--window) must be >= 1 pixel, got {self.window}")
        if not 0.0 <= self.min_coherence <= 1.0:
            raise ConfigError(f"the minimum coherence must be in [0, 1], not {self.min_coherence:g}")


@dataclass
class GbsarInterfereReport(Report):
    output: str
    attrs: dict[str, Any]
    value: str
    unit: str
    rate: dict[str, float]
    mean_coherence: float | None
    supported_pixels: int
    valid_value_pixels: int
    outputs: dict[str, Any] = field(default_factory=dict)
    timings_s: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable({"output": self.output, **self.attrs, "value": self.value, "unit": self.unit,
                            "rate": self.rate, "mean_coherence": self.mean_coherence,
                            "supported_pixels": self.supported_pixels, "valid_value_pixels": self.valid_value_pixels,
                            **self.outputs, "timings_s": self.timings_s})

    def lines(self) -> list[str]:
        return [f"wrote {self.output}: {self.attrs['mode']}, mean coherence {self.mean_coherence or 0:.3f} over "
                f"{self.supported_pixels} supported pixels, value {self.value} ({self.unit}) on "
                f"{self.valid_value_pixels} with coherence >= {self.attrs['min_coherence']:g}"
                + (f", in {self.timings_s['total_s']:.1f} s" if self.timings_s else "")]


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarInterfereReport:
    """Interfere ``config.secondary`` against ``config.reference``; write the product and pictures."""
    c = config
    t_start = time.perf_counter()
    timings: dict[str, float] = {}
    clock = [t_start]

    def done(stage: str, what: str) -> None:
        now = time.perf_counter()
        timings[f"{stage}_s"] = now - clock[0]
        clock[0] = now
        _log.info("%s in %.2f s", what, timings[f"{stage}_s"])
        if progress is not None:
            progress("interfere", STAGES.index(stage) + 1, len(STAGES))

    with using(provenance):
        guard([c.reference, c.secondary], [c.output, c.geotiff, c.png, c.value_png, c.value_geotiff, c.coherence_png,
                                           c.coherence_geotiff])
        a = load_image(c.reference)
        done("reference", f"{'focused the reference scan' if is_scan(c.reference) else 'read the reference'} "
                          f"{c.reference}")
        b = load_image(c.secondary, like=a)
        done("secondary", f"{'focused the secondary scan' if is_scan(c.secondary) else 'read the secondary'} "
                          f"{c.secondary}")
        pol = (c.pol or a.polarizations[0]).upper()
        ifg = interfere(a, b, c.mode, pol, c.window, c.ground_height_m, c.min_coherence)
        done("interferogram", f"{c.mode} interferogram and coherence")
        attrs = {"mode": c.mode, "pol": pol, "coherence_window": c.window, "ground_height_m": c.ground_height_m,
                 "min_coherence": c.min_coherence,
                 "rail_height_a_m": a.rail_height_m, "rail_height_b_m": b.rail_height_m,
                 "center_frequency_a_hz": a.center_frequency_hz, "center_frequency_b_hz": b.center_frequency_hz,
                 "epoch_utc": a.epoch_utc}
        inputs = (c.reference, c.secondary)
        write_interferogram(c.output, ifg, a.range_m, a.azimuth_m, attrs, parameters=parameters(c), inputs=inputs)
        done("product", f"wrote {c.output}")
        n_valid = int(np.count_nonzero(np.isfinite(ifg.value)))
        outputs = map_outputs(ifg.residual, a, c.geotiff, c.png, f"{c.mode} residual phase ({pol})",
                              "residual interferometric phase, wrapped", "twilight", -np.pi, np.pi, c.map_pixel_m,
                              unit="rad", overview="phase", inputs=inputs, brightness=ifg.coherence,
                              brightness_label=f"coherence ({c.window} x {c.window})")
        if c.value_png is not None or c.value_geotiff is not None:
            v = ifg.value[np.isfinite(ifg.value)]
            lo, hi = (np.percentile(v, [2, 98]) if v.size else (0.0, 1.0))
            lo, hi = (float(lo), float(hi)) if hi > lo else (float(lo) - 1.0, float(lo) + 1.0)
            title = f"{c.mode} {ifg.value_name}, unwrapped (coherence >= {c.min_coherence:g})"
            outputs["value_outputs"] = map_outputs(ifg.value, a, c.value_geotiff, c.value_png, title,
                                                   f"{ifg.value_name} ({ifg.value_unit})",
                                                   "RdBu_r" if c.mode == "dinsar" else "viridis", lo, hi,
                                                   c.map_pixel_m, unit=ifg.value_unit, inputs=inputs)
        if c.coherence_png is not None or c.coherence_geotiff is not None:
            outputs["coherence_outputs"] = map_outputs(ifg.coherence, a, c.coherence_geotiff, c.coherence_png,
                                                       f"coherence ({pol}, {c.window} x {c.window} boxcar)",
                                                       "coherence", "gray", 0.0, 1.0, c.map_pixel_m, unit="1",
                                                       inputs=inputs)
        done("pictures", "pictures and GeoTIFFs")
        timings["total_s"] = time.perf_counter() - t_start
        if not n_valid:
            warnings.warn(f"no pixel has both images' support and coherence >= {c.min_coherence:g}: the value is "
                          "all NaN", stacklevel=2)
        return GbsarInterfereReport(
            output=str(c.output), attrs=attrs, value=ifg.value_name, unit=ifg.value_unit, rate=ifg.rate,
            mean_coherence=float(np.nanmean(ifg.coherence)) if ifg.support.any() else None,
            supported_pixels=int(np.count_nonzero(ifg.support)), valid_value_pixels=n_valid, outputs=outputs,
            timings_s=timings)
