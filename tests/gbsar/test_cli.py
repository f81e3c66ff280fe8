"""End-to-end `sarcli gbsar` commands on small simulated scans."""

from __future__ import annotations

import csv
import json

import h5py
import numpy as np
import pytest

from sarcli.io.gbsar_image import read_gbsar_image
from sarcli.io.interferogram import read_interferogram, read_ps

SCENE = """
[scene]
name = "tiny"
seed = {seed}
epoch_utc = "2024-05-01T10:{minute:02d}:00Z"
[sweep]
center_frequency_hz = 5.3e9
bandwidth_hz = 200e6
points = 201
polarizations = ["VV", "HH"]
[rail]
length_m = 1.0
step_m = 0.05
height_m = 2.0
[site]
latitude_deg = 37.87
longitude_deg = 127.74
heading_deg = 60.0
[[points]]
x_m = 0.0
y_m = 30.0
los_displacement_mm = 1.0
scattering = {{ VV = 1.0, HH = 0.5 }}
[[points]]
x_m = 3.0
y_m = 45.0
scattering = 0.3
[effects.noise]
power_db = -60.0
{extra}
"""


def _scene(tmp_path, name, seed=1, minute=0, extra=""):
    p = tmp_path / f"{name}.toml"
    p.write_text(SCENE.format(seed=seed, minute=minute, extra=extra))
    return p


