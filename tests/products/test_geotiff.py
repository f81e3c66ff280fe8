"""GeoTIFFs as the field's tools read them: rio-cogeo's COG validator, rasterio reading back overviews,
units, descriptions and provenance tags, QGIS styles parsed as XML; the focus, GB-SAR focus,
interfere and polarimetry GeoTIFFs end to end."""

from __future__ import annotations

import datetime as dt
import hashlib
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import rasterio
from rasterio.transform import Affine
from rio_cogeo.cogeo import cog_validate

from sarcli.io.images import Band, Style, provenance_tags, write_geotiff

C = 299792458.0


def _sha(path) -> str:
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def _cells(a: np.ndarray, f: int):
    """Every f x f cell of ``a`` (edge cells partial), with its (row, col) in the overview: a plain loop."""
    for i in range(0, a.shape[0], f):
        for j in range(0, a.shape[1], f):
            v = a[i:i + f, j:j + f].ravel()
            yield i // f, j // f, v[np.isfinite(v)]


def test_overviews_average_power_not_db(tmp_path):
    rng = np.random.default_rng(1)
    n, m = 601, 523  # odd sizes: partial cells at the edges
    amp = np.abs(rng.normal(size=(n, m)) + 1j * rng.normal(size=(n, m)))
    amp[100:140, 200:260] = np.nan  # no data
    db = 20 * np.log10(amp)
    phase = np.angle(np.exp(1j * (0.02 * np.arange(m)[None, :] + rng.normal(0, 0.3, (n, m)))))
    write_geotiff(tmp_path / "t.tif", [Band(amp, "amplitude", "1", "power"), Band(db, "amplitude", "dB", "power_db"),
                                       Band(phase, "phase", "rad", "phase")],
                  "EPSG:32610", transform=Affine(10, 0, 5e5, 0, -10, 4e6))
    assert cog_validate(str(tmp_path / "t.tif")) == (True, [], [])
    with rasterio.open(tmp_path / "t.tif") as ds:
        assert ds.overviews(1) == [2, 4]  # until the picture fits one 256-pixel tile: 601 / 4 = 151
        full = ds.read()
    np.testing.assert_array_equal(full[0], amp.astype(np.float32))
    levels = {}
    for level, f, shape, every in ((0, 2, (3, 301, 262), 97), (1, 4, (3, 151, 131), 37)):  # 4: pooled 2 x 2 sums
        with rasterio.open(tmp_path / "t.tif", overview_level=level) as ov:
            o = levels[f] = ov.read()
        assert o.shape == shape
        for i, j, v in list(_cells(amp, f))[::every]:
            if v.size == 0:
                assert np.isnan(o[0, i, j]) and np.isnan(o[1, i, j])
                continue
            assert o[0, i, j] == pytest.approx(np.sqrt(np.mean(v ** 2)), rel=1e-5)
            assert o[1, i, j] == pytest.approx(10 * np.log10(np.mean(v ** 2)), abs=1e-4)
        for i, j, v in list(_cells(phase, f))[::every]:
            assert o[2, i, j] == pytest.approx(np.angle(np.sum(np.exp(1j * v))), abs=1e-5)
    o = levels[2]
    # averaging the dB values instead would sit low on speckle: for 4 exponential intensities (|z|^2 of a
    # complex Gaussian) E[10 log10 mean] - E[10 log10 x] = (10 / ln 10)(psi(4) - ln 4 - psi(1)) = 1.94 dB
    plain = db[:100, :522].reshape(50, 2, 261, 2).mean(axis=(1, 3))  # rows clear of the no-data patch
    gap = o[1, :50, :261] - plain
    assert np.nanmean(gap) == pytest.approx(1.94, abs=0.1)


