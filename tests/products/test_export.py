"""``sarcli export --format sicd|envi`` checked by the outside tools: sarkit's NITF reader and SICD
consistency checker (pixels equal, the SICD projection of the simulated targets within one pixel of
the simulator's truth and of sarcli's geolocation), GDAL's ENVI driver through rasterio."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("sarkit", reason="sarkit is the optional 'sicd' extra (installed by make install)")

# RADARSAT-1 samples its 30.1 MHz chirp at 32.3 MHz: a range oversampling of 1.07, which sarkit WARNS is
# below its usual 1.1 (a property of the sensor, not of the export)
KNOWN_WARNINGS = {"check_iprbw_to_ss_osr_row"}


@pytest.mark.slow
def test_sicd_consistent_same_pixels_geolocated_within_a_pixel(cli, small, tmp_path):
    import sarkit.sicd as sksicd
    import sarkit.verification as skver

    from orbit.geodetic import ecef_to_geodetic
    from sarcli.focus.geolocation import zero_doppler_points
    from sarcli.io.slc import read_slc
    from sarcli.model.terrain import ConstantHeight

    out = tmp_path / "x.nitf"
    r = cli("export", small.slc, "--format", "sicd", "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["format"] == "sicd"
    with open(out, "rb") as f:
        con = skver.SicdConsistency.from_file(f)
        con.check()
    failures = con.failures()
    assert set(failures) <= KNOWN_WARNINGS, {k: str(v)[:300] for k, v in failures.items()}
    for v in failures.values():
        assert all(d["severity"] == "Warning" for d in v["details"] if not d["passed"])
    with open(out, "rb") as f:
        reader = sksicd.NitfReader(f)
        pixels = reader.read_image()
        tree = reader.metadata.xmltree
    slc = read_slc(small.slc)
    np.testing.assert_array_equal(pixels, slc.image.T)  # rows are ranges in SICD
    # the simulated targets: their (zero-Doppler time, closest range) as SICD image coordinates
    tg = slc.truth["targets"]
    dt = np.median(np.diff(slc.azimuth_time))
    dr = np.median(np.diff(slc.slant_range))
    rows = (tg["closest_range_m"] - slc.slant_range[0]) / dr
    cols = (tg["zero_doppler_time_s"] - slc.azimuth_time[0]) / dt
    xy = sksicd.rowcol_to_xrowycol(tree, np.column_stack([rows, cols]))
    spp, _, ok = sksicd.image_to_constant_hae_surface(tree, xy, tg["height_m"])
    assert ok
    lat, lon, _ = ecef_to_geodetic(spp)
    north = (lat - tg["lat_deg"]) * 111.2e3
    east = (lon - tg["lon_deg"]) * 111.2e3 * np.cos(np.radians(tg["lat_deg"]))
    col_ss = float(tree.findtext("{*}Grid/{*}Col/{*}SS"))
    ground_range = dr / np.sin(np.radians(30.0))  # the incidence here is ~37 deg: a pixel is < 9.3 m across
    assert np.max(np.hypot(north, east)) < min(col_ss, ground_range)
    mine = zero_doppler_points(slc.orbit, slc.epoch_utc, tg["zero_doppler_time_s"], tg["closest_range_m"],
                               slc.radar.wavelength_m, slc.look_side, ConstantHeight(0.0))
    assert np.max(np.linalg.norm(spp - mine, axis=-1)) < 0.01  # the same zero-Doppler geometry


@pytest.mark.slow
def test_envi_reads_back_with_corner_gcps(cli, small, tmp_path):
    import rasterio

    from orbit.geodetic import ecef_to_geodetic
    from sarcli.focus.geolocation import zero_doppler_points
    from sarcli.io.slc import read_slc
    from sarcli.model.terrain import ConstantHeight

    out = tmp_path / "x.img"
    r = cli("export", small.slc, "--format", "envi", "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    assert "geo points" in (tmp_path / "x.hdr").read_text()
    slc = read_slc(small.slc)
    with rasterio.open(out) as ds:
        a = ds.read(1)
        gcps, crs = ds.gcps
        tags = ds.tags()
    np.testing.assert_array_equal(a, slc.image)
    assert crs.to_epsg() == 4326 and len(gcps) == 4 and tags["SOFTWARE"] == "sarcli"
    n, m = slc.image.shape
    for g in gcps:
        i, j = int(g.row - 0.5), int(g.col - 0.5)
        assert (i, j) in {(0, 0), (0, m - 1), (n - 1, 0), (n - 1, m - 1)}
        p = zero_doppler_points(slc.orbit, slc.epoch_utc, slc.azimuth_time[i], slc.slant_range[j],
                                slc.radar.wavelength_m, slc.look_side, ConstantHeight(0.0))
        lat, lon, _ = ecef_to_geodetic(np.reshape(p, (1, 3)))
        assert abs(float(lat[0]) - g.y) < 1e-7 and abs(float(lon[0]) - g.x) < 1e-7
    assert len(json.loads(tags["GCP_GRID"])) == 100


def test_unknown_format_and_bad_name_refused(cli, tmp_path):
    src = tmp_path / "slc.h5"
    src.write_bytes(b"not read")
    r = cli("export", src, "--format", "nope", "-o", tmp_path / "x.nitf")
    assert r.exit_code == 2 and r.stderr.startswith("sarcli: error:") and "sicd" in r.stderr
