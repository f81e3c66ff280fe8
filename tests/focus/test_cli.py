"""End-to-end CLI: simulate -> focus -> GeoTIFFs + quicklook -> quality.

The geocoded product is checked against the simulator's truth (lat/lon of each target): the amplitude
peak in the map-projected GeoTIFF must be within one pixel of where the truth projects.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from .theory import irf_theory

SCENES = Path(__file__).parent / "scenes"


def _peak_near(a: np.ndarray, row: float, col: float, r: int = 3) -> tuple[float, float]:
    i, j = int(round(row)), int(round(col))
    w = a[i - r:i + r + 1, j - r:j + r + 1]
    ii, jj = np.unravel_index(np.nanargmax(w), w.shape)
    pi, pj = i - r + ii, j - r + jj

    def par(m, c, p):
        return 0.5 * (m - p) / (m - 2 * c + p)

    return pi + par(a[pi - 1, pj], a[pi, pj], a[pi + 1, pj]), pj + par(a[pi, pj - 1], a[pi, pj], a[pi, pj + 1])


@pytest.mark.slow
def test_simulate_focus_geocode_quality(cli, tmp_path):
    import rasterio
    from pyproj import Transformer

    from sarcli.io.raw import read_raw

    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENES / "e2e.toml", "-o", raw).exit_code == 0
    truth = read_raw(raw, load_echo=False).truth
    # the accuracy bars with the true centroid and rate at mid-swath (the estimated Doppler: test_batch)
    fdc_true = truth["doppler_centroid_hz"]
    mid = fdc_true.size // 2
    r = cli("focus", raw, "-o", tmp_path / "slc.h5", "--range-window", "rect",
            "--fdc", str(fdc_true[mid]), "--fr", str(truth["doppler_rate_hz_per_s"][mid]),
            "--geotiff", tmp_path / "amp.tif", "--geotiff-slant", tmp_path / "sr.tif",
            "--quicklook", tmp_path / "q.png")
    assert r.exit_code == 0, r.stderr
    assert (tmp_path / "q.png").stat().st_size > 1000

    q = cli("quality", tmp_path / "slc.h5", "--json")
    assert q.exit_code == 0, q.stderr
    res = json.loads(q.stdout)
    assert len(res) == 2
    c, fs = 299792458.0, 32317075.0
    dr = c / (2 * fs)
    for m in res:
        assert set(m) >= {"range_m", "azimuth_time_s", "irw_range_m", "irw_azimuth_m", "pslr_range_db",
                          "pslr_azimuth_db", "islr_range_db", "islr_azimuth_db", "position_error_m"}
        # rect range window: IRW 0.886 c / (2B), PSLR -13.26 dB (B = 0.72135e12 x 41.74e-6)
        assert m["irw_range_m"] == pytest.approx(0.886 * c / (2 * 0.72135e12 * 41.74e-6), rel=0.05)
        assert abs(m["pslr_range_db"] + 13.26) < 0.3
        assert abs(m["islr_range_db"] - irf_theory("rect")["islr_db"]) < 0.3
        assert m["position_error_m"] < 0.1 * dr

    with rasterio.open(tmp_path / "amp.tif") as ds:
        amp = ds.read(1)
        tr, crs, res_m = ds.transform, ds.crs, ds.res[0]
        assert ds.crs.to_epsg() == 32610 and ds.overviews(1) and ds.profile["tiled"] and np.isnan(ds.nodata)
    with rasterio.open(tmp_path / "sr.tif") as ds:
        gcps, gcrs = ds.gcps
        assert len(gcps) >= 4 and gcrs.to_epsg() == 4326
    to_map = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
    for tg in truth["targets"]:
        x, y = to_map.transform(tg["lon_deg"], tg["lat_deg"])
        col, row = ~tr * (x, y)
        pr, pc = _peak_near(amp, row - 0.5, col - 0.5)
        assert np.hypot(pr - (row - 0.5), pc - (col - 0.5)) < 1.0, (res_m, pr, row, pc, col)


def test_focus_refuses_bad_input_in_one_line(cli, tmp_path):
    r = cli("focus", tmp_path / "missing.h5", "-o", tmp_path / "slc.h5")
    assert r.exit_code != 0 and r.stderr.startswith("sarcli: error:") and len(r.stderr.strip().splitlines()) == 1
    r = cli("focus", tmp_path / "missing.h5", "-o", tmp_path / "slc.h5", "--rcmc", "cubic")
    assert r.exit_code != 0 and "interpolator" in r.stderr
    r = cli("quality", tmp_path / "missing.h5")
    assert r.exit_code != 0 and r.stderr.startswith("sarcli: error:")
    # a product without an Earth orbit cannot be geocoded: refused before any work
    from sarcli.io.raw import write_raw

    from .synth import scene

    write_raw(tmp_path / "flat.h5", scene([], n_lines=64, n_samples=600))
    r = cli("focus", tmp_path / "flat.h5", "-o", tmp_path / "slc.h5", "--fdc", "0", "--fr", "-2000",
            "--geotiff", tmp_path / "a.tif")
    assert r.exit_code != 0 and "Earth orbit" in r.stderr and not (tmp_path / "slc.h5").exists()
    r = cli("focus", tmp_path / "flat.h5", "-o", tmp_path / "slc.h5", "--fdc", "0", "--fr", "2000")
    assert r.exit_code != 0 and "negative" in r.stderr
