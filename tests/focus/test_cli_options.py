"""``sarcli focus`` / ``sarcli quality``: bad options are refused in one line before any work, and the
--json report is honest (only the products written, one consistent set of timing keys)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

SCENE = Path(__file__).parent / "scenes" / "batch.toml"


def _one_line_error(r, needle: str) -> None:
    assert r.exit_code != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: ") and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr + r.stdout


@pytest.mark.parametrize("args, needle", [
    (["--looks-az", "0", "--quicklook", "q.png"], "--looks-az"),
    (["--looks-rg", "-2"], "--looks-rg"),
    (["--crs", "EPSG:99999"], "--crs 'EPSG:99999'"),
    (["--pixel-spacing", "-1"], "--pixel-spacing"),
    (["--pixel-spacing", "nan"], "--pixel-spacing"),
    (["--azimuth-bandwidth", "-5"], "--azimuth-bandwidth"),
    (["--range-band-fraction", "2"], "--range-band-fraction"),
    (["--range-band-fraction", "0"], "--range-band-fraction"),
])
def test_focus_bad_options_refused_before_any_work(cli, tmp_path, args, needle):
    # the raw product does not even exist: the option check must come first (no "no --doppler given"
    # line, no Doppler estimate, no focus), and nothing is written
    out = tmp_path / "x.h5"
    r = cli("focus", tmp_path / "missing.h5", "-o", out, *[a if a != "q.png" else str(tmp_path / a) for a in args])
    _one_line_error(r, needle)
    assert not out.exists() and not (tmp_path / "q.png").exists()


def test_focus_json_timings_and_products_honest(cli, tmp_path):
    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENE, "-o", raw).exit_code == 0
    r = cli("focus", raw, "-o", tmp_path / "slc.h5", "--fdc", "-6558", "--fr", "-1781", "--json")
    assert r.exit_code == 0, r.stderr
    rep = json.loads(r.stdout)
    assert rep["products"] == {"slc": str(tmp_path / "slc.h5")}  # nothing that was not requested
    t = rep["timings_s"]
    assert all(k.endswith("_s") for k in t), t
    assert "total" not in t and {"doppler_s", "focus_s", "statistics_and_products_s", "total_s"} <= set(t)
    # the command total covers the focus, the Doppler and the products
    assert t["total_s"] >= t["focus_s"] + t["doppler_s"] + t["statistics_and_products_s"] - 1e-6
    q = cli("quality", tmp_path / "slc.h5", "--at", "nan,nan")
    _one_line_error(q, "finite")
    q = cli("quality", tmp_path / "slc.h5", "--at", "1,inf")
    _one_line_error(q, "finite")


def test_focus_missing_output_folders_refused_before_any_work(cli, tmp_path):
    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENE, "-o", raw).exit_code == 0
    for opt in ("--quicklook", "--geotiff-slant", "-o"):
        out = ["-o", tmp_path / "slc.h5"] if opt != "-o" else []
        r = cli("focus", raw, *out, opt, tmp_path / "nope" / "x", "--fdc", "-6558", "--fr", "-1781")
        _one_line_error(r, "does not exist")
        assert not (tmp_path / "slc.h5").exists()  # no SLC left behind by a late failure


def test_focus_and_doppler_say_where_their_centroids_hold(cli, tmp_path):
    """doppler reports the scene centre's range; focus the closest range of its mid-swath column and, for a
    given --fdc/--fr, the beam-centre range they are taken at: the two focus numbers differ from the given
    ones only by reading the model at R0 / cos(squint) (independently: fr ~ 1/R at a constant V)."""
    import re

    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENE, "-o", raw).exit_code == 0
    r = cli("doppler", raw, "--json")
    assert r.exit_code == 0, r.stderr
    scene_range = json.loads(r.stdout)["scene_range_m"]
    r = cli("doppler", raw)
    assert re.search(rf"fdc -?\d+\.\d\d Hz at the scene centre \(R = {scene_range:.0f} m\) = baseband",
                     r.stdout + r.stderr)
    r = cli("focus", raw, "-o", tmp_path / "slc.h5", "--fdc", "-6558", "--fr", "-1781", "--json")
    assert r.exit_code == 0, r.stderr
    du = json.loads(r.stdout)["doppler_used"]
    r = cli("focus", raw, "-o", tmp_path / "slc.h5", "--fdc", "-6558", "--fr", "-1781")
    line = next(x for x in r.stderr.splitlines() if x.startswith("focused "))
    assert "given:" not in line and "::" not in line
    m = re.search(r"beam-centre range (\d+) m, mid-swath\); used at the closest range (\d+) m", line)
    assert m, line
    r_beam, r0 = float(m.group(1)), du["range_m_mid"]
    assert abs(r0 - float(m.group(2))) <= 0.5
    # fdc = -2 V s / lam, fr = -2 V^2 (1 - s^2) / (lam R) through (fdc, fr) at r_beam: V^2 = -fr lam R / 2 +
    # (fdc lam / 2)^2, s = -fdc lam / (2 V), constant in range; the focuser reads the model at Rc = R0 / cos
    lam = 299792458.0 / 5.3e9
    v = np.sqrt(1781 * lam * r_beam / 2 + (6558 * lam / 2) ** 2)
    s = 6558 * lam / (2 * v)
    rc = r0 / np.sqrt(1 - s * s)
    assert du["fdc_hz_mid"] == pytest.approx(-6558, abs=1e-6)
    # r_beam is printed to 1 m (0.5 m: 5e-7 relative)
    assert du["fr_hz_per_s_mid"] == pytest.approx(-1781 * r_beam / rc, rel=1e-6)
