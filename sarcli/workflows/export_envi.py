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

Option ``radiometry`` (``sarcli export --radiometry beta0|sigma0|gamma0``): the image is then the calibrated
backscatter in dB, float32 (ENVI data type 4), 10 log10(|DN|^2 L) with L the SLC's look-up table of that
kind bilinear on each pixel (:func:`sarcli.calibration.radiometry.calibrated_intensity`, NISAR's
multiplicative convention), NaN where the product is not calibrated; gamma0 is on the ellipsoid at the
focusing height (no DEM: not terrain-flattened). The header says so: ``band names``, ``data units = dB``
and ``description`` with the terms of the radiometric model not applied (also warned on stderr).
"""

from __future__ import annotations

import os
import re
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sarcli.errors import ConfigError, ProductError
from sarcli.model.slc import SLC


@dataclass(frozen=True)
class EnviOptions:
    """gcps: ground control points per image axis (>= 2); radiometry: write that calibrated backscatter
    in dB instead of the complex samples (module docstring)."""

    gcps: int = 10
    radiometry: Literal["beta0", "sigma0", "gamma0"] | None = None

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
        data, band, description, extra = _pixels(slc, options.radiometry, output.stem)
        with tempfile.TemporaryDirectory(prefix=f".{output.name}.", dir=folder) as td, warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)  # GCPs are set after the file is opened
            tmp = Path(td) / output.name
            with rasterio.open(tmp, "w", driver="ENVI", height=n, width=m, count=1, dtype=data.dtype) as dst:
                dst.write(data, 1)
                dst.gcps = ([GroundControlPoint(row=r, col=c, x=x, y=y, z=z) for r, c, x, y, z in gcps],
                            CRS.from_epsg(4326))
                dst.set_band_description(1, band)
                dst.update_tags(**tags)
            hdr = tmp.with_suffix(".hdr")
            text = re.sub(r"description = \{[^}]*\}", lambda _: f"description = {{{description}}}", hdr.read_text())
            if options.radiometry is not None:
                text = text.rstrip("\n") + "\ndata units = {dB}\n"
            hdr.write_text(text)
            written = sorted(Path(td).iterdir(), key=lambda p: p.suffix == ".hdr")  # the header last
            for f in written:
                os.replace(f, folder / f.name)
        return {"files": [f.name for f in written], "gcps": len(gcps),
                "corner_fit_error_m": corner_fit_error(grid), **extra}


def _pixels(slc: SLC, kind: str | None, stem: str) -> tuple[np.ndarray, str, str, dict[str, Any]]:
    """(the band's pixels, its name, the header's description, report details): the complex samples, or
    the calibrated backscatter ``kind`` in dB (module docstring)."""
    if kind is None:
        return np.asarray(slc.image, np.complex64), "complex SLC (zero-Doppler line, slant-range sample)", \
            f"sarcli SLC {stem}", {}
    from sarcli.calibration.radiometry import calibrated_intensity

    cal = slc.calibration
    if cal is None:  # the workflow refuses an uncalibrated SLC before this
        raise ProductError("the SLC has no /calibration: focus it again to write calibrated backscatter")
    inten = np.abs(np.asarray(slc.image, np.complex64)).astype(np.float64) ** 2
    lin = calibrated_intensity(slc, inten, 1, 1, kind)
    with np.errstate(divide="ignore", invalid="ignore"):
        db = (10.0 * np.log10(lin.astype(np.float64))).astype(np.float32)
    missing = "; ".join(cal.not_applied) or "none"
    if cal.not_applied:
        warnings.warn(f"{kind}: not applied: {missing} (relative backscatter)", stacklevel=3)
    where = "" if kind == "beta0" else " on the ellipsoid at the focusing height"
    band = f"{kind} in dB (10 log10){where}; NaN where not calibrated"  # no comma: it splits ENVI band names
    # a closing brace ends an ENVI header value: none in the text
    description = (f"sarcli {kind} {stem}: calibrated backscatter in dB (10 log10 of |DN|^2 x the {kind} "
                   f"look-up table), NaN where not calibrated; not applied: {missing}").replace("{", "(") \
        .replace("}", ")")
    return db, band, description, {"radiometry": kind, "units": "dB", "not_applied": list(cal.not_applied),
                                    "calibrated_fraction": float(np.mean(np.isfinite(db)))}


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
