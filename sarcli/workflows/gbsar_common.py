"""What the GB-SAR workflows share (not a workflow itself): the guard run before any work, the
parameters stored in products, inputs that are images or scans, and the map / picture outputs.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, ProductError
from sarcli.model.gbsar import GbsarImage
from sarcli.workflows.base import refuse_overwriting_inputs

if TYPE_CHECKING:
    from sarcli.io.images import OverviewKind


def guard(inputs: Iterable[str | os.PathLike | None], outputs: Iterable[str | os.PathLike | None]) -> None:
    """Before any work: refuse an output that is an input (same path, symbolic or hard link) and an
    output whose folder does not exist (``None`` entries are skipped)."""
    given = [p for p in outputs if p is not None]
    refuse_overwriting_inputs(inputs, given)
    for p in given:
        folder = Path(p).resolve().parent
        if not folder.is_dir():
            raise ConfigError(f"output folder {folder} does not exist: create it first")


def parameters(config: Any) -> dict[str, Any]:
    """The configuration as stored in a product's ``parameters``: paths by file name only (like the
    provenance ``inputs``), so that the same command in two folders writes the same bytes."""
    def names(v: Any) -> Any:
        if isinstance(v, Path):
            return v.name
        return [names(x) for x in v] if isinstance(v, tuple | list) else v

    values = {f.name: getattr(config, f.name) for f in dataclasses.fields(config)}
    return to_mapping({k: names(v) for k, v in values.items() if v is not None})


def criterion_rad(criterion_deg: float) -> float:
    """The eq. 12 phase-error criterion, given in degrees in (0, 180], in radians."""
    if not (math.isfinite(criterion_deg) and 0 < criterion_deg <= 180):
        raise ConfigError(f"--criterion-deg must be in (0, 180] degrees, got {criterion_deg:g}")
    return math.radians(criterion_deg)


def is_scan(path: str | os.PathLike) -> bool:
    """True for a ``gbsar_scan`` product, False for a ``gbsar_image`` (anything else is refused)."""
    from sarcli.io.h5common import attr_str, open_product

    with open_product(path, ("gbsar_image", "gbsar_scan")) as f:
        return attr_str(f, "product_type") == "gbsar_scan"


def focus_on_the_fly(path: str | os.PathLike, like: GbsarImage | None = None) -> GbsarImage:
    """A scan focused with ``auto`` on the grid of the image ``like`` (default grid without one: it
    depends on the wavelength, so a delta-f pair needs ``like``)."""
    from sarcli.gbsar.focus import Grid, image_from_scan
    from sarcli.io.scan import read_scan

    grid = Grid(ranges=like.range_m, azimuths=like.azimuth_m) if like is not None else None
    return image_from_scan(read_scan(path), grid=grid)


def rail_image(img: GbsarImage, path: str | os.PathLike) -> GbsarImage:
    """``img`` if it is a rail slant-plane image focused in air; interferometry, coherence and
    polarimetry (their phase models, footprint masks and map outputs) assume that geometry, so a
    ``--grid`` or ``--permittivity`` image is refused in one line."""
    if img.grid_z_m is not None:
        raise ProductError(f"{path} is a grid image (gbsar focus --grid): interfere, coherence and polarimetry "
                           "work on rail slant-plane images")
    if img.permittivity != 1.0:
        raise ProductError(f"{path} was focused in a medium (--permittivity {img.permittivity:g}): interfere, "
                           "coherence and polarimetry work on images focused in air")
    return img


def load_image(path: str | os.PathLike, like: GbsarImage | None = None) -> GbsarImage:
    """A focused rail image product (:func:`rail_image`), or a scan focused on the fly
    (:func:`focus_on_the_fly`)."""
    if is_scan(path):
        return focus_on_the_fly(path, like)
    from sarcli.io.gbsar_image import read_gbsar_image

    return rail_image(read_gbsar_image(path), path)


def slant_extent(img: GbsarImage) -> list[float]:
    """imshow extent of a slant-plane raster: azimuth x across, range R0 down."""
    return [img.azimuth_m[0], img.azimuth_m[-1], img.range_m[-1], img.range_m[0]]


def gbsar_tags(img: GbsarImage, inputs: Iterable[str | os.PathLike], **extra: Any) -> dict[str, str]:
    """GeoTIFF provenance tags of a picture of ``img`` (:func:`sarcli.io.images.provenance_tags`): the
    wavelength at the centre frequency, the rail's look side, the scan time, the input files."""
    from sarcli.io.images import provenance_tags

    return provenance_tags(tuple(inputs), sensor="GB-SAR", wavelength_m=img.wavelength_m,
                           look_side=img.site.look_side, acquisition=(img.epoch_utc, img.scan_time_s, img.scan_time_s),
                           ALGORITHM=img.algorithm, RAIL_HEIGHT_M=img.rail_height_m, **extra)


def map_outputs(raster: np.ndarray, img: GbsarImage, geotiff: Path | None, png: Path | None, title: str, label: str,
                cmap: str, vmin: float, vmax: float, map_pixel_m: float | None, *, unit: str,
                overview: OverviewKind = "mean", inputs: Iterable[str | os.PathLike] = (),
                brightness: np.ndarray | None = None, brightness_label: str = "") -> dict[str, Any]:
    """UTM GeoTIFF (nearest resampling; a COG with ``unit``, ``label`` as the band description, the
    ``overview`` reduction, provenance tags and a QGIS style ``cmap`` from ``vmin`` to ``vmax``) and a
    slant-plane PNG of a real-valued raster on ``img``'s grid. With ``brightness`` (values in [0, 1],
    e.g. the coherence) and a phase raster, the PNG shows hue = phase and brightness = that."""
    from sarcli.gbsar.geocode import resample_to_map
    from sarcli.io.images import Band, Style, write_geotiff, write_phase_picture, write_quicklook

    out: dict[str, Any] = {}
    if geotiff is not None:
        pixel = map_pixel_m or float(img.range_m[1] - img.range_m[0])
        m, transform, crs, ginfo = resample_to_map(raster, img.range_m, img.azimuth_m, img.site, img.rail_height_m,
                                                   img.rail_centre_m, pixel, "utm")
        write_geotiff(geotiff, Band(m, label, unit, overview), crs, transform=transform,
                      tags=gbsar_tags(img, inputs), style=Style(1, vmin, vmax, cmap, label))
        out["geotiff"] = {"path": str(geotiff), "crs": crs, **ginfo}
    if png is not None:
        kw: dict[str, Any] = {"title": title, "extent": slant_extent(img), "xlabel": "azimuth x (m)",
                              "ylabel": "range R0 (m)"}
        if brightness is not None:
            write_phase_picture(png, raster, brightness, brightness_label=brightness_label, **kw)
        else:
            write_quicklook(png, raster, cmap=cmap, is_db=True, vmin=vmin, vmax=vmax, colorbar_label=label, **kw)
        out["png"] = str(png)
    return out
