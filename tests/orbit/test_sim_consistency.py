"""orbit.geometry against the simulator's truth (sarcli.sim computes it in ECI with a rotating target,
orbit.geometry in ECEF with a fixed one): geometric Doppler centroid/rate and Doppler times."""

from __future__ import annotations

import numpy as np
import pytest

from orbit import geometry as G
from orbit.geodetic import geodetic_to_ecef
from orbit.statevectors import StateVectors
from tests.conftest import SAMPLES


@pytest.fixture(scope="module")
def small_rs1():
    sim = pytest.importorskip("sarcli.sim.stripmap")
    from sarcli.sim.scene import parse_scene

    text = (SAMPLES / "rs1_point.toml").read_text()
    text = text.replace("n_lines = 2048", "n_lines = 64").replace("n_samples = 2400", "n_samples = 96")
    text = text.replace('"chirp_replica", "noise", "quantization"]', '"chirp_replica"]')  # truth only
    return sim.simulate(parse_scene(text))


def test_geometric_doppler_matches_simulator_truth(small_rs1):
    raw = small_rs1
    tr = raw.truth
    sv = StateVectors.from_record(raw.orbit, raw.epoch_utc)
    t = float(tr["doppler_truth_time_s"])
    pitch = np.interp(t, raw.attitude.time, raw.attitude.pitch)
    yaw = np.interp(t, raw.attitude.time, raw.attitude.yaw)
    rho = raw.slant_range()
    lam = raw.radar.wavelength_m
    h = float(tr["reference_height_m"])
    fdc = G.doppler_from_attitude(sv, t, rho, lam, pitch, yaw, raw.look_side, h)
    ok = np.isfinite(tr["doppler_centroid_hz"])
    assert ok.any() and np.abs(fdc - tr["doppler_centroid_hz"])[ok].max() < 1e-3
    r, v, a = sv.to_ecef().interpolate(t)
    p = G.target_from_doppler(r, v, rho, lam, fdc, raw.look_side, h)
    fr = G.doppler_rate_hz_per_s(r, v, a, p, lam)
    assert np.abs(fr - tr["doppler_rate_hz_per_s"])[ok].max() < 1e-3


def test_target_doppler_times_match_simulator_truth(small_rs1):
    raw = small_rs1
    tg = raw.truth["targets"]
    sv = StateVectors.from_record(raw.orbit, raw.epoch_utc)
    p = geodetic_to_ecef(tg["lat_deg"], tg["lon_deg"], tg["height_m"])
    t0, r0 = G.doppler_time(sv, p, t_guess=0.0)
    assert np.abs(t0 - tg["zero_doppler_time_s"]).max() < 1e-6
    assert np.abs(r0 - tg["closest_range_m"]).max() < 1e-3
    tb, rb = G.doppler_time(sv, p, raw.radar.wavelength_m, tg["doppler_centroid_hz"], t_guess=0.0)
    assert np.abs(tb - tg["beam_center_time_s"]).max() < 1e-6
    assert np.abs(rb - tg["beam_center_range_m"]).max() < 1e-3
