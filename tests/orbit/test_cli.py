"""``sarcli orbit info|interpolate|accuracy`` end to end on small raw products made here."""

from __future__ import annotations

import json

import numpy as np
import pytest

from orbit.frames import eci_to_ecef
from sarcli.io.raw import write_raw
from sarcli.model.raw import Orbit, Radar, RawProduct
from tests.orbit.truth import EPOCH, SPACING


def _product(path, truth, frame="ECI", orbit=True, t_shift=3000.0, extra=None):
    sv = truth.sv
    radar = Radar(carrier_frequency_hz=5.3e9, wavelength_m=0.05656, prf_hz=1256.98, range_sampling_rate_hz=32.317e6,
                  chirp_rate_hz_per_s=-7.2135e11, pulse_length_s=41.74e-6, window_start_s=6.5956e-3,
                  first_range_m=988_647.46)
    o = Orbit(sv.time, sv.position, sv.velocity, frame) if orbit else None
    raw = RawProduct(echo=np.zeros((16, 24), np.complex64), azimuth_time=t_shift + np.arange(16) / 1256.98,
                     epoch_utc=EPOCH, radar=radar, orbit=o, extra_attrs=extra or {})
    write_raw(path, raw)
    return path


@pytest.fixture(scope="module")
def product(tmp_path_factory, polar_truth):
    return _product(tmp_path_factory.mktemp("orbit_cli") / "raw.h5", polar_truth)


def test_info_json(cli, product, polar_truth):
    r = cli("orbit", "info", product, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["frame"] == "ECI" and s["n_vectors"] == 15 and s["spacing_s"] == SPACING
    assert s["echo_covered"] and s["margin_before_s"] == pytest.approx(3000.0)
    assert s["default_n_nodes"] == 10
    g = s["geometry"]
    assert 780e3 < g["altitude_m"] < 860e3 and g["pass"] in ("ascending", "descending")
    # slant range ~989 km from ~800 km altitude: look angle ~34-35 deg, incidence a few degrees larger
    assert 25 < g["look_angle_deg"][0] < 45 and g["incidence_angle_deg"][0] > g["look_angle_deg"][0]
    r = cli("orbit", "info", product)
    assert r.exit_code == 0 and "15 state vectors (ECI)" in r.stdout and "inside the span" in r.stdout


def test_interpolate_at_nodes_returns_the_vectors(cli, product, polar_truth, tmp_path):
    sv = polar_truth.sv
    r = cli("orbit", "interpolate", product, "--times", f"0,{SPACING}:{3 * SPACING}:{SPACING}", "--json")
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    p = np.stack([d["x_m"], d["y_m"], d["z_m"]], -1)
    assert np.abs(p - sv.position[:4]).max() < 1e-6 and d["frame"] == "ECI" and len(d["utc"]) == 4
    r = cli("orbit", "interpolate", product, "--times", "2002-06-16T15:49:00Z,1e3", "--json")
    assert json.loads(r.stdout)["time_s"] == [480.0, 1000.0]  # the epoch is 15:41:00
    csv = tmp_path / "o.csv"
    r = cli("orbit", "interpolate", product, "-t", "0,480", "--frame", "ecef", "--csv", csv, "--json")
    d = json.loads(r.stdout)
    pe = eci_to_ecef(EPOCH, sv.time[:2], sv.position[:2])
    assert np.abs(np.stack([d["x_m"], d["y_m"], d["z_m"]], -1) - pe).max() < 1e-6
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert csv.read_text().splitlines()[0].startswith("time_s,x_m,y_m,z_m,vx_mps")
    assert rows.shape == (2, 13) and np.abs(rows[:, 1:4] - pe).max() < 1e-6
    assert 780e3 < rows[0, 12] < 830e3  # geodetic height column


@pytest.mark.parametrize("args,match", [
    (["--times", "7300"], "outside the state-vector span [0.000000, 6720.000000] s (use --extrapolate"),
    (["--times", "7300", "--extrapolate", "100"], "+ 100 s allowed extrapolation"),
    (["--times", "abc"], "cannot read 'abc'"),
    (["--times", "2002-13-01T00:00:00Z"], "cannot read"),
    (["--times", "5:1:1"], "cannot read"),
    (["--times", "0", "--frame", "j2000"], "--frame must be"),
    (["--times", "0", "-n", "17"], "n_nodes must be in 2..16"),
])
def test_interpolate_errors_are_one_line(cli, product, args, match):
    r = cli("orbit", "interpolate", product, *args)
    assert r.exit_code != 0
    assert r.stderr.startswith("sarcli: error:") and match in r.stderr and r.stderr.count("\n") == 1
    assert "Traceback" not in r.stderr


def test_bounded_extrapolation_on_request(cli, product):
    r = cli("orbit", "interpolate", product, "--times", "6800", "--extrapolate", "100", "--json")
    assert r.exit_code == 0 and np.isfinite(json.loads(r.stdout)["x_m"][0])


def test_products_without_or_with_local_orbit(cli, tmp_path, polar_truth):
    no = _product(tmp_path / "no.h5", polar_truth, orbit=False)
    r = cli("orbit", "info", no)
    assert r.exit_code != 0 and "no /orbit" in r.stderr
    loc = _product(tmp_path / "loc.h5", polar_truth, frame="LOCAL")
    r = cli("orbit", "info", loc, "--json")
    assert r.exit_code == 0 and "geometry" not in json.loads(r.stdout)
    r = cli("orbit", "interpolate", loc, "--times", "0", "--frame", "ecef")
    assert r.exit_code != 0 and "LOCAL" in r.stderr and r.stderr.count("\n") == 1
    out = _product(tmp_path / "late.h5", polar_truth, t_shift=7000.0)
    r = cli("orbit", "info", out)
    assert r.exit_code == 0 and "NOT inside" in r.stdout


def test_accuracy_table_and_plot(cli, tmp_path):
    png = tmp_path / "acc.png"
    r = cli("orbit", "accuracy", "--no-timing", "--json", "--plot", png)
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    by_n = {row["n_nodes"]: row for row in d["hermite"]}
    assert set(by_n) == {2, 4, 6, 8, 10, 12}
    assert by_n[10]["pos_err_interior_m"] < 1e-3 and by_n[10]["vel_err_interior_mps"] < 1e-6
    # the error falls with N until the truth floor
    assert by_n[2]["pos_err_interior_m"] > by_n[4]["pos_err_interior_m"] > by_n[6]["pos_err_interior_m"]
    assert [a["scale"] for a in d["attitude"]] == [0.0, 1.0, 10.0, 100.0]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_info_reports_the_ceos_hour_angle_check(cli, tmp_path, polar_truth):
    p = _product(tmp_path / "gha.h5", polar_truth, extra={"ceos_gha_minus_gmst_deg": 0.001})
    r = cli("orbit", "info", p, "--json")
    s = json.loads(r.stdout)
    assert s["gha_minus_gmst_deg"] == 0.001 and s["gha_minus_gmst_ground_m"] == pytest.approx(111.3, abs=0.1)
    assert "frame check" in cli("orbit", "info", p).stdout