def test_tags_units_and_gcps(tmp_path):
    src = tmp_path / "in.h5"
    src.write_bytes(b"input bytes")
    a = np.arange(40 * 30, dtype=np.float32).reshape(40, 30)
    tags = provenance_tags([src], sensor="ceos", wavelength_m=0.0566, look_side="right",
                           acquisition=("2002-06-16T15:41:00.5Z", 1.25, 3.0), EXTRA={"k": 1})
    gcps = [(0.5, 0.5, -123.0, 49.0, 0.0), (0.5, 29.5, -122.9, 49.0, 0.0), (39.5, 0.5, -123.0, 49.1, 0.0)]
    write_geotiff(tmp_path / "g.tif", Band(a, "amplitude, slant range", "1", "power"), 4326, gcps=gcps, tags=tags,
                  style=Style(1, 0.0, 100.0))
    assert cog_validate(str(tmp_path / "g.tif")) == (True, [], [])
    with rasterio.open(tmp_path / "g.tif") as ds:
        t = ds.tags()
        assert ds.units == ("1",) and ds.descriptions == ("amplitude, slant range",)
        assert ds.scales == (1.0,) and ds.offsets == (0.0,) and np.isnan(ds.nodata)
        got_gcps, crs = ds.gcps
        assert len(got_gcps) == 3 and crs.to_epsg() == 4326 and got_gcps[1].x == -122.9
    assert t["SOFTWARE"] == "sarcli" and t["SENSOR"].startswith("RADARSAT-1") and t["LOOK_SIDE"] == "right"
    assert float(t["WAVELENGTH_M"]) == 0.0566 and json.loads(t["EXTRA"]) == {"k": 1}
    assert t["ACQUISITION_START_UTC"] == "2002-06-16T15:41:01.750000Z"
    assert t["ACQUISITION_STOP_UTC"] == "2002-06-16T15:41:03.500000Z"
    assert json.loads(t["INPUTS"]) == [{"path": str(src), "sha256": _sha(src)}]
    assert t["TIFFTAG_SOFTWARE"].startswith("sarcli ")
    created = dt.datetime.strptime(t["CREATED_UTC"], "%Y-%m-%dT%H:%M:%S.%fZ")
    assert t["TIFFTAG_DATETIME"] == created.strftime("%Y:%m:%d %H:%M:%S")


def test_qgis_styles(tmp_path):
    a = np.linspace(-np.pi, np.pi, 64 * 64, dtype=np.float32).reshape(64, 64)
    write_geotiff(tmp_path / "p.tif", [Band(a, "phase", "rad", "phase"), Band(a, "x", "1")], "EPSG:32610",
                  transform=Affine(1, 0, 0, 0, -1, 0), style=Style(1, -np.pi, np.pi, "twilight"))
    r = ET.parse(tmp_path / "p.qml").getroot().find("pipe/rasterrenderer")
    assert r.get("type") == "singlebandpseudocolor" and r.get("band") == "1"
    items = r.findall("rastershader/colorrampshader/item")
    assert len(items) == 17 and float(items[0].get("value")) == pytest.approx(-np.pi, abs=1e-5)
    assert items[0].get("color") == items[-1].get("color")  # a cyclic map closes on itself
    write_geotiff(tmp_path / "d.tif", [Band(a, "a", "1"), Band(a, "db", "dB")], "EPSG:32610",
                  transform=Affine(1, 0, 0, 0, -1, 0), style=Style(2, -25.0, 5.0))
    r = ET.parse(tmp_path / "d.qml").getroot().find("pipe/rasterrenderer")
    assert r.get("type") == "singlebandgray" and r.get("grayBand") == "2"
    assert (float(r.find("contrastEnhancement/minValue").text), float(r.find("contrastEnhancement/maxValue").text)) \
        == (-25.0, 5.0)


@pytest.mark.slow
def test_focus_geotiffs(small):
    import h5py

    with h5py.File(small.slc) as f:
        first, last, n = int(f.attrs["first_full_line"]), int(f.attrs["last_full_line"]), f["image"].shape[0]
        t0, t1 = f["azimuth_time"][0], f["azimuth_time"][-1]
        epoch = f.attrs["epoch_utc"]
    assert 0 < first < last < n - 1  # the scene has partly focused lines at both ends
    for tif in (small.slant_tif, small.map_tif):
        assert cog_validate(str(tif)) == (True, [], []), tif
        with rasterio.open(tif) as ds:
            assert ds.count == 2 and ds.units == ("1", "dB") and ds.overviews(2)
            t = ds.tags()
            a, b = ds.read(1), ds.read(2)
        np.testing.assert_allclose(b[np.isfinite(b)], 20 * np.log10(a[np.isfinite(b)]), atol=1e-4)
        assert t["SENSOR"] == "simulated (sarcli simulate)" and t["LOOK_SIDE"] == "right"
        assert float(t["WAVELENGTH_M"]) == pytest.approx(C / 5.3e9, rel=1e-12)
        e = dt.datetime.fromisoformat(epoch.replace("Z", "+00:00"))
        assert t["ACQUISITION_START_UTC"] == (e + dt.timedelta(seconds=float(t0))).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
        assert t["ACQUISITION_STOP_UTC"] == (e + dt.timedelta(seconds=float(t1))).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
        assert json.loads(t["INPUTS"]) == [{"path": str(small.slc), "sha256": _sha(small.slc)}]
        assert t["FULLY_FOCUSED_LINES"].startswith(f"{first}..{last} of {n}")
        assert (tif.with_suffix(".qml")).is_file()
    with rasterio.open(small.slant_tif) as ds:
        amp = ds.read(1)
    rows = np.arange(amp.shape[0]) * 2  # 2 azimuth looks: row k holds lines 2k, 2k + 1
    full = (rows >= first) & (rows + 1 <= last)
    assert np.all(np.isnan(amp[~full])) and np.all(np.isfinite(amp[full]))


