"""Configuration checks, CLI refusals, the alarm hook inside a campaign, and the DEM's pixel heights."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.errors import ConfigError
from sarcli.monitor.config import load_monitor_config, parse_monitor_config
from tests.monitor.conftest import MONITOR


def test_sample_config_and_refusals(tmp_path):
    cfg = load_monitor_config(MONITOR)
    assert [a.name for a in cfg.areas] == ["stable-low", "stable-high", "creep", "slide"]
    assert cfg.acquisition["vna"]["points"] == 401
    with pytest.raises(ConfigError, match="unknown option"):
        parse_monitor_config({"velocity": {"window": 3}})
    with pytest.raises(ConfigError, match="increasing"):
        parse_monitor_config({"areas": [{"name": "a", "polygon": [[0, 0], [1, 0], [1, 1]],
                                         "velocity_mm_per_h": [2.0, 1.0, 3.0]}]})
    with pytest.raises(ConfigError, match="distinct"):
        parse_monitor_config({"watch": [{"name": "x", "x_m": 0, "y_m": 10}],
                              "areas": [{"name": "x", "polygon": [[0, 0], [1, 0], [1, 1]]}]})
    with pytest.raises(ConfigError, match="commas"):
        parse_monitor_config({"watch": [{"name": "a,b", "x_m": 0, "y_m": 10}]})
    scan_only = tmp_path / "scan.toml"
    scan_only.write_text("[vna]\npoints = 201\n")
    assert load_monitor_config(scan_only).acquisition == {"vna": {"points": 201}}


def test_monitor_cli_refusals(cli, tmp_path):
    r = cli("gbsar", "monitor", "--out", tmp_path / "c")
    assert r.exit_code == 2 and "needs -c" in r.stderr
    r = cli("gbsar", "monitor", "--out", tmp_path / "c", "-c", MONITOR, "--time-scale", "2")
    assert r.exit_code == 2 and "--time-scale" in r.stderr
    r = cli("gbsar", "monitor", "--out", tmp_path / "c", "-c", MONITOR, "--start-utc", "yesterday")
    assert r.exit_code == 2 and "ISO-8601" in r.stderr
    r = cli("gbsar", "monitor", "--out", tmp_path / "c", "-c", MONITOR, "--count", "2")
    assert r.exit_code == 2 and "--port and --rail-port" in r.stderr
    other = tmp_path / "other.toml"
    other.write_text(MONITOR.read_text().replace("refresh_s = 60", "refresh_s = 30"))
    r = cli("gbsar", "monitor", "--out", tmp_path / "c", "-c", other, "--count", "2")
    assert r.exit_code == 2 and "another config" in r.stderr


def test_a_failing_hook_is_logged_and_the_campaign_goes_on(offline_campaign, tmp_path):
    from sarcli.workflows import gbsar_series

    cfg = tmp_path / "low.toml"
    cfg.write_text(MONITOR.read_text().replace("velocity_mm_per_h = [2.0, 4.0, 8.0]",
                                               "velocity_mm_per_h = [0.15, 5.0, 9.0]"))
    scans = tuple(sorted((offline_campaign / "scans").glob("scan_*.h5"))[:5])
    rep = gbsar_series.run(gbsar_series.Config(inputs=scans, config=cfg, out=tmp_path / "o", jobs=1,
                                               on_alarm="echo no phone line >&2; exit 7"))
    assert rep.n_accepted == 5
    log = (tmp_path / "o" / "monitor.log").read_text()
    assert "ALARM slide: none -> attention at scan 3" in log
    assert "the --on-alarm hook failed for slide at scan 3: exit status 7: no phone line" in log


def test_dem_heights_under_the_pixels(offline_campaign, tmp_path):
    """A DEM of the sample's slope z = 0.3 (y - 100) in the site's east/north frame: the height found
    under each pixel satisfies R0^2 = y^2 + (z - h)^2 with z = 0.3 (y - 100)."""
    import rasterio
    from rasterio.transform import from_origin

    from sarcli.gbsar.geocode import enu_crs, rail_axes
    from sarcli.io.scan import read_scan
    from sarcli.monitor.campaign import focus
    from sarcli.monitor.geometry import pixel_heights

    cfg = load_monitor_config(MONITOR)
    img = focus(read_scan(offline_campaign / "scans" / "scan_00001.h5"), cfg)
    a, look = rail_axes(img.site)
    e0, n0, px = -400.0, 400.0, 0.5
    ee, nn = np.meshgrid(e0 + px * (np.arange(1600) + 0.5), n0 - px * (np.arange(1600) + 0.5))
    y = ee * look[0] + nn * look[1]
    z = np.maximum(0.3 * (y - 100.0), 0.0).astype(np.float32)
    dem = tmp_path / "dem.tif"
    with rasterio.open(dem, "w", driver="GTiff", width=1600, height=1600, count=1, dtype="float32",
                       crs=enu_crs(img.site), transform=from_origin(e0, n0, px, px)) as ds:
        ds.write(z, 1)
    h = pixel_heights(dem, img)
    r0 = img.range_m[:, None] * np.ones((1, img.azimuth_m.size))
    ok = np.isfinite(h) & (r0 > 110)
    assert ok.mean() > 0.9
    y_pix = np.sqrt(r0[ok] ** 2 - (img.rail_height_m - h[ok]) ** 2)
    # nearest DEM cell: 0.5 m cells on a 0.3 slope -> 0.15 m in z (+ the iteration's residual)
    np.testing.assert_allclose(h[ok], 0.3 * (y_pix - 100.0), atol=0.2)
