"""``sarcli orbit interpolate`` output for people: --csv gives a one-line summary instead of the rows,
the table carries the acceleration its help promises, extrapolated times are named."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.orbit.test_cli import _product


@pytest.fixture(scope="module")
def product(tmp_path_factory, polar_truth):
    return _product(tmp_path_factory.mktemp("orbit_cli_out") / "raw.h5", polar_truth)


def test_csv_prints_one_summary_line(cli, product, tmp_path):
    csv = tmp_path / "o.csv"
    r = cli("orbit", "interpolate", product, "-t", "0:6000:60", "--csv", csv)
    assert r.exit_code == 0, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"wrote {csv}: 101 row(s)"), lines
    assert np.loadtxt(csv, delimiter=",", skiprows=1).shape == (101, 10)


def test_table_has_acceleration_matching_gravity(cli, product, polar_truth):
    r = cli("orbit", "interpolate", product, "-t", "480,960")
    assert r.exit_code == 0, r.stderr
    lines = r.stdout.strip().splitlines()
    head = lines[1].split()
    assert head[-3:] == ["ax_mps2", "ay_mps2", "az_mps2"]
    rows = np.array([[float(x) for x in ln.split()] for ln in lines[2:]])
    assert rows.shape == (2, 10)
    # ECI acceleration of a 798 km orbit: central gravity GM / r^2 = 7.76 m/s^2 towards the centre (J2 < 0.2 %)
    r_vec, a_vec = rows[:, 1:4], rows[:, 7:10]
    g = 3.986004418e14 / np.sum(r_vec**2, 1)
    assert np.allclose(np.linalg.norm(a_vec, axis=1), g, rtol=3e-3)
    cosang = np.sum(r_vec * a_vec, 1) / np.linalg.norm(r_vec, axis=1) / np.linalg.norm(a_vec, axis=1)
    assert np.all(cosang < -0.999)


def test_extrapolated_times_are_named(cli, product):
    r = cli("orbit", "interpolate", product, "--times", "-30,100,6800", "--extrapolate", "100", "--json")
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["extrapolated_time_s"] == [-30.0, 6800.0] and d["span_s"] == [0.0, 6720.0]
    warn = [ln for ln in r.stderr.splitlines() if "extrapolated" in ln]
    assert len(warn) == 1 and "2 of 3" in warn[0] and "-30.000000" in warn[0] and "6800.000000" in warn[0]
    r = cli("orbit", "interpolate", product, "--times", "100", "--json")
    assert json.loads(r.stdout)["extrapolated_time_s"] == [] and "extrapolated" not in r.stderr
