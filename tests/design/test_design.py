"""sarcli design: the worked example of [KimAODCCD], the relations against independent geometry, and the CLI."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from orbit.constants import C_LIGHT
from sarcli.design import relations as rel
from sarcli.design.params import load
from sarcli.design.report import evaluate

SAMPLES = Path(__file__).resolve().parents[2] / "samples"
SEED = SAMPLES / "aod_ccd_example.toml"


def test_seed_example_reproduced():
    r = evaluate(load(SEED))
    # Printed: range resolution 17.32 m, azimuth 38.53 m (the paper rounds c = 3e8 and lam = 0.03 m).
    assert r["ground_range_resolution_m"] == pytest.approx(17.32, rel=1e-3)
    assert r["slant_range_resolution_m"] == pytest.approx(15.0, rel=1e-3)
    assert r["azimuth_resolution_m"] == pytest.approx(38.53, rel=1e-3)
    assert [o["prf_hz"] for o in r["prf_options"]] == [15734.0, 3934.0, 1967.0]
    assert [o["doppler_samples"] for o in r["prf_options"]] == [490, 122, 61]
    assert r["slant_range_m"] == pytest.approx(10000.0)


def test_seed_example_flags_its_violation():
    """15734 Hz puts more than one pulse in flight at 10 km (c/(2 R) = 14.99 kHz at R = 10 km)."""
    r = evaluate(load(SEED))
    by_prf = {o["prf_hz"]: o for o in r["prf_options"]}
    bad = {c["name"] for c in by_prf[15734.0]["constraints"] if not c["ok"]}
    assert "range_unambiguous" in bad
    assert by_prf[3934.0]["ok"] and by_prf[1967.0]["ok"]
    assert not r["ok"]
    assert any("19.2" in n for n in r["notes"])  # broadside value stated next to the reading of [KimAODCCD]


def test_broadside_resolution_is_half_the_seeds_reading():
    r = evaluate(load(SEED))
    o = r["prf_options"][0]
    assert o["azimuth_resolution_broadside_m"] == pytest.approx(o["azimuth_resolution_m"] * math.sin(math.radians(30)))


def test_azimuth_resolution_equals_v_over_doppler_bandwidth_from_exact_geometry():
    """Independent route: Doppler at the two ends of the aperture from exact geometry, B_D = f1 - f0,
    resolution = v / B_D must equal lam R / (2 L) for a broadside aperture."""
    lam, R, L, v = 0.03, 10000.0, 7.786, 250.0
    y = np.array([-L / 2, L / 2])
    fd = -(2 / lam) * (-v * (0 - y) / np.sqrt(R**2 + y**2)) * -1  # d/dt |r| = v*y/|r| for platform at y
    bd = abs(fd[1] - fd[0])
    assert v / bd == pytest.approx(rel.azimuth_resolution(lam, R, L), rel=1e-6)


@settings(max_examples=60, deadline=None)
@given(h=st.floats(200e3, 1500e3), look=st.floats(1.0, 55.0))
def test_spherical_geometry_against_vector_construction(h, look):
    re = 6371000.0
    assume(look < math.degrees(math.asin(re / (re + h))) - 0.1)  # beyond the horizon: tested below
    g = math.radians(look)
    R, inc = rel.spherical_earth_geometry(h, g, re)
    sat = np.array([0.0, re + h])
    p = sat + R * np.array([math.sin(g), -math.cos(g)])  # ray from the satellite at angle g from nadir
    assert np.linalg.norm(p) == pytest.approx(re, rel=1e-12)
    normal = p / np.linalg.norm(p)
    los = (sat - p) / np.linalg.norm(sat - p)
    assert math.acos(normal @ los) == pytest.approx(inc, abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(h=st.floats(200e3, 1500e3), look=st.floats(1.0, 55.0))
def test_look_angle_for_slant_range_inverts_the_geometry(h, look):
    assume(look < math.degrees(math.asin(6371000.0 / (6371000.0 + h))) - 0.1)
    R, _ = rel.spherical_earth_geometry(h, math.radians(look))
    assert math.degrees(rel.look_angle_for_slant_range(h, R)) == pytest.approx(look, abs=1e-7)


def test_look_that_misses_the_earth():
    with pytest.raises(ValueError, match="misses the Earth"):
        rel.spherical_earth_geometry(800e3, math.radians(70.0))


@settings(max_examples=200, deadline=None)
@given(rows=st.integers(2, 2000), rate=st.floats(1e3, 1e5), k=st.floats(1.0, 50.0))
def test_ccd_doppler_samples_bracket(rows, rate, k):
    prf = rate / k
    n = rel.ccd_doppler_samples(rows, rate, prf)
    # N pulses fit into the rows-1 shifts, N+1 do not
    assert n * rate / prf <= (rows - 1) * (1 + 1e-9)
    assert (n + 1) * rate / prf > (rows - 1)


def _brute_force_window_ok(prf, r_near, r_far, tau):
    """Timing diagram on a 10 ns grid: transmit pulses [k PRI, k PRI + tau) must not overlap the
    receive window [2 R_near/c, 2 R_far/c + tau) and the window must be shorter than one PRI slot."""
    t = np.arange(2 * r_near / C_LIGHT, 2 * r_far / C_LIGHT + tau, 1e-8)
    phase = np.mod(t, 1 / prf)
    overlaps = np.any(phase < tau)
    return not overlaps and (t[-1] - t[0]) < 1 / prf - tau


@settings(max_examples=80, deadline=None)
@given(prf=st.floats(500.0, 20000.0), r=st.floats(2e3, 60e3), w=st.floats(0.0, 8e3), tau=st.floats(1e-6, 3e-5))
def test_echo_window_matches_timing_diagram(prf, r, w, tau):
    from sarcli.design.report import _echo_window

    ok, _, _ = _echo_window(prf, r - w / 2, r + w / 2, tau)
    if ok != _brute_force_window_ok(prf, r - w / 2, r + w / 2, tau):
        # the two may differ only where an edge falls within the 10 ns grid of a boundary
        pri = 1 / prf
        t0, t1 = 2 * (r - w / 2) / C_LIGHT, 2 * (r + w / 2) / C_LIGHT + tau
        ph1 = np.mod(t1, pri)
        assert min(abs(np.mod(t0, pri) - tau), ph1, pri - ph1, abs((t1 - t0) - (pri - tau))) < 2e-8


def test_radarsat1_design_multiple_pulses_in_flight():
    r = evaluate(load(SAMPLES / "design_radarsat1.toml"))
    o = r["prf_options"][0]
    assert o["pulses_in_flight"] >= 7  # RS-1 keeps 7-9 pulses in flight (beam tables)
    assert r["slant_range_resolution_m"] == pytest.approx(C_LIGHT / (2 * 0.72135e12 * 41.75e-6))
    names = {c["name"]: c["ok"] for c in o["constraints"]}
    assert names["azimuth_sampling"]  # 1257 Hz > 2 v / D = 941.6 Hz
    assert names["echo_window"]
    assert names["range_unambiguous"]  # one pulse in flight is not a spaceborne rule: noted, not violated
    note = next(c["note"] for c in o["constraints"] if c["name"] == "range_unambiguous")
    assert "pulse(s) in flight" in note and "echo-window" in note


def test_gbsar_table1_outdoor():
    r = evaluate(load(SAMPLES / "design_gbsar_outdoor.toml"))
    assert r["r_max_m"] == pytest.approx(600.0, rel=2e-3)
    assert r["slant_range_resolution_m"] == pytest.approx(0.75, rel=2e-3)
    by_r = {x["range_m"]: x for x in r["resolution_by_range"]}
    lam = C_LIGHT / 5.3e9
    assert by_r[100.0]["azimuth_resolution_m"] == pytest.approx(lam * 100 / (2 * 5.0))
    assert by_r[10.0]["azimuth_resolution_m"] == pytest.approx(0.125)
    assert r["ok"]


def test_cli_json_keys(cli):
    res = cli("design", SEED, "--json")
    assert res.exit_code == 0, res.stderr
    d = json.loads(res.stdout)
    for key in ("slant_range_resolution_m", "ground_range_resolution_m", "azimuth_resolution_m",
                "prf_min_hz", "prf_max_hz"):
        assert key in d
    assert [o["doppler_samples"] for o in d["prf_options"]] == [490, 122, 61]


def test_cli_human_output(cli):
    res = cli("design", SEED)
    assert res.exit_code == 0
    assert "VIOLATES range_unambiguous" in res.stdout


@pytest.mark.parametrize("text, msg", [
    ("[design]\nplatform='boat'\ncarrier_frequency_hz=1e9\n", "d.toml: design.platform: 'boat' is not one of"),
    ("[design]\nplatform='airborne'\ncarrier_frequency_hz=1e9\n", "needs chirp_rate_hz_per_s"),
    ("[design]\nplatform='airborne'\ncarrier_frequency_hz=1e9\nwings=2\n", "d.toml: design: unknown option(s) wings"),
    ("[design\n", "not valid TOML"),
    ("[design]\nprf_hz=[1.0]\n", "design: missing required option(s) platform"),
    ("[design]\nplatform='airborne'\ncarrier_frequency_hz=1e9\n[design.processor]\nlens=1\n",
     "design.processor: unknown option(s) lens"),
    ("[radar]\n", "no [design] table"),
])
def test_cli_bad_input_one_line(cli, tmp_path, text, msg):
    p = tmp_path / "d.toml"
    p.write_text(text)
    res = cli("design", p)
    assert res.exit_code == 2
    assert msg in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    assert "Traceback" not in res.stderr


@pytest.mark.parametrize("scene, platform", [("rs1_point.toml", "spaceborne"), ("aod_ccd_scene.toml", "airborne"),
                                             ("gbsar_outdoor.toml", "gbsar")])
def test_design_from_scene_files(scene, platform):
    """The scene's own chirp (or sweep) gives c/(2B), computed here from the TOML independently."""
    import tomllib

    doc = tomllib.loads((SAMPLES / scene).read_text())
    if platform == "gbsar":
        band = doc["sweep"]["bandwidth_hz"]
    else:
        band = abs(doc["radar"]["chirp_rate_hz_per_s"]) * doc["radar"]["pulse_length_s"]
    r = evaluate(load(SAMPLES / scene))
    assert r["platform"] == platform
    assert r["slant_range_resolution_m"] == pytest.approx(C_LIGHT / (2 * band), rel=1e-9)


