"""Scene loading and the S21 simulator against a plain-numpy reference and theory."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import ConfigError, SarcliError
from sarcli.gbsar.scene import load_scene, scene_from_dict
from sarcli.gbsar.simulate import (
    antenna_gain,
    s21_stop_kernel,
    s21_stop_reference,
    simulate,
    simulate_stop,
)
from sarcli.model.constants import C_LIGHT
from tests.conftest import SAMPLES


def base(**over):
    d = {
        "scene": {"seed": 3},
        "sweep": {"center_frequency_hz": 5.3e9, "bandwidth_hz": 600e6, "points": 21},
        "rail": {"length_m": 0.2, "step_m": 0.05},
        "points": [{"x_m": 0.3, "y_m": 5.0}],
    }
    d.update(over)
    return d


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 6), nf=st.integers(1, 200), uniform=st.booleans(), seed=st.integers(0, 2**31))
def test_kernel_matches_numpy_reference(n, nf, uniform, seed):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(-50, 50, (n, 3))
    amp = rng.standard_normal((2, n)) + 1j * rng.standard_normal((2, n))
    gain = rng.uniform(0, 1, n)
    ant = rng.uniform(-1, 1, 3)
    freq = 5e9 + np.arange(nf) * 1.25e5 if uniform else np.sort(rng.uniform(5e9, 5.6e9, nf))
    out = np.zeros((2, nf), np.complex128)
    s21_stop_kernel(pos, amp, gain, ant, freq, uniform, 1.0 + 3e-4, out)
    ref = s21_stop_reference(pos, amp, gain, ant, freq, 1.0 + 3e-4)
    np.testing.assert_allclose(out, ref, rtol=0, atol=1e-10 * max(1.0, np.abs(ref).max()))


def test_single_point_phase_is_theory():
    sc = scene_from_dict(base())
    f = sc.frequencies()
    s = simulate_stop(sc, 0.1, 0.0, f, ["VV", "VH"])
    r = np.hypot(0.2, 5.0)
    np.testing.assert_allclose(s[0], np.exp(-4j * np.pi * f * r / C_LIGHT), atol=1e-12)
    assert np.all(s[1] == 0)  # default scattering has no cross-pol


def test_frequency_axis_and_rail_stops():
    sc = scene_from_dict(base())
    f = sc.frequencies()
    assert f.size == 21 and np.isclose(f[0], 5.0e9) and np.isclose(f[-1], 5.6e9)
    np.testing.assert_allclose(sc.positions_m, [-0.1, -0.05, 0, 0.05, 0.1], atol=1e-12)


def test_effects_only_when_listed():
    plain = scene_from_dict(base())
    fx = scene_from_dict(base(effects={"frequency_shift": {"shift_hz": -10e6},
                                       "vertical_baseline": {"offset_m": -0.3}}))
    np.testing.assert_allclose(fx.frequencies() - plain.frequencies(), -10e6)
    np.testing.assert_allclose(fx.rail_heights() - plain.rail_heights(), -0.3)
    a = simulate(plain).s21
    b = simulate(plain).s21
    np.testing.assert_array_equal(a, b)  # no noise listed: deterministic


def test_noise_power_and_reproducibility():
    d = base(effects={"noise": {"power_db": -20.0}}, points=[{"x_m": 0.0, "y_m": 5.0, "scattering": 0.0}])
    d["sweep"]["points"] = 2001
    sc = scene_from_dict(d)
    s1 = simulate_stop(sc, 0.0, 0.0, sc.frequencies(), ["VV"])
    s2 = simulate_stop(sc, 0.0, 0.0, sc.frequencies(), ["VV"])
    np.testing.assert_array_equal(s1, s2)
    assert np.mean(np.abs(s1) ** 2) == pytest.approx(0.01, rel=0.1)


def test_atmosphere_scales_the_path():
    sc = scene_from_dict(base(effects={"atmosphere": {"refractivity_ppm": 300.0}}))
    f = sc.frequencies()
    s = simulate_stop(sc, 0.3, 0.0, f, ["VV"])
    np.testing.assert_allclose(s[0], np.exp(-4j * np.pi * f * 5.0 * (1 + 300e-6) / C_LIGHT), atol=1e-12)


def test_displacement_los_and_decorrelation():
    d = base(points=[{"x_m": 0.0, "y_m": 10.0, "los_displacement_mm": 2.0},
                     {"x_m": 1.0, "y_m": 12.0, "stable": False}],
             effects={"displacement": {"scale": 1.5}, "decorrelation": {"coherence": 0.25}})
    sc = scene_from_dict(d)
    np.testing.assert_allclose(sc.scatterers.position[0], [0, 10.003, 0], atol=1e-12)
    np.testing.assert_allclose(sc.scatterers.los_displacement, [0.003, 0.0], atol=1e-12)
    assert sc.scatterers.reflectivity[0, 0] == 1.0  # stable point untouched
    # decorrelation: correlation of the unstable scatterer's reflectivity over many seeds -> coherence
    vals = []
    for seed in range(400):
        d["scene"]["seed"] = seed
        vals.append(scene_from_dict(d).scatterers.reflectivity[0, 1])
    v = np.array(vals)
    assert np.mean(v) == pytest.approx(0.5, abs=0.06)  # E[a'] = sqrt(g) a
    assert np.mean(np.abs(v) ** 2) == pytest.approx(1.0, rel=0.15)


def test_rect_pattern_is_the_papers_footprint():
    sc = scene_from_dict(base(antenna={"pattern": "rect"}, effects={"antenna_pattern": {}}))
    lam = sc.wavelength_m
    half = 10.0 * lam / (2 * 0.25)
    pos = np.array([[half * 0.99, 10.0, 0.0], [half * 1.01, 10.0, 0.0], [0.0, -10.0, 0.0]])
    np.testing.assert_array_equal(antenna_gain(sc, np.zeros(3), pos), [1.0, 0.0, 0.0])


def test_sinc_pattern_two_way():
    sc = scene_from_dict(base(effects={"antenna_pattern": {}}))
    lam = sc.wavelength_m
    # first null of the one-way sinc at sin(az) = lam / L_x
    az = np.arcsin(lam / 0.25)
    pos = np.array([[0.0, 10.0, 0.0], [10 * np.tan(az), 10.0, 0.0], [10 * np.tan(az / 2), 10.0, 0.0]])
    g = antenna_gain(sc, np.zeros(3), pos)
    assert g[0] == pytest.approx(1.0) and g[1] == pytest.approx(0.0, abs=1e-12)
    assert g[2] == pytest.approx(np.sinc(np.sin(az / 2) * 0.25 / lam) ** 2)


def test_wall_is_a_line_of_scatterers():
    sc = scene_from_dict(base(points=[], walls=[{"start_m": [-1, 6, 0], "end_m": [1, 6, 0], "spacing_m": 0.1}]))
    p = sc.scatterers.position
    assert p.shape == (21, 3) and np.allclose(p[:, 1], 6.0) and np.isclose(np.diff(p[:, 0]).max(), 0.1)


@pytest.mark.parametrize("bad, msg", [
    ({"sweep": {"center_frequency_hz": 5e9, "points": 10}}, "bandwidth"),
    ({"rail": {"positions_m": [0.0, 0.1, 0.05]}}, "increasing"),
    ({"effects": {"rain": {}}}, r"scene \[effects\]: unknown option\(s\) rain; known: antenna_pattern"),
    ({"points": [{"y_m": 5.0, "colour": 1}]}, r"scene \[\[points\]\] 0: unknown option\(s\) colour"),
    ({"sweep": {"center_frequency_hz": 5e9, "points": 2.5, "bandwidth_hz": 1e6}},
     r"\[sweep\].points: expected an integer"),
    ({"effects": {"noise": {"power_db": "loud"}}}, r"\[effects\].noise.power_db: expected a number"),
    ({"effects": {"decorrelation": {"coherence": 2.0}}}, r"scene: \[effects.decorrelation\] coherence must be in"),
    ({"points": [{"y_m": 5.0, "scattering": {"XX": 1}}]}, "polarization"),
    ({"points": []}, "no scatterers"),
])
def test_bad_scenes_are_one_line_errors(bad, msg):
    with pytest.raises(SarcliError, match=msg):
        scene_from_dict(base(**bad))


def test_samples_load():
    for name in ("gbsar_indoor.toml", "gbsar_outdoor.toml"):
        sc = load_scene(SAMPLES / name)
        assert sc.scatterers.position.shape[0] > 0


def test_missing_scene_file(tmp_path):
    with pytest.raises(ConfigError, match="nope.toml: no such file"):
        load_scene(tmp_path / "nope.toml")
    (tmp_path / "bad.toml").write_text("[scene\n")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_scene(tmp_path / "bad.toml")
    (tmp_path / "typo.toml").write_text("[sweep]\ncenter_frequency_hz = 5e9\npoints = 1\n[rail]\nlenght_m = 1\n")
    with pytest.raises(ConfigError, match=r"typo.toml \[rail\]: unknown option\(s\) lenght_m; known: height_m"):
        load_scene(tmp_path / "typo.toml")