def _scan(cli, tmp_path, name, **kw):
    out = tmp_path / f"{name}.h5"
    r = cli("gbsar", "simulate", _scene(tmp_path, name, **kw), "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    return out


def test_simulate_focus_geocode(cli, tmp_path):
    scan = _scan(cli, tmp_path, "a")
    img, tif, enu, png = (tmp_path / n for n in ("img.h5", "img.tif", "enu.tif", "img.png"))
    r = cli("gbsar", "focus", scan, "-o", img, "--geotiff", tif, "--enu-geotiff", enu, "--quicklook", png, "--json")
    assert r.exit_code == 0, r.stderr
    rep = json.loads(r.stdout)
    assert rep["algorithm"] == "auto" and set(rep["used"]) == {"bp", "df"}
    assert rep["utm_geotiff"]["crs"] == "EPSG:32652" and rep["utm_geotiff"]["enu_to_utm_residual_m"] < 0.01
    im = read_gbsar_image(img)
    assert im.polarizations == ("VV", "HH") and np.all(np.isfinite(im.image))
    i, j = np.unravel_index(np.argmax(np.abs(im.image[0])), im.image[0].shape)
    assert abs(im.range_m[i] - np.hypot(30.0, 2.0)) < 0.6 and abs(im.azimuth_m[j]) <= 0.3
    import rasterio

    with rasterio.open(tif) as ds:
        assert ds.crs.to_epsg() == 32652 and ds.count == 1
        a = ds.read(1)
        # the target's UTM position: brightest map pixel within 2 pixels of the pyproj-projected truth
        from pyproj import Transformer

        from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef
        lat, lon = np.radians(37.87), np.radians(127.74)
        hd = np.radians(60.0)
        e, n = 30.0 * np.cos(hd), -30.0 * np.sin(hd)  # 30 m to the right of a rail heading 060
        east = np.array([-np.sin(lon), np.cos(lon), 0.0])
        north = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
        p = np.asarray(geodetic_to_ecef(37.87, 127.74, 0.0)).reshape(3) + e * east + n * north
        la, lo, _ = ecef_to_geodetic(p[None, :])
        tx, ty = Transformer.from_crs("EPSG:4326", "EPSG:32652", always_xy=True).transform(lo[0], la[0])
        rr, cc = np.unravel_index(np.nanargmax(a), a.shape)
        px, py = ds.xy(rr, cc)
        assert np.hypot(px - tx, py - ty) < 2 * ds.res[0] + 0.3
    assert png.stat().st_size > 1000 and enu.stat().st_size > 0


def test_focus_each_algorithm_and_errors(cli, tmp_path):
    scan = _scan(cli, tmp_path, "a")
    for alg in ("df", "rd", "bp"):
        r = cli("gbsar", "focus", scan, "--algorithm", alg, "--max-range", "50", "-o", tmp_path / f"{alg}.h5")
        assert r.exit_code == 0, (alg, r.stderr)
    r = cli("gbsar", "focus", scan, "--algorithm", "magic", "-o", tmp_path / "x.h5")
    assert r.exit_code != 0 and r.stderr.startswith("sarcli: error:") and "Traceback" not in r.stderr
    r = cli("gbsar", "focus", tmp_path / "missing.h5", "-o", tmp_path / "x.h5")
    assert r.exit_code != 0 and "no such file" in r.stderr
    with h5py.File(scan, "r+") as f:  # one stop with a NaN sweep: flagged and skipped, reported
        d = f["s21"][()]
        d[0, 3, 10] = np.nan
        f["s21"][...] = d
    r = cli("gbsar", "focus", scan, "--algorithm", "bp", "--max-range", "50", "-o", tmp_path / "nan.h5", "--json")
    assert r.exit_code == 0 and json.loads(r.stdout)["skipped_stops"] == [3] and "skipped 1" in r.stderr


def test_interfere_dinsar_and_mismatch(cli, tmp_path):
    a = _scan(cli, tmp_path, "a")
    b = _scan(cli, tmp_path, "b", minute=30, extra="[effects.displacement]\nscale = 1.0\n")
    out, png, tif = tmp_path / "ifg.h5", tmp_path / "ifg.png", tmp_path / "ifg.tif"
    vtif = tmp_path / "los.tif"
    r = cli("-v", "gbsar", "interfere", a, b, "--mode", "dinsar", "-o", out, "--png", png, "--geotiff", tif,
            "--value-geotiff", vtif, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    # where the time went: the two scans focused on the fly, the interferogram, the product, the pictures
    t = s["timings_s"]
    assert set(t) == {"reference_s", "secondary_s", "interferogram_s", "product_s", "pictures_s", "total_s"}
    assert t["total_s"] >= sum(v for k, v in t.items() if k != "total_s") > 0
    for what in ("focused the reference", "focused the secondary", "interferogram", "wrote"):
        assert what in r.stderr, what  # -v: one diagnostic per stage
    assert s["rate"]["deg_per_m_los"] == pytest.approx(-12729, rel=0.001) and s["min_coherence"] == 0.5
    d = read_interferogram(out)
    i = int(np.argmin(abs(d["range"] - np.hypot(30.0, 2.0))))
    j = int(np.argmin(abs(d["azimuth"])))
    assert d["value"][i, j] == pytest.approx(1.0, abs=0.1)  # the 1 mm LOS displacement
    # outside the beam footprint |x| - X/2 > lam R0/(2 L_x) (default L_x 0.25 m, rail 1 m): NaN, not phase 0
    outside = np.abs(d["azimuth"])[None, :] - 0.5 > 299792458.0 / 5.3e9 * d["range"][:, None] / 0.5 + 1e-6
    assert outside.sum() > 100 and np.all(np.isnan(d["value"][outside])) and np.all(np.isnan(d["phase"][outside]))
    inner = (d["range"][:, None] > 3.0) & (d["range"][:, None] < d["range"][-1])  # DF does not cover R_max itself
    assert np.all(np.isfinite(d["phase"][~outside & inner]))
    assert s["supported_pixels"] == int(np.count_nonzero(np.isfinite(d["phase"])))
    import rasterio

    with rasterio.open(vtif) as ds:
        v = ds.read(1)
        # nodata outside; inside, a wrapped phase gives at most lam/4 of LOS displacement (14.1 mm)
        assert np.isnan(ds.nodata) and np.isnan(v).any() and np.isfinite(v).any()
        assert np.nanmax(np.abs(v)) <= 299792458.0 / 5.3e9 / 4 * 1e3
    assert png.stat().st_size > 1000 and tif.stat().st_size > 0
    other = tmp_path / "c.toml"
    other.write_text(SCENE.format(seed=1, minute=0, extra="").replace("points = 201", "points = 101"))
    c = tmp_path / "c.h5"
    assert cli("gbsar", "simulate", other, "-o", c).exit_code == 0
    r = cli("gbsar", "interfere", a, c, "--mode", "dinsar", "-o", tmp_path / "bad.h5")
    assert r.exit_code != 0 and "different frequency grids" in r.stderr and "Traceback" not in r.stderr


def test_coherence_ps_series_and_polarimetry(cli, tmp_path):
    scans = [_scan(cli, tmp_path, f"p{k}", seed=k, minute=10 * k) for k in range(1, 4)]
    out, csv_path, plot = tmp_path / "ps.h5", tmp_path / "ps.csv", tmp_path / "ps.png"
    r = cli("gbsar", "coherence", *scans, "--threshold", "0.99", "-o", out, "--csv", csv_path, "--plot", plot,
            "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["n_ps"] >= 2 and s["max_abs_phase_change_deg"] < 1.0
    assert s["time_s"][1] - s["time_s"][0] == pytest.approx(600.0)
    ps = read_ps(out)
    assert ps["ps_phase"].shape == (s["n_ps"], 3) and np.all(ps["ps_coherence"] >= 0.99)
    assert np.isnan(ps["coherence"]).any() and np.nanmin(ps["coherence"]) >= 0.0  # blank outside the footprint
    rows = list(csv.reader(csv_path.open()))
    assert rows[0][:4] == ["ps", "azimuth_m", "range_m", "coherence"] and len(rows) == s["n_ps"] + 1
    assert plot.stat().st_size > 1000
    r = cli("gbsar", "coherence", scans[0], scans[0], "-o", tmp_path / "same.h5", "--plot", tmp_path / "s.png",
            "--json")  # identical epochs: one warning line, the plot falls back to the scan index
    assert r.exit_code == 0 and json.loads(r.stdout)["plot_time_axis"] == "scan_index"
    assert r.stderr.count("warning:") == 1 and "scan index" in r.stderr
    high = _scan(cli, tmp_path, "high", seed=4, minute=40, extra="[effects.vertical_baseline]\noffset_m = 0.3\n")
    r = cli("gbsar", "coherence", scans[0], high, "-o", tmp_path / "bad.h5")
    assert r.exit_code != 0 and "Traceback" not in r.stderr
    assert "one geometry" in r.stderr and "interfere that pair with --mode crosstrack" in r.stderr
    r = cli("gbsar", "polarimetry", scans[0], "--png", tmp_path / "nd.png", "--json")
    assert r.exit_code == 0, r.stderr
    assert -1.0 <= json.loads(r.stdout)["mean"] <= 1.0


def test_help_has_examples(cli):
    for cmd in ("simulate", "plan", "focus", "interfere", "coherence", "polarimetry"):
        r = cli("gbsar", cmd, "--help")
        assert r.exit_code == 0 and "Examples:" in r.stdout, cmd


def test_simulate_warns_beyond_r_max(cli, tmp_path):
    p = _scene(tmp_path, "far", extra="[[points]]\nx_m = 0.0\ny_m = 80.0\n")  # R_max = 75 m here
    r = cli("gbsar", "simulate", p, "-o", tmp_path / "far.h5", "--json")
    assert r.exit_code == 0 and json.loads(r.stdout)["n_beyond_r_max"] == 1 and "fold back" in r.stderr
    r = cli("gbsar", "simulate", tmp_path / "nope.toml", "-o", tmp_path / "x.h5")
    assert r.exit_code != 0 and r.stderr.startswith("sarcli: error:")


def test_products_are_reproducible(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    blobs = []
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        scene = _scene(tmp_path / d, "s")
        assert cli("gbsar", "simulate", scene, "-o", tmp_path / d / "s.h5").exit_code == 0
        assert cli("gbsar", "focus", tmp_path / d / "s.h5", "-o", tmp_path / d / "i.h5").exit_code == 0
        blobs.append(((tmp_path / d / "s.h5").read_bytes(), (tmp_path / d / "i.h5").read_bytes()))
    assert blobs[0] == blobs[1]


def test_readme_examples_are_self_contained():
    """Every input of an example in the GB-SAR manual (docs/gbsar.md) is a shipped sample or made by an earlier line."""
    import re
    import shlex
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    text = (root / "docs" / "gbsar.md").read_text()
    made: set[str] = set()
    lines = [ln.split("#")[0].strip() for ln in re.findall(r"```sh\n(.*?)```", text, re.S)[0].splitlines()]
    assert sum(ln.startswith("sarcli gbsar") for ln in lines) >= 10
    for ln in filter(None, lines):
        words = shlex.split(ln)
        outs = {w for k, w in enumerate(words[1:], 1) if words[k - 1].startswith("-")}
        for w in words[3:]:
            if w.endswith(".toml"):
                assert (root / w).is_file(), (ln, w)
            elif w.endswith(".h5") and w not in outs:
                assert w in made, (ln, w)
        made |= {w for w in outs if w.endswith(".h5")}
