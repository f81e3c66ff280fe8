"""``gbsar_focus``: scan product -> focused image product (+ UTM / ENU GeoTIFFs and a quicklook).

Range compression, then DF, RD, BP, FFBP or ``auto`` (DF beyond the eq. 12 limit, BP or RD nearer); see
:mod:`sarcli.gbsar.focus`. The image lies in the slant plane of the rail (range R0 from the rail line,
azimuth x along it); its phase at a scatterer is ``-4 pi R0/lam`` for every algorithm. Everything
that can be refused is refused before any focusing: an output that is the input, a missing output
folder, an impossible range interval (:func:`sarcli.gbsar.focus.check_range_interval`), an absent
polarization, a rail focusing cannot use (:func:`sarcli.gbsar.rail.ordered`).

With ``grid_m`` (``--grid x0,x1,dx,y0,y1,dy[,z]``) the scan is backprojected onto that horizontal grid
of its own frame instead (x along the rail or the data's local x, y across, z up; for an imported
phase history such as GOTCHA, the scene-centred frame of its antenna positions), which is how scans
with 3-D antenna positions or reference ranges are focused; such an image has no map geometry
(``--geotiff``/``--enu-geotiff`` are refused) and its quicklook has y up. ``permittivity``: waves at
c/sqrt(eps) (a ground-penetrating scan; image range = distance in the medium, e.g. depth).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sarcli.errors import ConfigError
from sarcli.gbsar.focus import FocusOptions, check_range_interval, image_from_scan
from sarcli.gbsar.geocode import resample_to_map
from sarcli.io.gbsar_image import write_gbsar_image
from sarcli.io.images import amplitude_db, write_geotiff, write_quicklook
from sarcli.io.scan import read_scan
from sarcli.model.gbsar import GbsarImage
from sarcli.workflows.base import Progress, Report, using
from sarcli.workflows.gbsar_common import criterion_rad, gbsar_tags, guard, parameters, slant_extent


@dataclass(frozen=True)
class Config:
    """The ``sarcli gbsar focus`` options (SI units; windows are taper specs ``rect | hamming[:a] |
    hann | kaiser[:beta]``, ``none`` = rect). ``pols`` empty: every polarization of the scan."""

    scan: Path
    output: Path
    algorithm: Literal["auto", "df", "rd", "bp", "ffbp"] = "auto"
    pols: tuple[str, ...] = ()
    max_range_m: float | None = None
    min_range_m: float = 0.0
    pixel_x_m: float | None = None
    width_m: float | None = None
    criterion_deg: float = 45.0
    near: Literal["bp", "rd"] = "bp"
    n_xfft: int | None = None
    rd_reference: Literal["sinc", "rect"] = "sinc"
    range_window: str = "hamming"
    azimuth_window: str = "hamming"
    geotiff: Path | None = None
    enu_geotiff: Path | None = None
    map_pixel_m: float | None = None
    ground_height_m: float = 0.0
    quicklook: Path | None = None
    grid_m: tuple[float, ...] | None = None
    permittivity: float = 1.0
    bp_precision: Literal["single", "double"] = "single"
    device: Literal["cpu", "cuda"] = "cpu"

    def __post_init__(self) -> None:
        self.options()  # every option checked when the configuration is made, before any file is opened
        object.__setattr__(self, "pols", tuple(p.upper() for p in self.pols))
        if self.grid_m and (self.geotiff or self.enu_geotiff):
            raise ConfigError("a --grid image lies in the scan's own local frame, which has no map geometry: "
                              "drop --geotiff/--enu-geotiff (use --quicklook)")

    def options(self) -> FocusOptions:
        return FocusOptions(algorithm=self.algorithm, range_window=self.range_window,
                            azimuth_window=self.azimuth_window, max_range_m=self.max_range_m,
                            min_range_m=self.min_range_m, pixel_x_m=self.pixel_x_m, width_m=self.width_m,
                            criterion_rad=criterion_rad(self.criterion_deg), near=self.near, n_xfft=self.n_xfft,
                            rd_reference=self.rd_reference, grid_m=self.grid_m or (), permittivity=self.permittivity,
                            bp_precision=self.bp_precision, device=self.device)


@dataclass
class GbsarFocusReport(Report):
    """``focus``: the focuser's report (algorithms and the ranges they covered, DF limit, skipped stops,
    wall times, GeoTIFF descriptions); the image shape and output path."""

    output: str
    shape: tuple[int, int]
    focus: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.focus)

    def lines(self) -> list[str]:
        g = self.focus.get("grid")
        if g is not None:
            return [f"wrote {self.output}: {self.shape[0]} x {self.shape[1]} pixels, {next(iter(self.focus['used']))} "
                    f"on the grid x "
                    f"{g['x_m'][0]:g}..{g['x_m'][1]:g} m, y {g['y_m'][0]:g}..{g['y_m'][1]:g} m at z {g['z_m']:g} m "
                    f"from {self.focus['n_sweeps']} sweeps ({self.focus['track']} track"
                    f"{', reference ranges' if self.focus['reference_range'] else ''}); "
                    f"{100 * self.focus['full_aperture_fraction']:.0f} % of the pixels seen by every sweep"]
        used = ", ".join(f"{k} {a:.2f}-{b:.2f} m" for k, (a, b) in self.focus["used"].items())
        return [f"wrote {self.output}: {self.shape[0]} x {self.shape[1]} pixels, {used} "
                f"(DF minimum range {self.focus['df_min_range_m']:.2f} m)"]


def image_outputs(img: GbsarImage, config: Config) -> dict[str, Any]:
    """GeoTIFFs (UTM / ENU) and the quicklook of the first polarization's amplitude in dB; pixels
    without signal (not covered by the focusing, or exactly zero) are NaN (nodata), not a dB floor."""
    from sarcli.io.images import Band, Style, db_stretch

    out: dict[str, Any] = {}
    db = amplitude_db(img.image[0], floor_db=None)
    db[img.algorithm_map == 0] = np.nan
    pixel = config.map_pixel_m or (float(img.range_m[1] - img.range_m[0]) if img.range_m.size > 1 else 1.0)
    for path, frame in ((config.geotiff, "utm"), (config.enu_geotiff, "enu")):
        if path is None:
            continue
        raster, transform, crs, ginfo = resample_to_map(db, img.range_m, img.azimuth_m, img.site, img.rail_height_m,
                                                        img.rail_centre_m, pixel, frame, config.ground_height_m)
        out[f"{frame}_geotiff"] = {"path": str(path), "crs": crs, "shape": list(raster.shape), **ginfo}
        lo, hi = db_stretch(raster)
        label = f"{img.polarizations[0]} amplitude 20 log10|z|, nearest slant pixel"
        write_geotiff(path, Band(raster, label, "dB", "power_db"), crs, transform=transform,
                      tags=gbsar_tags(img, (config.output,), MAP_FRAME=frame, GROUND_HEIGHT_M=config.ground_height_m),
                      style=Style(1, lo, hi, "gray", label))
    if config.quicklook is not None and img.grid_z_m is not None:  # rows are y: draw them y up, 1 m = 1 m
        write_quicklook(config.quicklook, img.image[0][::-1],
                        title=f"{img.polarizations[0]} backprojection, z = {img.grid_z_m:g} m",
                        extent=[img.azimuth_m[0], img.azimuth_m[-1], img.range_m[0], img.range_m[-1]],
                        xlabel="x (m)", ylabel="y (m)", aspect="equal")
    elif config.quicklook is not None:
        write_quicklook(config.quicklook, img.image[0], title=f"GB-SAR {img.polarizations[0]} ({img.algorithm})",
                        extent=slant_extent(img), xlabel="azimuth x (m)", ylabel="range R0 (m)", aspect="auto")
    return out


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarFocusReport:
    """Focus ``config.scan`` into ``config.output`` (and the GeoTIFFs / quicklook asked for)."""
    with using(provenance):
        guard([config.scan], [config.output, config.geotiff, config.enu_geotiff, config.quicklook])
        opts = config.options()
        s = read_scan(config.scan)
        check_range_interval(s, opts)
        for p in config.pols:
            s.pol(p)
        img = image_from_scan(s, opts, pols=config.pols or None)
        rep = img.report
        timings = rep.pop("seconds")  # wall times stay out of the product (reproducible bytes)
        write_gbsar_image(config.output, img, parameters=parameters(config), inputs=(config.scan,))
        rep["seconds"] = timings
        rep.update(image_outputs(img, config))
        if "df_below_limit" in rep:
            b = rep["df_below_limit"]
            warnings.warn(f"DF used from {b['from_m']:.2f} m, below its minimum range {b['limit_m']:.2f} m (eq. 12): "
                          f"phase error up to {b['eq11_phase_error_rad']:.2f} rad, near-range targets defocus",
                          stacklevel=2)
        if rep["skipped_stops"]:
            warnings.warn(f"skipped {len(rep['skipped_stops'])} flagged/NaN stop(s): {rep['skipped_stops']}",
                          stacklevel=2)
        return GbsarFocusReport(output=str(config.output), shape=(img.image.shape[1], img.image.shape[2]), focus=rep)