def _gbsar_scans(cli, tmp_path):
    from tests.gbsar.test_cli import _scan

    return _scan(cli, tmp_path, "a"), _scan(cli, tmp_path, "b", minute=30,
                                            extra="[effects.displacement]\nscale = 1.0\n")


def test_gbsar_geotiffs_nan_for_no_signal_and_tagged(cli, tmp_path):
    a, b = _gbsar_scans(cli, tmp_path)
    img = tmp_path / "img.h5"
    r = cli("gbsar", "focus", a, "-o", img, "--geotiff", tmp_path / "img.tif")
    assert r.exit_code == 0, r.stderr
    with rasterio.open(tmp_path / "img.tif") as ds:
        v = ds.read(1)
        assert ds.units == ("dB",) and ds.tags(1)["OVERVIEW_RESAMPLING"] == "power_db"
        t = ds.tags()
    assert np.isnan(v).any() and np.isfinite(v).any()
    assert np.nanmin(v) > -190.0  # no -200 dB floor: pixels without signal are nodata
    assert json.loads(t["INPUTS"]) == [{"path": str(img), "sha256": _sha(img)}]
    assert float(t["WAVELENGTH_M"]) == pytest.approx(C / 5.3e9) and t["SENSOR"] == "GB-SAR"
    assert t["ACQUISITION_START_UTC"].startswith("2024-05-01T10:00")
    outs = {k: tmp_path / f"{k}.tif" for k in ("phase", "los", "coh")}
    r = cli("gbsar", "interfere", a, b, "-o", tmp_path / "ifg.h5", "--geotiff", outs["phase"], "--value-geotiff",
            outs["los"], "--coherence-geotiff", outs["coh"], "--png", tmp_path / "ifg.png", "--coherence-png",
            tmp_path / "coh.png")
    assert r.exit_code == 0, r.stderr
    nd = tmp_path / "nd.tif"
    assert cli("gbsar", "polarimetry", img, "--geotiff", nd).exit_code == 0
    for path, unit in ((outs["phase"], "rad"), (outs["los"], "mm"), (outs["coh"], "1"), (nd, "1")):
        assert cog_validate(str(path)) == (True, [], []), path
        with rasterio.open(path) as ds:
            t = ds.tags()
            assert ds.units == (unit,) and ds.descriptions[0]
        assert {"SOFTWARE", "SOFTWARE_VERSION", "CREATED_UTC", "INPUTS", "SENSOR", "WAVELENGTH_M", "LOOK_SIDE",
                "ACQUISITION_START_UTC"} <= set(t), path
        assert path.with_suffix(".qml").is_file()
    with rasterio.open(outs["coh"]) as ds:
        c = ds.read(1)
    assert np.nanmax(c) <= 1.0 + 1e-6 and np.nanmin(c) >= 0.0
    assert (tmp_path / "coh.png").stat().st_size > 1000 and (tmp_path / "ifg.png").stat().st_size > 1000


def test_the_file_does_not_depend_on_the_thread_budget(tmp_path):
    """The COG's tiles are deflated on the budget's threads, each tile on its own: the same bytes."""

    from sarcli import threads

    a = np.abs(np.random.default_rng(3).standard_normal((700, 600))).astype(np.float32)
    t = Affine(10.0, 0.0, 500000.0, 0.0, -10.0, 5400000.0)
    for n in (1, 2):
        with threads.limited(n):
            write_geotiff(tmp_path / f"t{n}.tif", [Band(a, "a", "1", "power")], "EPSG:32610", transform=t,
                          tags={"k": "v"})
    assert (tmp_path / "t1.tif").read_bytes() == (tmp_path / "t2.tif").read_bytes()


@pytest.mark.parametrize("compression,tag", [("deflate", "deflate"), ("zstd", "zstd"), ("none", None)])
def test_every_compression_gives_a_valid_cog_of_the_same_pixels(tmp_path, compression, tag):
    """The COG driver compresses the tiles as asked; the pixels, overviews and layout stay the same."""
    rng = np.random.default_rng(4)
    amp = np.abs(rng.standard_normal((530, 610))).astype(np.float32)
    amp[:90, :120] = np.nan  # a no-data corner, as a map's
    t = Affine(10.0, 0.0, 500000.0, 0.0, -10.0, 5400000.0)
    path = tmp_path / f"{compression}.tif"
    write_geotiff(path, [Band(amp, "a", "1", "power")], "EPSG:32610", transform=t, compression=compression)
    assert cog_validate(str(path)) == (True, [], [])
    with rasterio.open(path) as ds:
        assert ds.profile.get("compress") == tag
        np.testing.assert_array_equal(ds.read(1), amp)
        assert ds.overviews(1) == [2, 4]
        with rasterio.open(path, overview_level=0) as ov:
            first = ov.read(1)
    write_geotiff(tmp_path / "ref.tif", [Band(amp, "a", "1", "power")], "EPSG:32610", transform=t)
    with rasterio.open(tmp_path / "ref.tif", overview_level=0) as ov:
        np.testing.assert_array_equal(first, ov.read(1))


