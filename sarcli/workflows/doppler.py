"""Workflow ``doppler``: raw product -> Doppler centroid (with its ambiguity) and Doppler rate -> doppler.h5.

``[doppler]`` in a TOML file::

    [doppler]
    raw = "raw.h5"
    output = "doppler.h5"          # optional
    plot = "doppler.png"           # optional
    height = 0.0                   # terrain height, m above the WGS-84 ellipsoid
    [doppler.options]              # sarcli.doppler.options.DopplerOptions
    az_block = 512
    estimator = "cde"

The product records this configuration as its ``parameters``. Warnings (an unresolved ambiguity) are
returned in the report, one line each.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from sarcli.config import to_mapping
from sarcli.doppler.options import DopplerOptions
from sarcli.errors import ConfigError
from sarcli.model.doppler_summary import DopplerSummary
from sarcli.workflows.base import Progress, Provenance, Report, refuse_overwriting_inputs, using

#: block-table columns in the JSON report (the product holds all of them)
JSON_BLOCK_KEYS = ("range_m", "azimuth_time_s", "fdc_baseband_hz", "quality", "ambiguity", "fdc_hz", "fr_hz_per_s",
                   "valid", "outlier", "margin_prf")
#: plausible terrain heights above the WGS-84 ellipsoid (Dead Sea shore ~ -410 m, Everest ~ +8820 m)
HEIGHT_RANGE_M = (-1000.0, 9000.0)


@dataclass(frozen=True)
class Config:
    """``raw``: raw product (HDF5); ``output``: doppler.h5 to write (None: none); ``plot``: PNG of fdc and
    fr against range and azimuth (None: none); ``options``: the estimation knobs; the terrain under the
    scene (:func:`sarcli.io.dem.load_terrain`; processing never reads the simulator's truth):
    ``height_m`` (m above the WGS-84 ellipsoid) or a DEM raster ``dem`` whose heights are above the
    ellipsoid or, with ``dem_geoid``, above that geoid."""

    raw: Path
    output: Path | None = None
    plot: Path | None = None
    options: DopplerOptions = field(default_factory=DopplerOptions)
    height_m: float = 0.0
    dem: Path | None = None
    dem_geoid: Literal["egm96", "egm2008"] | None = None

    def __post_init__(self) -> None:
        lo, hi = HEIGHT_RANGE_M
        if not (math.isfinite(self.height_m) and lo <= self.height_m <= hi):
            raise ConfigError(f"terrain height {self.height_m} m is not a height above the WGS-84 ellipsoid in "
                              f"[{lo:.0f}, {hi:.0f}] m")
        if self.dem_geoid is not None and self.dem is None:
            raise ConfigError("a DEM geoid (--dem-geoid) needs a DEM (--dem)")


@dataclass
class DopplerReport(Report):
    """The estimate's summary, its block table, what was written and the warnings."""

    summary: DopplerSummary
    blocks: dict[str, Any]
    output: str | None = None
    plot: str | None = None
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` document: the summary's keys, ``output``, ``warnings`` and ``blocks`` (one
        object per block with :data:`JSON_BLOCK_KEYS`)."""
        from sarcli.io.h5common import to_jsonable

        n = len(self.blocks["range_m"])
        rows = [{k: self.blocks[k][i] for k in JSON_BLOCK_KEYS} for i in range(n)]
        return to_jsonable({**self.summary.to_dict(), "output": self.output, "warnings": self.warnings,
                            "blocks": rows})

    def lines(self) -> list[str]:
        s = self.summary
        out = [f"fdc {s.fdc_hz:.2f} Hz at the scene centre (R = {s.scene_range_m:.0f} m) = baseband "
               f"{s.fdc_baseband_hz:.2f} Hz + ({s.ambiguity}) x PRF "
               f"[{s.ambiguity_source}{'' if s.ambiguity_resolved else ', NOT RESOLVED'}, confidence "
               f"{s.ambiguity_confidence:.3f}, margin {s.ambiguity_margin_prf:.3f} PRF]; fr {s.fr_hz_per_s:.3f} Hz/s "
               f"[{s.fr_method}]; {s.n_valid_blocks}/{s.n_blocks} blocks valid, {s.n_outlier_blocks} flagged"]
        if s.gain_steps:
            out.append(f"undid {len(s.gain_steps)} receiver-gain step(s) found in the echo (line, dB): "
                       + ", ".join(f"{m} {d:+.2f}" for m, d in s.gain_steps))
        out += [f"wrote {p}" for p in (self.output, self.plot) if p is not None]
        return out


def run(config: Config, provenance: Provenance | None = None, progress: Progress | None = None) -> DopplerReport:
    """Estimate the Doppler of ``config.raw`` (``sarcli.doppler.api.estimate_doppler`` over a constant
    terrain height or a DEM), write the product and the plot; ``progress(stage, done, total)``."""
    from sarcli.io.h5common import start_probing

    start_probing()  # the input's metadata probe starts while the estimators are imported
    from sarcli.doppler.api import estimate_doppler
    from sarcli.io.dem import load_terrain
    from sarcli.io.raw import read_raw

    refuse_overwriting_inputs([config.raw, config.dem], [config.output, config.plot])
    with using(provenance):
        raw = read_raw(config.raw)
        terrain = load_terrain(config.height_m, config.dem, config.dem_geoid)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            # the echo is read for the estimate alone: consumed (the plot below only reads the metadata)
            model = estimate_doppler(raw, config.options, terrain=terrain, progress=progress, consume=True)
        assert model.summary is not None  # estimate_doppler always returns one
        if config.output is not None:
            from sarcli.io.doppler_product import write_doppler

            write_doppler(config.output, model, inputs=tuple(p for p in (config.raw, config.dem) if p is not None),
                          parameters=to_mapping(config))
        if config.plot is not None:
            from sarcli.doppler.plot import plot_doppler

            plot_doppler(config.plot, model, raw)  # the plot draws a simulated product's truth beside it
    for w in caught:  # the estimate's own warnings go to the report, any other is passed on
        if not issubclass(w.category, UserWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return DopplerReport(model.summary, model.blocks, None if config.output is None else str(config.output),
                         None if config.plot is None else str(config.plot),
                         [str(w.message) for w in caught if issubclass(w.category, UserWarning)])
