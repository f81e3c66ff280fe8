"""`sarcli doppler` end to end on a small simulated scene, the doppler.h5 round trip, bad inputs."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from sarcli.doppler.api import estimate_doppler
from sarcli.doppler.options import DopplerOptions
from sarcli.io.doppler_product import read_doppler
from sarcli.io.h5common import to_jsonable
from sarcli.io.raw import write_raw

JSON_KEYS = {"prf_hz", "fdc_baseband_hz", "ambiguity", "ambiguity_source", "ambiguity_confidence", "fdc_hz",
             "fr_hz_per_s", "blocks"}
BLOCK_KEYS = {"range_m", "azimuth_time_s", "fdc_baseband_hz", "quality", "ambiguity", "fdc_hz", "fr_hz_per_s"}


@pytest.fixture(scope="module")
def raw_file(tmp_path_factory, clutter_raw):
    p = tmp_path_factory.mktemp("dop") / "raw.h5"
    write_raw(p, clutter_raw)
    return p


def test_cli_json_product_and_plot(cli, raw_file, tmp_path, clutter_raw):
    out, png = tmp_path / "doppler.h5", tmp_path / "doppler.png"
    r = cli("doppler", raw_file, "--json", "-o", out, "--plot", png, "--az-block", "512", "--rg-block", "96")
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    assert JSON_KEYS <= set(d)
    assert d["ambiguity_source"] == "orbit" and 0.0 <= d["ambiguity_confidence"] <= 1.0
    assert len(d["blocks"]) == 4 and BLOCK_KEYS <= set(d["blocks"][0])
    assert d["fdc_hz"] == pytest.approx(d["fdc_baseband_hz"] + d["ambiguity"] * d["prf_hz"], abs=0.1 * d["prf_hz"])
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    m = read_doppler(out)
    ref = estimate_doppler(clutter_raw, DopplerOptions(az_block=512, rg_block=96))
    rho = clutter_raw.slant_range()
    t = np.linspace(clutter_raw.azimuth_time[0], clutter_raw.azimuth_time[-1], rho.size)
    np.testing.assert_allclose(m.fdc(rho, t), ref.fdc(rho, t), rtol=0, atol=1e-9)
    np.testing.assert_allclose(m.fr(rho, t), ref.fr(rho, t), rtol=1e-14)
    assert m.summary.ambiguity == d["ambiguity"] and m.parameters["options"]["az_block"] == 512
    assert m.ambiguity_resolved and m.parameters["height_m"] == 0.0
    assert to_jsonable(m.summary.to_dict()) == {k: v for k, v in d.items() if k not in ("output", "warnings", "blocks")}
    np.testing.assert_array_equal(m.blocks["ambiguity"], [b["ambiguity"] for b in d["blocks"]])
    assert m.blocks["valid"].dtype == bool
    h = cli("doppler", "--help")
    assert "Examples:" in h.stdout


def test_cli_human_summary_on_stderr(cli, raw_file):
    r = cli("doppler", raw_file, "--az-block", "512", "--rg-block", "96")
    assert r.exit_code == 0 and r.stdout == ""
    assert "fdc" in r.stderr and "ambiguity" not in r.stdout


def test_cli_bad_inputs_one_line_errors(cli, tmp_path, clutter_raw, raw_file):
    r = cli("doppler", tmp_path / "missing.h5")
    assert r.exit_code != 0 and r.stderr.startswith("sarcli: error:") and len(r.stderr.strip().splitlines()) == 1
    bad = clutter_raw.echo.copy()
    bad[5, 5] = np.nan
    p = tmp_path / "nan.h5"
    write_raw(p, dataclasses.replace(clutter_raw, echo=bad))
    r = cli("doppler", p)
    assert r.exit_code != 0 and "NaN" in r.stderr and "Traceback" not in r.stderr
    r = cli("doppler", raw_file, "--estimator", "bogus")
    assert r.exit_code == 2 and "unknown Doppler centroid estimator 'bogus'" in r.stderr
    r = cli("doppler", raw_file, "--fit-degree", "x")
    assert r.exit_code != 0 and "--fit-degree" in r.stderr
    zero = tmp_path / "zero.h5"
    write_raw(zero, dataclasses.replace(clutter_raw, echo=np.zeros_like(clutter_raw.echo)))
    r = cli("doppler", zero)
    assert r.exit_code != 0 and "usable Doppler signal" in r.stderr


def test_read_doppler_refuses_other_products(tmp_path, raw_file):
    from sarcli.errors import ProductError

    with pytest.raises(ProductError, match="expected doppler"):
        read_doppler(raw_file)


def test_cli_on_the_real_vancouver_block(cli, shared_data, tmp_path):
    """Real RADARSAT-1 echoes, no orbit: data-only ambiguity -6 (published centroid ~ -7050 Hz), an
    honest confidence, and a map-drift rate consistent with the published Vr = 7062 m/s (+-1 %)."""
    raw = tmp_path / "van.h5"
    r = cli("ingest", "--matlab", shared_data / "rs1_vancouver_block1.mat",
            "--params", shared_data / "rs1_vancouver_run_params.mat", "-o", raw)
    assert r.exit_code == 0, r.stderr
    r = cli("doppler", raw, "--az-block", "1536", "--json")
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["fdc_baseband_hz"] == pytest.approx(487.0, abs=5.0)
    assert d["ambiguity"] == -6 and d["ambiguity_source"] == "data" and d["ambiguity_resolved"] is True
    assert 0.3 < d["ambiguity_confidence"] < 0.9  # MLBF and MLCC disagree: not a certainty
    assert d["fr_method"] == "mapdrift"
    lam = 2.9979e8 / 5.3e9
    fr_pub = -2 * 7062.0**2 / (lam * d["scene_range_m"])
    assert d["fr_hz_per_s"] == pytest.approx(fr_pub, rel=0.01)
    # one effective velocity for the swath: |fr| falls as 1/R from near to far range (a free slope over
    # the four map-drift segments had the wrong sign here), Vr reported with its uncertainty
    md = d["fr_info"]["mapdrift"]
    assert md["velocity_mps"] == pytest.approx(7062.0, rel=0.01) and 0 < md["velocity_sigma_mps"] < 70.0
    r_b = np.array([b["range_m"] for b in d["blocks"]])
    fr_b = np.array([b["fr_hz_per_s"] for b in d["blocks"]])
    np.testing.assert_allclose(fr_b * r_b, -2 * md["velocity_mps"] ** 2 / lam, rtol=1e-4)
    assert np.ptp(r_b) > 8e3 and np.all(np.diff(np.abs(fr_b)[np.argsort(r_b)]) < 0)