def test_an_unknown_compression_is_refused_in_one_line(tmp_path):
    from sarcli.errors import ConfigError

    with pytest.raises(ConfigError, match="deflate, zstd, none"):
        write_geotiff(tmp_path / "x.tif", [Band(np.ones((4, 4), np.float32), "a", "1", "power")], "EPSG:32610",
                      transform=Affine(1.0, 0.0, 0.0, 0.0, -1.0, 0.0), compression="lzw")
    assert not (tmp_path / "x.tif").exists()


def test_focus_geotiff_compression_option(small, tmp_path):
    from tests.conftest import run_cli

    r = run_cli("focus", small.raw, "-o", tmp_path / "slc.h5", "--range-window", "rect", "--looks-az", "2",
                "--geotiff", tmp_path / "z.tif", "--geotiff-compression", "zstd")
    assert r.exit_code == 0, r.stderr
    with rasterio.open(tmp_path / "z.tif") as z, rasterio.open(small.map_tif) as d:
        assert (z.profile["compress"], d.profile["compress"]) == ("zstd", "deflate")
        np.testing.assert_array_equal(z.read(), d.read())  # the same pixels as the default's
    r = run_cli("focus", small.raw, "-o", tmp_path / "slc2.h5", "--geotiff", tmp_path / "x.tif",
                "--geotiff-compression", "lzw")
    assert r.exit_code == 2 and "GeoTIFF compression must be one of deflate, zstd, none" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "slc2.h5").exists()


def test_the_slc_is_hashed_once_beside_the_quicklook(small, tmp_path, monkeypatch):
    """The GeoTIFFs' INPUTS tag hashes the SLC just written: once, on the hashing thread while the
    quicklook is drawn; both GeoTIFFs then find it in sha256_file's table."""
    import os
    import threading

    from sarcli.io import h5common
    from tests.conftest import run_cli

    reads = []
    real_open = open

    def counting_open(path, mode="r", *a, **k):
        if "b" in mode and "slc" in os.fspath(path):
            reads.append(threading.current_thread().name)
        return real_open(path, mode, *a, **k)

    monkeypatch.setattr(h5common, "open", counting_open, raising=False)
    r = run_cli("focus", small.raw, "-o", tmp_path / "slc.h5", "--range-window", "rect", "--looks-az", "2",
                "--geotiff", tmp_path / "m.tif", "--geotiff-slant", tmp_path / "s.tif", "--quicklook",
                tmp_path / "q.png")
    assert r.exit_code == 0, r.stderr
    assert len(reads) == 1 and reads[0].startswith("sarcli-sha256"), reads
    with rasterio.open(tmp_path / "m.tif") as d:
        slc = tmp_path / "slc.h5"
        assert json.loads(d.tags()["INPUTS"]) == [{"path": str(slc), "sha256": _sha(slc)}]


def test_focus_is_byte_identical_under_source_date_epoch(small, tmp_path, monkeypatch):
    """README: with SOURCE_DATE_EPOCH set, products are byte-identical between runs. focus twice: the SLC
    (no wall-clock timings stored then) and the GeoTIFF (whose INPUTS tag is the SLC's hash) are the same
    bytes; the timings are still reported (--json) and stored when SOURCE_DATE_EPOCH is unset."""
    import h5py

    from tests.conftest import run_cli

    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    runs = []
    for _ in range(2):  # the same command (the command line and the paths are part of the provenance)
        r = run_cli("focus", small.raw, "-o", tmp_path / "slc.h5", "--range-window", "rect", "--looks-az",
                    "2", "--geotiff", tmp_path / "amp.tif", "--json")
        assert r.exit_code == 0, r.stderr
        assert json.loads(r.stdout)["timings_s"]["total_s"] > 0
        runs.append({name: (tmp_path / name).read_bytes() for name in ("slc.h5", "amp.tif")})
        for name in runs[-1]:
            (tmp_path / name).unlink()
    for name in runs[0]:
        assert runs[0][name] == runs[1][name], name
    with h5py.File(small.slc) as f:  # focused without SOURCE_DATE_EPOCH: the focuser's timings are kept
        assert len(f["timings"].attrs) > 0 and all(v > 0 for v in f["timings"].attrs.values())
