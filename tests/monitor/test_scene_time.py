"""The emulator's time: motion laws, the scene realised at a time, the atmosphere in time, the
simulated scan clock and its truth file. Expected values from the laws' definitions (integrals done
numerically here, independently of the closed forms in the code) and from statistics."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad

from sarcli.errors import ConfigError
from sarcli.gbsar.scene import MotionLaw, load_scene, scene_at, scene_from_dict, scene_truth
from sarcli.gbsar.simulate import simulate_stop
from tests.monitor.conftest import LANDSLIDE


def _base(**extra) -> dict:
    d = {"scene": {"seed": 3, "epoch_utc": "2026-01-01T00:00:00Z"},
         "sweep": {"center_frequency_hz": 5.3e9, "bandwidth_hz": 100e6, "points": 11},
         "rail": {"length_m": 0.2, "step_m": 0.1, "height_m": 2.0},
         "points": [{"name": "p", "x_m": 3.0, "y_m": 100.0, "z_m": 10.0,
                     "motion": {"law": "failure", "velocity_mm_per_h": 0.4, "onset_h": 1.0, "failure_h": 5.0}}]}
    d.update(extra)
    return d


@given(t=st.floats(0.0, 4.95), v0=st.floats(0.05, 3.0), ta=st.floats(0.0, 2.0), span=st.floats(1.0, 6.0))
def test_failure_law_is_the_integral_of_fukuzono_velocity(t, v0, ta, span):
    law = MotionLaw("failure", v0, ta, ta + span)
    t = min(t, ta + span - 0.05)

    def v(s):  # 1/v falls linearly from 1/v0 at the onset to 0 at failure
        return v0 if s <= ta else v0 * span / (ta + span - s)

    expected, _ = quad(v, 0.0, t, points=[ta] if 0 < ta < t else None, limit=200)
    assert law.displacement_mm(t) == pytest.approx(expected, rel=1e-7, abs=1e-9)
    assert law.velocity_mm_per_h_at(t) == pytest.approx(v(t), rel=1e-12)


def test_failure_law_refuses_impossible_times():
    with pytest.raises(ConfigError):
        MotionLaw("failure", 1.0, 3.0, 2.0)
    with pytest.raises(ConfigError):
        scene_from_dict(_base(points=[{"y_m": 10.0, "motion": {"law": "failure", "velocity_mm_per_h": 1.0}}]))


def test_scene_at_zero_is_the_scene_as_loaded():
    sc = load_scene(LANDSLIDE)
    s0 = scene_at(sc, 0.0, 0)
    np.testing.assert_array_equal(s0.scatterers.position, sc.scatterers.position)
    np.testing.assert_array_equal(s0.scatterers.reflectivity, sc.scatterers.reflectivity)
    assert s0.seed == sc.seed and s0.effects == sc.effects


def test_targets_move_along_their_line_of_sight_by_their_law():
    sc = scene_from_dict(_base())
    t = 3.0 * 3600
    s = scene_at(sc, t, 18)
    p0 = np.array([3.0, 100.0, 10.0])
    antenna = np.array([0.0, 0.0, 2.0])
    d = MotionLaw("failure", 0.4, 1.0, 5.0).displacement_mm(3.0) * 1e-3
    u = (p0 - antenna) / np.linalg.norm(p0 - antenna)
    np.testing.assert_allclose(s.scatterers.position[0], p0 + d * u, atol=1e-12)
    assert s.scatterers.los_displacement[0] == pytest.approx(d, rel=1e-12)
    tr = scene_truth(s)["groups"]["p"]
    assert tr["los_displacement_mm"] == pytest.approx(d * 1e3) and not tr["failed"]
    # the phase of the echo changes by -4 pi d / lam at every frequency (the project's convention)
    f = np.array([5.3e9])
    ratio = simulate_stop(s, 0.0, 2.0, f, ("VV",))[0, 0] / simulate_stop(sc, 0.0, 2.0, f, ("VV",))[0, 0]
    dr = np.linalg.norm(p0 + d * u - antenna) - np.linalg.norm(p0 - antenna)
    assert np.angle(ratio) == pytest.approx(-4 * np.pi * f[0] * dr / 299792458.0, abs=1e-9)


def test_failed_targets_decorrelate():
    sc = scene_from_dict(_base())
    a, b = scene_at(sc, 5.5 * 3600, 33), scene_at(sc, 5.7 * 3600, 34)
    assert scene_truth(a)["groups"]["p"]["failed"]
    assert a.scatterers.reflectivity[0, 0] != b.scatterers.reflectivity[0, 0]


def test_atmosphere_in_time():
    atm = {"refractivity_ppm": 1.0, "drift_ppm_per_h": 2.0, "diurnal_ppm": 3.0, "diurnal_period_h": 24.0,
           "diurnal_phase_deg": 90.0, "gradient_ppm_per_m": 0.1, "gradient_drift_ppm_per_m_per_h": -0.05}
    sc = scene_from_dict(_base(effects={"atmosphere": atm}, points=[{"y_m": 100.0, "z_m": 12.0}]))
    s = scene_at(sc, 2 * 3600, 12)
    n = 1.0 + 2.0 * 2 + 3.0 * np.sin(2 * np.pi * 2 / 24 + np.pi / 2)
    assert s.effects["atmosphere"]["refractivity_ppm"] == pytest.approx(n)
    g = 0.1 - 0.05 * 2
    r = np.hypot(100.0, 10.0)
    assert s.scatterers.atmosphere_m[0] == pytest.approx(1e-6 * r * g * (12.0 - 2.0) / 2, abs=1e-15)


def test_turbulent_screen_statistics():
    """Std and spatial correlation of the screen over many scans: sigma^2 exp(-d^2 / 2L^2)."""
    sigma, scale = 0.2, 30.0
    pts = [{"x_m": 0.0, "y_m": 100.0}, {"x_m": 0.0, "y_m": 130.0}, {"x_m": 0.0, "y_m": 400.0}]
    sc = scene_from_dict(_base(points=pts, effects={"atmosphere": {"turbulence_mm": sigma,
                                                                    "turbulence_scale_m": scale}}))
    s = np.array([scene_at(sc, 0.0, k).scatterers.atmosphere_m for k in range(1, 1501)]) * 1e3
    n = s.shape[0]
    assert np.std(s[:, 0]) == pytest.approx(sigma, rel=4 / np.sqrt(2 * n) + 0.03)
    rho = np.corrcoef(s.T)
    assert rho[0, 1] == pytest.approx(np.exp(-30.0 ** 2 / (2 * scale ** 2)), abs=4 / np.sqrt(n) + 0.03)
    assert abs(rho[0, 2]) < 4 / np.sqrt(n) + 0.03


def test_scene_clock_counts_scans_and_writes_truth(tmp_path):
    from sarcli.acquire.emulator import SceneClock

    sc = load_scene(LANDSLIDE)
    truth = tmp_path / "t.jsonl"
    clock = SceneClock(sc, 2.0, 600.0, str(truth))
    f = np.linspace(5.25e9, 5.35e9, 5)
    clock.warm_up()
    assert clock.scan == -1 and not truth.exists()
    for x in (-0.5, -0.5, -0.45, -0.4):  # one scan (a stop swept twice: two polarizations, or a resume)
        clock(x, f, "VV")
    assert clock.scan == 0
    clock(-0.4, f, "VV")  # resumed at the same stop: the same scan
    assert clock.scan == 0
    a = clock(-0.5, f, "VV")  # back to the start: the next scan, 10 minutes later
    assert clock.scan == 1
    np.testing.assert_allclose(a, simulate_stop(scene_at(sc, 600.0, 1), -0.5, 2.0, f, ("VV",))[0], rtol=1e-12)
    lines = [json.loads(x) for x in truth.read_text().splitlines()]
    assert [x["scan"] for x in lines] == [1, 2] and lines[1]["time_utc"] == "2026-05-01T06:10:00Z"
    assert lines[1]["groups"]["CR-creep"]["los_displacement_mm"] == pytest.approx(0.3 / 6, rel=1e-9)


def test_emulate_options_are_checked(cli, tmp_path):
    r = cli("gbsar", "emulate", "--truth", tmp_path / "t.jsonl")
    assert r.exit_code == 2 and "--scene" in r.stderr
    r = cli("gbsar", "emulate", "--scene", LANDSLIDE, "--truth", tmp_path / "t.jsonl")
    assert r.exit_code == 2 and "--scan-interval" in r.stderr
