"""A point target's simulated phase history equals the analytic truth (independent geometry), float64."""

from __future__ import annotations

import numpy as np

from orbit.frames import ecef_to_eci
from orbit.geodetic import geodetic_to_ecef
from orbit.propagate import kepler_to_state, propagate_j2
from sarcli.sim.stripmap import simulate

C = 299792458.0
LAT, LON, H = 49.949179, -122.303533, 120.0  # near the beam centre of the test orbit at t = 0


def _expected(sc, R_phase, R_env, amp=1.0):
    """amp exp(-j 4 pi R/lam) exp(j pi K tau^2) on every (pulse, sample), and the inside-pulse mask."""
    rad = sc.radar
    n = np.arange(rad.n_samples)
    tau = rad.window_start_s + n[None, :] / rad.range_sampling_rate_hz - 2.0 * R_env[:, None] / C
    carrier = np.exp(-4j * np.pi * R_phase / rad.wavelength_m)[:, None]
    e = amp * carrier * np.exp(1j * np.pi * rad.chirp_rate_hz_per_s * tau**2)
    return e, np.abs(tau) < 0.5 * rad.pulse_length_s - 1.0 / rad.range_sampling_rate_hz


def _max_phase_error(sim, exp, mask):
    sel = mask & (np.abs(sim) > 0)
    assert sel.sum() > 1000
    assert np.allclose(np.abs(sim[sel]), np.abs(exp[sel]), rtol=1e-9)
    return np.max(np.abs(np.angle(sim[sel] * np.conj(exp[sel]))))


def test_orbit_point_target_phase_matches_truth(orbit_scene):
    tgt = f"[[targets]]\nlat_deg = {LAT}\nlon_deg = {LON}\nheight_m = {H}\n"
    sc = orbit_scene(effects=("range_migration", "earth_rotation"), targets=tgt, n_lines=400, n_samples=420)
    raw = simulate(sc, dtype=np.complex128)
    t = raw.azimuth_time
    r0, v0 = kepler_to_state(sc.platform.elements)
    r, _ = propagate_j2(r0, v0, t)
    p = ecef_to_eci(sc.epoch_utc, t, np.broadcast_to(geodetic_to_ecef(LAT, LON, H), (t.size, 3)))
    R = np.linalg.norm(p - r, axis=1)
    exp, mask = _expected(sc, R, R)
    assert _max_phase_error(raw.echo, exp, mask) < 1e-6


def test_orbit_without_range_migration_freezes_envelope_only(orbit_scene):
    tgt = f"[[targets]]\nlat_deg = {LAT}\nlon_deg = {LON}\nheight_m = {H}\n"
    sc = orbit_scene(effects=(), targets=tgt, n_lines=400, n_samples=420)
    raw = simulate(sc, dtype=np.complex128)
    t = raw.azimuth_time
    r0, v0 = kepler_to_state(sc.platform.elements)
    r, v = propagate_j2(r0, v0, t)
    # inertial scene: the target keeps its ECI position of the scene centre
    p = ecef_to_eci(sc.epoch_utc, 0.0, geodetic_to_ecef(LAT, LON, H))
    R = np.linalg.norm(p - r, axis=1)
    R0 = raw.truth["targets"]["closest_range_m"][0]
    # closest approach of the inertial target (independent check: the minimum of the dense R(t) is above it)
    assert R0 <= R.min() + 1e-6 and R.min() - R0 < 0.05
    exp, mask = _expected(sc, R, np.full_like(R, R0))
    assert _max_phase_error(raw.echo, exp, mask) < 1e-6


def test_airborne_moving_target_two_channels_match_truth(linear_scene):
    x0, y0, vx, vy, d = 5095.3, 30.0, 10.0, 50.0, 2.0
    tgt = f"[[targets]]\nx_m = {x0}\ny_m = {y0}\nvx_mps = {vx}\nvy_mps = {vy}\namplitude = 2.0\n"
    sc = linear_scene(effects=("range_migration", "target_motion", "second_channel"), targets=tgt,
                      extra=f"[second_channel]\nreceiver_offset_m = {d}\n")
    raw = simulate(sc, dtype=np.complex128)
    t = raw.azimuth_time
    V, H = 2000.0, 10000.0
    tx = np.stack([0 * t, V * t, H + 0 * t], 1)
    p = np.stack([x0 + vx * t, y0 + vy * t, 0 * t], 1)
    r_tx = np.linalg.norm(p - tx, axis=1)
    r_rx = np.linalg.norm(p - tx - [0.0, d, 0.0], axis=1)
    for ch, R in ((raw.echo, r_tx), (raw.echo_channels[0], 0.5 * (r_tx + r_rx))):
        exp, mask = _expected(sc, R, R, amp=2.0)
        assert _max_phase_error(ch, exp, mask) < 1e-6
    assert raw.radar.receiver_offsets_m == (0.0, d)


def test_left_looking_airborne_target(linear_scene):
    tgt = "[[targets]]\nx_m = -5095.3\ny_m = 0.0\n"
    text_scene = linear_scene(effects=("range_migration", "antenna_pattern"), targets=tgt)
    sc = type(text_scene.radar)(**{**text_scene.radar.__dict__, "look_side": "left"})
    text_scene.radar = sc
    raw = simulate(text_scene, dtype=np.complex128)
    assert raw.look_side == "left" and np.abs(raw.echo).max() > 0.5
    t = raw.azimuth_time
    R = np.linalg.norm(np.stack([-5095.3 + 0 * t, -2000.0 * t, -10000.0 + 0 * t], 1), axis=1)
    exp, mask = _expected(text_scene, R, R)
    sel = mask & (np.abs(raw.echo) > 0)
    assert np.max(np.abs(np.angle(raw.echo[sel] * np.conj(exp[sel])))) < 1e-6
    # a right-looking radar does not see a target on its left
    right = simulate(linear_scene(effects=("range_migration",), targets=tgt))
    assert np.abs(right.echo).max() == 0
