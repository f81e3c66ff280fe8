"""The ``envi`` export format: an SLC as an ENVI complex image (GDAL's ENVI driver), georeferenced by
ground control points.

``OUT.img`` holds the complex64 image (ENVI data type 6, band-sequential, lines = zero-Doppler times,
samples = slant ranges, as in the SLC); ``OUT.hdr`` the ENVI header with ``geo points`` at the four corner
pixel centres (GDAL's ENVI driver writes four: lat/lon on the ellipsoid raised by the focusing height, the
same zero-Doppler geolocation as the slant GeoTIFF, :func:`sarcli.focus.geocode.slant_gcps`) and the band
name; GDAL keeps sarcli's provenance tags (:func:`sarcli.focus.geocode.slc_tags`) and the whole
``gcps`` x ``gcps`` grid (tag ``GCP_GRID``: row, col, lon, lat, h) in ``OUT.img.aux.xml``. A reader
maps pixels bilinearly between the corners: the report gives the largest miss of that map at the grid
(``corner_fit_error_m``; a few metres on a 600 x 1536 RADARSAT-1 cut, more on a full 100 km swath,
where the slant-to-ground range map bends: use the grid or the SICD there).
ENVI, GDAL (``gdalinfo``, ``gdalwarp -tps``), QGIS and SNAP read it. The files are written in a temporary
folder beside the output and renamed into place, the header last.
"""

from __future__ import annotations

import os
import re
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, ProductError
from sarcli.model.slc import SLC


@dataclass(frozen=True)
class EnviOptions:
    """gcps: ground control points per image axis (>= 2)."""

    gcps: int = 10

    def __post_init__(self) -> None:
        if self.gcps < 2:
            raise ConfigError(f"envi option gcps must be at least 2, got {self.gcps}")


class EnviFormat:
    """ENVI complex image with GCP georeferencing (module docstring)."""

    name = "envi"
    description = "ENVI complex image (.img + .hdr) with ground control points (GDAL, ENVI, QGIS)"
    suffix = ".img"
    Options = EnviOptions

    def write(self, slc: SLC, output: Path, options: EnviOptions, inputs: tuple[Path, ...]) -> dict[str, Any]:
        import rasterio
        from rasterio.control import GroundControlPoint
        from rasterio.crs import CRS
        from rasterio.errors import NotGeoreferencedWarning

        from sarcli.focus.geocode import slant_gcps, slc_tags
        from sarcli.io.slc import recorded_height
        from sarcli.model.terrain import ConstantHeight

        if slc.orbit is None or slc.orbit.frame == "LOCAL":
            raise ProductError("ENVI georeferencing needs an Earth orbit (ECI or ECEF state vectors); this SLC has "
                               f"{'none' if slc.orbit is None else 'a LOCAL (flat-Earth) orbit'}")
        output = Path(output)
        if output.suffix.lower() != ".img":
            raise ConfigError(f"an ENVI image is NAME.img (its header NAME.hdr), got {output.name}")
        folder = output.parent if str(output.parent) else Path(".")
        if not folder.is_dir():
            raise ProductError(f"output folder {folder} does not exist")
        n, m = slc.image.shape
        grid = slant_gcps(slc, (n, m), 1, 1, ConstantHeight(recorded_height(slc.parameters)), options.gcps,
                          options.gcps)
        corner = {(0.5, 0.5), (0.5, m - 0.5), (n - 0.5, 0.5), (n - 0.5, m - 0.5)}
        gcps = [g for g in grid if (g[0], g[1]) in corner]
        tags = slc_tags(slc, inputs, {"GCP_GRID": [list(g) for g in grid]})
        with tempfile.TemporaryDirectory(prefix=f".{output.name}.", dir=folder) as td, warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)  # GCPs are set after the file is opened
            tmp = Path(td) / output.name
            with rasterio.open(tmp, "w", driver="ENVI", height=n, width=m, count=1, dtype="complex64") as dst:
                dst.write(np.asarray(slc.image, np.complex64), 1)
                dst.gcps = ([GroundControlPoint(row=r, col=c, x=x, y=y, z=z) for r, c, x, y, z in gcps],
                            CRS.from_epsg(4326))
                dst.set_band_description(1, "complex SLC (zero-Doppler line, slant-range sample)")
                dst.update_tags(**tags)
            hdr = tmp.with_suffix(".hdr")
            text = re.sub(r"description = \{[^}]*\}", f"description = {{sarcli SLC {output.stem}}}",
                          hdr.read_text())
            hdr.write_text(text)
            written = sorted(Path(td).iterdir(), key=lambda p: p.suffix == ".hdr")  # the header last
            for f in written:
                os.replace(f, folder / f.name)
        return {"files": [f.name for f in written], "gcps": len(gcps),
                "corner_fit_error_m": corner_fit_error(grid)}


def corner_fit_error(grid: list[tuple[float, float, float, float, float]]) -> float:
    """Largest distance (m) between a grid GCP and the bilinear map (line, sample) -> (lon, lat) through
    the four corner GCPs, which is how a reader georeferences an ENVI ``geo points`` list of four."""
    g = np.asarray(grid, np.float64)
    r, c = g[:, 0], g[:, 1]
    corner = (np.isin(r, [r.min(), r.max()])) & (np.isin(c, [c.min(), c.max()]))
    a = np.column_stack([np.ones_like(r), r, c, r * c])
    coef, *_ = np.linalg.lstsq(a[corner], g[corner, 2:4], rcond=None)
    d = a @ coef - g[:, 2:4]
    north = d[:, 1] * 111.2e3
    east = d[:, 0] * 111.2e3 * np.cos(np.radians(g[:, 3]))
    return float(np.max(np.hypot(north, east)))


ENVI = EnviFormat()
