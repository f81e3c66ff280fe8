"""``sarcli info`` beyond products (docs/ingest.md): a GeoTIFF (size, CRS, bounds, nodata, band units and tags),
a CEOS scene folder (read by its reader, nothing written), and one line for anything else."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sarcli.io.ceos.radarsat1 import write_ceos
from sarcli.io.h5common import sha256_file


@pytest.fixture
def geotiff(tmp_path):
    """A 40 x 30 float32 UTM 10N GeoTIFF written with rasterio directly: 12.5 m pixels from (491000, 5430000)."""
    import rasterio
    from rasterio.transform import from_origin

    path = tmp_path / "amp.tif"
    a = np.arange(40 * 30, dtype=np.float32).reshape(40, 30)
    a[0, 0] = np.nan
    with rasterio.open(path, "w", driver="GTiff", width=30, height=40, count=1, dtype="float32",
                       crs="EPSG:32610", transform=from_origin(491000.0, 5430000.0, 12.5, 12.5),
                       nodata=float("nan")) as dst:
        dst.write(a, 1)
        dst.update_tags(software="sarcli-test", wavelength_m="0.0566")
        dst.set_band_description(1, "amplitude")
        dst.set_band_unit(1, "dB")
    return path


def test_geotiff_size_crs_bounds_nodata_units_tags(cli, geotiff):
    r = cli("info", geotiff, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["product_type"] == "geotiff" and (s["width"], s["height"], s["count"]) == (30, 40, 1)
    assert s["crs"] == "EPSG:32610" and s["crs_epsg"] == 32610 and s["resolution"] == [12.5, 12.5]
    assert s["bounds"] == {"left": 491000.0, "bottom": 5430000.0 - 40 * 12.5, "right": 491000.0 + 30 * 12.5,
                           "top": 5430000.0}
    assert s["nodata"] is None  # NaN nodata: JSON has no NaN, null stands for it
    band = s["bands"][0]
    assert band["unit"] == "dB" and band["description"] == "amplitude" and band["dtype"] == "float32"
    assert s["tags"]["software"] == "sarcli-test" and s["tags"]["wavelength_m"] == "0.0566"
    assert s["n_gcps"] == 0 and s["gcp_bounds"] is None
    human = cli("info", geotiff).stdout
    assert "GeoTIFF 30 x 40 pixels, 1 band(s), CRS EPSG:32610, nodata nan" in human
    assert "unit dB, amplitude" in human and "tag software: sarcli-test" in human


def test_geotiff_with_ground_control_points(cli, tmp_path):
    """Slant-range images are georeferenced by GCPs (lon/lat), not by a transform."""
    import rasterio
    from rasterio.control import GroundControlPoint
    from rasterio.crs import CRS

    path = tmp_path / "slant.tif"
    with rasterio.open(path, "w", driver="GTiff", width=8, height=6, count=1, dtype="float32") as dst:
        dst.write(np.ones((6, 8), np.float32), 1)
        dst.gcps = ([GroundControlPoint(row=r, col=c, x=-123.0 + 0.01 * c, y=49.0 + 0.02 * r, z=0.0)
                     for r in (0, 5) for c in (0, 7)], CRS.from_epsg(4326))
    s = json.loads(cli("info", path, "--json").stdout)
    assert s["n_gcps"] == 4 and s["gcp_crs"] == "EPSG:4326" and s["bounds"] is None and s["crs"] is None
    assert s["gcp_bounds"] == pytest.approx({"left": -123.0, "bottom": 49.0, "right": -122.93, "top": 49.1})


def test_ceos_folder_is_described_without_writing(cli, make_raw, tmp_path):
    raw = make_raw(n_lines=24)
    lea, dat = write_ceos(tmp_path / "scene", raw)
    before = {p.name: sha256_file(p) for p in (tmp_path / "scene").iterdir()}
    r = cli("info", tmp_path / "scene", "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["format"] == "ceos-rs1" and s["product_type"] == "raw input" and s["shape"] == [24, 96]
    assert s["prf_hz"] == pytest.approx(raw.radar.prf_hz, rel=1e-15) and s["beam"] == "FN1"
    assert s["first_range_m"] == pytest.approx(raw.radar.first_range_m, rel=1e-12)
    assert s["azimuth_start_utc"] == raw.epoch_utc and s["n_state_vectors"] == 15 and s["orbit_frame"] == "ECI"
    assert s["inputs"] == [str(lea), str(dat)]
    assert {p.name: sha256_file(p) for p in (tmp_path / "scene").iterdir()} == before  # nothing written
    assert json.loads(cli("info", lea, dat, "--json").stdout)["shape"] == [24, 96]
    human = cli("info", tmp_path / "scene").stdout
    assert "raw input (ceos-rs1)" in human and "15 state vectors (ECI)" in human


@pytest.mark.parametrize("content, needle", [
    (b"hello", "not a sarcli product, a GeoTIFF, or a raw input a reader recognises"),
    (b"II*\x00" + b"\0" * 20, "not a readable GeoTIFF"),
])
def test_anything_else_is_one_line(cli, tmp_path, content, needle):
    p = tmp_path / "x.bin"
    p.write_bytes(content)
    r = cli("info", p)
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 1 and len(lines) == 1 and needle in lines[0], r.stderr
