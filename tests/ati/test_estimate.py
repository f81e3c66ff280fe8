"""Estimation chain on slow-time signals synthesized from the exact bistatic range history.

Per-sample SNR 40 dB stands for the paper's 20 dB raw SNR after range compression (B*Tp = 128,
+21 dB); the raw-level check is the end-to-end test.
"""

import math

import numpy as np
import pytest

from sarcli.ati.estimate import SlowTime, estimate
from sarcli.ati.geometry import Platform
from sarcli.errors import SarcliError

P = Platform(10e3, 2000.0, 299792458.0 / 1e9)


def _obs(synth, **kw):
    eta, s0, s1, r_track = synth(**kw)
    return SlowTime(eta, s0, s1, r_track, 0.1, P, kw.get("d", 2.0))


def _rel(e, truth):
    return {k: abs(getattr(e, k + ("_mps" if k[0] == "v" else "_m")) - v) / abs(v) for k, v in truth.items()}


@pytest.mark.parametrize("route", ["exact", "nonlinear"])
def test_paper_scenario_within_0p2_percent(synth, paper, route):
    obs = _obs(synth, snr_db=40.0, seed=4)
    e = estimate(obs, route)
    rel = _rel(e, {"vy": paper["vy"], "x0": paper["x0"], "y0": paper["y0"]})
    assert max(rel.values()) < 0.002, rel
    assert abs(e.vx_mps - paper["vx"]) < 4 * e.vx_mps_sigma + 1e-3
    for k in ("vx_mps", "vy_mps", "x0_m", "y0_m", "r0_m"):
        assert 0 < getattr(e, k + "_sigma") < 1.0
    assert not e.vy_degenerate and not e.ati_ambiguous


def test_seed_route_shows_its_approximation_errors(synth, paper):
    """The paper's chain as printed (typos fixed): y0 neglects the vx*x0 term of vR (~5 %)."""
    e = estimate(_obs(synth, snr_db=40.0), "seed")
    assert 0.03 < abs(e.y0_m - paper["y0"]) / paper["y0"] < 0.08
    assert abs(e.vy_mps - paper["vy"]) / paper["vy"] < 0.03


def test_uncertainties_are_honest_over_seeds(synth, paper):
    z = []
    for seed in range(12):
        e = estimate(_obs(synth, snr_db=15.0, seed=seed), "exact")
        z.append([(e.vy_mps - paper["vy"]) / e.vy_mps_sigma, (e.y0_m - paper["y0"]) / e.y0_m_sigma])
    z = np.array(z)
    assert np.all(np.abs(z) < 4.5)
    assert 0.4 < np.sqrt(np.mean(z ** 2)) < 1.8


def test_unwrap_knob_gives_same_answer_at_high_snr(synth):
    obs = _obs(synth, snr_db=40.0, seed=2)
    a, b = estimate(obs, "exact", "itoh"), estimate(obs, "exact", "dechirp")
    assert abs(a.vy_mps - b.vy_mps) < 1e-6 and abs(a.y0_m - b.y0_m) < 1e-4


def test_vx_zero_no_ati_phase(synth):
    e = estimate(_obs(synth, vx=0.0, snr_db=40.0), "exact")
    assert abs(e.vx_mps) < 4 * e.vx_mps_sigma
    assert abs(e.vy_mps - 50.0) / 50.0 < 0.002 and abs(e.y0_m - 500.0) < 2.0


@pytest.mark.parametrize("route", ["seed", "exact"])
@pytest.mark.parametrize("y0", [0.0, 300.0])
def test_vy_equal_platform_speed_is_flagged_not_nan(synth, route, y0):
    # relative along-track velocity zero: no azimuth chirp beyond vx^2/R; sqrt argument ~ 0
    e = estimate(_obs(synth, vy=2000.0, vx=10.0, y0=y0, snr_db=40.0), route)
    assert math.isfinite(e.vy_mps) and e.vy_degenerate
    assert abs(e.vy_mps - 2000.0) < 20.0
    if route == "exact":                          # the geometry still gives the position
        assert e.vy_mps_sigma > 0                 # from +-2 sigma steps, not the (zero) linear slope
        assert abs(e.x0_m - 5095.3) < 1.0 and abs(e.y0_m - y0) < 1.0


def test_mover_leaving_the_scene_uses_the_visible_part(synth, paper):
    gate = lambda eta: (eta < 0.35).astype(float)  # noqa: E731
    full = estimate(_obs(synth, snr_db=40.0, seed=1), "exact")
    part = estimate(_obs(synth, snr_db=40.0, seed=1, gate=gate), "exact")
    assert part.extra["n_used"] < 0.7 * full.extra["n_used"]
    assert part.y0_m_sigma > full.y0_m_sigma
    assert abs(part.vy_mps - paper["vy"]) < 4 * part.vy_mps_sigma
    assert abs(part.y0_m - paper["y0"]) < 4 * part.y0_m_sigma


def test_ati_phase_near_pi_is_reported_ambiguous(synth):
    # vm ~ 140 m/s LOS = ~0.47 of the 300 m/s blind speed -> phase near pi
    e = estimate(_obs(synth, vx=300.0, vy=5.0, y0=0.0, snr_db=30.0, cpi=0.2), "exact")
    assert e.ati_ambiguous
    assert abs(e.blind_speed_mps - P.wavelength * P.speed / 2.0) < 1e-9


@pytest.mark.parametrize("route", ["exact", "nonlinear"])
def test_very_low_snr_degrades_gracefully(synth, paper, route):
    # 0 dB per slow-time sample (~ -21 dB raw): still unbiased within the reported sigmas
    for seed in range(3):
        e = estimate(_obs(synth, snr_db=0.0, seed=seed), route)
        for k in ("vy_mps", "x0_m", "y0_m"):
            assert math.isfinite(getattr(e, k)) and math.isfinite(getattr(e, k + "_sigma"))
        assert abs(e.vy_mps - paper["vy"]) < 4 * e.vy_mps_sigma
        assert abs(e.y0_m - paper["y0"]) < 4 * e.y0_m_sigma
        assert e.y0_m_sigma > 5.0


def test_bad_inputs_are_clear_errors(synth):
    eta, s0, s1, r = synth(cpi=0.01)
    with pytest.raises(SarcliError):
        estimate(SlowTime(eta[:5], s0[:5], s1[:5], r, 0.1, P, 2.0))
    with pytest.raises(SarcliError):
        estimate(SlowTime(eta, s0, s1, r, 0.1, P, 2.0), route="magic")
