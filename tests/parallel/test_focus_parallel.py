"""Focus in one pass: block-parallel focusing gives the single-process image bit for bit; the GeoTIFFs,
the quicklook and the statistics made from the stream equal those made from the SLC read back; the
SLC is chunked by whole lines; the input hashes are those of the files."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import h5py
import numpy as np
import pytest

SCENE = Path(__file__).parent / "scene_2048.toml"


@pytest.fixture(scope="module")
def raw(tmp_path_factory):
    from tests.conftest import run_cli

    out = tmp_path_factory.mktemp("pfocus") / "raw.h5"
    r = run_cli("simulate", SCENE, "-o", out)
    assert r.exit_code == 0, r.stderr
    return out


def _config(raw: Path, out: Path, tag: str, **kw):
    from sarcli.workflows.focus import Config

    return Config(raw=raw, output=out / f"{tag}.h5", geotiff=out / f"{tag}.tif", geotiff_slant=out / f"{tag}_sr.tif",
                  quicklook=out / f"{tag}.png", fdc=-6700.0, fr=-1990.0, looks_az=3, looks_rg=2,
                  options={"block_lines": 1024}, **kw)


@pytest.mark.slow
def test_block_parallel_focus_is_the_single_process_focus(raw, tmp_path):
    from distributed import LocalCluster

    from sarcli.workflows.focus import run

    one = run(_config(raw, tmp_path, "one"))
    assert one.parameters["n_blocks"] >= 3
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
                      dashboard_address=None) as cluster:
        par = run(_config(raw, tmp_path, "par", scheduler=cluster.scheduler_address))
    with h5py.File(tmp_path / "one.h5") as a, h5py.File(tmp_path / "par.h5") as b:
        np.testing.assert_array_equal(a["image"][()], b["image"][()])
        assert json.loads(a.attrs["parameters"])["config"] == {
            **json.loads(b.attrs["parameters"])["config"], "output": str(tmp_path / "one.h5"),
            "geotiff": str(tmp_path / "one.tif"), "geotiff_slant": str(tmp_path / "one_sr.tif"),
            "quicklook": str(tmp_path / "one.png")}  # where it ran is not stored
    assert par.image_statistics == one.image_statistics
    import rasterio

    for suffix in (".tif", "_sr.tif"):
        with rasterio.open(tmp_path / f"one{suffix}") as a, rasterio.open(tmp_path / f"par{suffix}") as b:
            np.testing.assert_array_equal(a.read(), b.read())
    assert (tmp_path / "one.png").read_bytes() == (tmp_path / "par.png").read_bytes()


def test_products_from_the_stream_equal_products_from_the_slc_read_back(raw, tmp_path, monkeypatch):
    """The former two-pass products: the SLC read back whole, multilooked by the product writers."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")  # one creation time in both files' tags
    from sarcli.focus.geocode import write_map_geotiff, write_slant_geotiff
    from sarcli.focus.quality import image_statistics
    from sarcli.focus.quicklook import write_slc_quicklook
    from sarcli.io.dem import load_terrain
    from sarcli.io.slc import read_slc
    from sarcli.workflows.focus import run

    rep = run(_config(raw, tmp_path, "s"))
    slc = read_slc(tmp_path / "s.h5")
    terrain = load_terrain(0.0, None, None)
    tags = {"source_product": "s.h5", "algorithm": "rd", "doppler": rep.doppler_source}
    src = (tmp_path / "s.h5",)
    write_map_geotiff(tmp_path / "ref.tif", slc, 3, 2, None, None, tags, terrain, inputs=src)
    write_slant_geotiff(tmp_path / "ref_sr.tif", slc, 3, 2, tags, terrain, inputs=src)
    write_slc_quicklook(tmp_path / "ref.png", slc, 3, 2)
    assert (tmp_path / "ref.tif").read_bytes() == (tmp_path / "s.tif").read_bytes()
    assert (tmp_path / "ref_sr.tif").read_bytes() == (tmp_path / "s_sr.tif").read_bytes()
    assert (tmp_path / "ref.png").read_bytes() == (tmp_path / "s.png").read_bytes()
    a, b = slc.first_full_line, slc.last_full_line + 1
    ref = image_statistics(slc.image[a:b])
    assert rep.image_statistics["n_pixels"] == ref["n_pixels"]
    for k in ("contrast", "entropy"):  # the same float64 sums in another order: last bits only
        assert rep.image_statistics[k] == pytest.approx(ref[k], rel=1e-12)


def test_slc_chunks_are_whole_lines_and_inputs_are_hashed(raw, tmp_path):
    from sarcli.io.slc import CHUNK_BYTES, image_chunks
    from sarcli.workflows.focus import run

    run(_config(raw, tmp_path, "c"))
    with h5py.File(tmp_path / "c.h5") as f:
        n, m = f["image"].shape
        rows, cols = f["image"].chunks
        assert cols == m and rows * m * 8 <= CHUNK_BYTES and (rows + 1) * m * 8 > CHUNK_BYTES
        assert f["image"].id.get_storage_size() == n * m * 8 + (-n % rows) * m * 8  # no padding but the last chunk
        inputs = json.loads(f.attrs["inputs"])
    assert inputs == [{"path": "raw.h5", "sha256": hashlib.sha256(raw.read_bytes()).hexdigest()}]
    assert image_chunks((6354 * 0 + 23000, 6354)) == (20, 6354)  # 6354-sample lines: 20 lines of 50.8 kB


def test_a_geotiff_written_in_strips_is_the_file_written_whole(tmp_path):
    from rasterio.transform import Affine

    from sarcli.io.images import Band, Strips, amplitude_db, write_geotiff

    rng = np.random.default_rng(2)
    a = np.abs(rng.standard_normal((1300, 700))).astype(np.float32)
    a[rng.random(a.shape) < 0.05] = np.nan
    t = Affine(10.0, 0.0, 500000.0, 0.0, -10.0, 5400000.0)

    def bands(data):  # two bands of one source (the amplitude and its dB), as the focus GeoTIFFs have
        return [Band(data, "amplitude", "1", "power"),
                Band(data, "dB", "dB", "power_db", derive=lambda x: amplitude_db(x, floor_db=None))]

    write_geotiff(tmp_path / "whole.tif", bands(a), "EPSG:32610", transform=t, tags={"k": "v"})
    strips = Strips(a.shape, lambda: ((r, a[r:r + 512]) for r in range(0, a.shape[0], 512)))
    write_geotiff(tmp_path / "strips.tif", bands(strips), "EPSG:32610", transform=t, tags={"k": "v"})
    assert (tmp_path / "whole.tif").read_bytes() == (tmp_path / "strips.tif").read_bytes()
