"""A real Radarsat-1 block in relative sigma0: the product has no antenna description and no absolute
calibration, so the radiometry applies what it can (processing gain, range spreading loss) and says, in
the product, on stderr and in the GeoTIFF's tags, which terms it could not apply."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.slow
def test_block_in_relative_sigma0_names_the_terms_not_applied(rs1_pass, cli, tmp_path):
    import rasterio

    from sarcli.io.slc import read_slc

    data, params, line, cell = rs1_pass["blocks"]["block1"]
    raw = tmp_path / "raw.h5"
    extra = [] if line is None else ["--first-line", str(line), "--first-cell", str(cell)]
    r = cli("ingest", "--matlab", data, "--params", params, "--agc", rs1_pass["agc"], *extra, "-o", raw)
    assert r.exit_code == 0, r.stderr
    tif = tmp_path / "s0.tif"
    r = cli("focus", raw, "--fdc", "-6900", "--fr", "-1733", "-o", tmp_path / "slc.h5", "--geotiff-slant", tif,
            "--radiometry", "sigma0", "--looks-az", "4", "--looks-rg", "2")
    assert r.exit_code == 0, r.stderr
    for term in ("antenna elevation pattern", "antenna azimuth pattern", "absolute calibration constant K"):
        assert term in r.stderr
    cal = read_slc(tmp_path / "slc.h5", load_image=False).calibration
    assert any("antenna elevation pattern" in t for t in cal.not_applied)
    assert any(t.startswith("range spreading loss") for t in cal.applied)
    assert np.isnan(cal.nes0).all()  # no noise lines, no stated receiver noise: no noise floor claimed
    with rasterio.open(tif) as ds:
        tags = ds.tags()
        assert ds.units[1] == "dB" and tags["RADIOMETRY"] == "sigma0"
        assert "antenna elevation pattern" in tags["RADIOMETRY_NOT_APPLIED"]
        assert tags["NESZ_SIGMA0_DB_MEDIAN"] == "unknown"
        db = ds.read(2)
    # relative, but a backscatter image: finite inside the calibrated span, NaN (nodata) outside it
    assert 0.3 < np.isfinite(db).mean() < 1.0
    assert np.all(np.isnan(db[:, :2]))  # the near edge lacks part of the chirp
