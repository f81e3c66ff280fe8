"""Images for people: GeoTIFF (rasterio, real CRS, nodata, provenance tags, overviews) and PNG quicklooks.

GeoTIFFs are written atomically (temporary file in the target folder, then rename).
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sarcli.errors import ProductError
from sarcli.io.atomic import atomic_path  # re-exported: plots and CSV writers import it from here

#: GDAL's block cache while a GeoTIFF is written, MB (its default, 5 % of the machine's memory, would hold
#: a large raster's blocks a second time)
GDAL_CACHE_MB = 64


@dataclass(frozen=True)
class Strips:
    """A raster too large to hold twice, given as ``shape`` and ``strips()``: an iterator of (first row,
    rows) covering the rows in order (rows in multiples of 256, the GeoTIFF's tile height, but the last)."""

    shape: tuple[int, int]
    strips: Any

    def __iter__(self) -> Iterator[tuple[int, np.ndarray]]:
        return iter(self.strips())


def write_geotiff(
    path: str | os.PathLike,
    array: np.ndarray | Strips,
    crs: str | int,
    transform: Any | None = None,
    gcps: Sequence[tuple[float, float, float, float, float]] | None = None,
    nodata: float | None = float("nan"),
    tags: Mapping[str, Any] | None = None,
    band_description: str | None = None,
    overviews: Sequence[int] = (2, 4, 8),
) -> None:
    """Write a single-band float32 GeoTIFF: tiled, deflate-compressed, with overviews.

    Georeferencing is either an affine ``transform`` (rasterio.Affine) in ``crs``, or ground control
    points ``gcps`` given as (row, col, x, y, z) in ``crs`` (e.g. EPSG:4326 lon/lat for slant-range
    geometry images). ``crs`` is anything rasterio accepts ("EPSG:32610", 4326, a WKT string).
    ``array`` may be :class:`Strips`, written strip by strip (the same file).
    """
    import rasterio
    from rasterio.control import GroundControlPoint
    from rasterio.crs import CRS
    from rasterio.windows import Window

    a = array if isinstance(array, Strips) else np.asarray(array, dtype=np.float32)
    if len(a.shape) != 2:
        raise ProductError(f"GeoTIFF needs a 2-D array, got shape {a.shape}")
    crs_obj = CRS.from_epsg(crs) if isinstance(crs, int) else CRS.from_user_input(crs)
    profile: dict[str, Any] = {
        "driver": "GTiff", "height": a.shape[0], "width": a.shape[1], "count": 1, "dtype": "float32",
        "compress": "deflate", "predictor": 3, "tiled": True, "blockxsize": 256, "blockysize": 256,
        "nodata": nodata,
    }
    if a.shape[0] < 256 or a.shape[1] < 256:
        profile.pop("blockxsize")
        profile.pop("blockysize")
        profile["tiled"] = False
    if transform is not None:
        profile["crs"] = crs_obj
        profile["transform"] = transform
    with atomic_path(path, ".tif") as tmp, rasterio.Env(GDAL_CACHEMAX=GDAL_CACHE_MB):
        with rasterio.open(tmp, "w", **profile) as dst:
            if isinstance(a, Strips):
                for row, strip in a:
                    dst.write(np.asarray(strip, np.float32), 1, window=Window(0, row, a.shape[1], strip.shape[0]))
            else:
                dst.write(a, 1)
            if gcps is not None:
                dst.gcps = ([GroundControlPoint(row=r, col=c, x=x, y=y, z=z) for r, c, x, y, z in gcps],
                            crs_obj)
            if tags:
                dst.update_tags(**{str(k): str(v) for k, v in tags.items()})
            if band_description:
                dst.set_band_description(1, band_description)
            levels = [f for f in overviews if min(a.shape) // f >= 8]
            if levels:
                dst.build_overviews(levels, rasterio.enums.Resampling.average)
                dst.update_tags(ns="rio_overview", resampling="average")


def amplitude_db(image: np.ndarray, floor_db: float = -300.0) -> np.ndarray:
    """20*log10|image| with a floor instead of -inf (float32)."""
    a = np.abs(np.asarray(image)).astype(np.float64)
    with np.errstate(divide="ignore"):
        out = 20.0 * np.log10(a)
    return np.maximum(out, floor_db).astype(np.float32)


def write_quicklook(
    path: str | os.PathLike,
    image: np.ndarray,
    title: str = "",
    dynamic_range_db: float = 40.0,
    cmap: str = "gray",
    is_db: bool = False,
    vmin: float | None = None,
    vmax: float | None = None,
    extent: Sequence[float] | None = None,
    xlabel: str = "",
    ylabel: str = "",
    colorbar_label: str = "",
    aspect: str | float = "auto",
) -> None:
    """A PNG for people: amplitude in dB (or the values as given, e.g. phase with a cyclic cmap)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if np.iscomplexobj(image) or not is_db and cmap == "gray":
        data = amplitude_db(image)
        finite = data[np.isfinite(data)]
        # white at the 99.9th percentile (scenes), but never more than 20 dB under the peak: on a point
        # scene the percentile sits in the sidelobes/quantization floor and would paint it as white as
        # the targets
        top = max(float(np.percentile(finite, 99.9)), float(finite.max()) - 20.0) if finite.size else 0.0
        vmax = top if vmax is None else vmax
        vmin = vmax - dynamic_range_db if vmin is None else vmin
        colorbar_label = colorbar_label or "amplitude (dB)"
    else:
        data = np.asarray(image, dtype=np.float32)
    fig, ax = plt.subplots(figsize=(8, 6), dpi=100)
    im = ax.imshow(data, cmap=cmap, vmin=vmin, vmax=vmax, extent=extent, aspect=aspect,
                   interpolation="nearest", origin="upper")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    fig.colorbar(im, ax=ax, label=colorbar_label)
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