def test_design_from_simulated_raw_product(tmp_path, cli):
    """The raw product's own parameters (PRF, chirp, orbit height and speed) give the same radar design
    as the scene it was simulated from."""
    raw = tmp_path / "aod.h5"
    assert cli("simulate", SAMPLES / "aod_ccd_scene.toml", "-o", raw).exit_code == 0
    from_raw, from_scene = evaluate(load(raw)), evaluate(load(SAMPLES / "aod_ccd_scene.toml"))
    for key in ("slant_range_resolution_m", "ground_range_resolution_m", "slant_range_m", "prf_max_hz"):
        assert from_raw[key] == pytest.approx(from_scene[key], rel=1e-3)


@settings(max_examples=25, deadline=None)
@given(centroid=st.floats(-0.45, 0.45), width=st.floats(0.05, 0.5))
def test_doppler_bandwidth_of_a_known_spectrum(centroid, width):
    """White noise band-limited to [centroid - width/2, centroid + width/2] (cycles/line): the 99 %
    bandwidth is the band, wherever it sits (wrapping included)."""
    from sarcli.design.params import doppler_bandwidth

    rng = np.random.default_rng(1)
    n = 4096
    f = np.fft.fftfreq(n)
    inband = np.abs((f - centroid + 0.5) % 1.0 - 0.5) <= width / 2
    spec = (rng.normal(size=(n, 8)) + 1j * rng.normal(size=(n, 8))) * inband[:, None]
    echo = np.fft.ifft(spec, axis=0)
    assert doppler_bandwidth(echo, 1000.0) == pytest.approx(width * 1000.0 * 0.99, rel=0.05)
