"""``gbsar_polarimetry``: an image (or scan) with HH and VV -> the polarimetric normalized difference
``(|HH|^2 - |VV|^2)/(|HH|^2 + |VV|^2)`` ([LeeGBSAR-I-2007, §3.1]) as a UTM GeoTIFF and / or a slant-plane PNG.

NaN outside the beam footprint (no support in HH or VV).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.errors import ConfigError
from sarcli.gbsar.interferometry import support
from sarcli.gbsar.polarimetry import normalized_difference
from sarcli.workflows.base import Progress, Report, using
from sarcli.workflows.gbsar_common import guard, load_image, map_outputs


@dataclass(frozen=True)
class Config:
    """image: image or scan product; ``window``: boxcar (pixels) of the powers; GeoTIFF pixel (m)."""

    image: Path
    geotiff: Path | None = None
    png: Path | None = None
    window: int = 3
    map_pixel_m: float | None = None

    def __post_init__(self) -> None:
        if self.window < 1:
            raise ConfigError(f"the polarimetric window (--window) must be >= 1 pixel, got {self.window}")


@dataclass
class GbsarPolarimetryReport(Report):
    mean: float
    fraction_hh_dominant: float
    outputs: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable({"mean": self.mean, "fraction_hh_dominant": self.fraction_hh_dominant, **self.outputs})

    def lines(self) -> list[str]:
        return [f"normalized difference: mean {self.mean:.3f}"]


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarPolarimetryReport:
    with using(provenance):
        guard([config.image], [config.geotiff, config.png])
        img = load_image(config.image)
        nd = normalized_difference(img.pol("HH"), img.pol("VV"), config.window)
        nd[~(support(img, "HH") & support(img, "VV"))] = np.nan  # blank outside the beam footprint
        outputs = map_outputs(nd, img, config.geotiff, config.png, "(HH-VV)/(HH+VV)",
                              "normalized difference (HH-VV)/(HH+VV) of the intensities", "RdBu_r", -1.0, 1.0,
                              config.map_pixel_m, unit="1", inputs=(config.image,))
        return GbsarPolarimetryReport(mean=float(np.nanmean(nd)), fraction_hh_dominant=float(np.nanmean(nd > 0)),
                                      outputs=outputs)
