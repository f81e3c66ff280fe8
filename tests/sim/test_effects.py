"""Each effect's signature is present when listed and absent when not (small, fast scenes)."""

from __future__ import annotations

import numpy as np
import pytest

from orbit.frames import ecef_to_eci
from orbit.geodetic import geodetic_to_ecef
from orbit.pointing import beam_vector
from orbit.propagate import kepler_to_state, propagate_j2
from sarcli.sim.effects.chirp_replica import replica
from sarcli.sim.stripmap import simulate

C = 299792458.0


def cde(echo: np.ndarray, prf: float) -> float:
    """Lag-one azimuth correlation Doppler estimate (Madsen), Hz in [-PRF/2, PRF/2)."""
    e = echo.astype(np.complex128)
    return float(np.angle(np.sum(e[1:] * np.conj(e[:-1]))) / (2 * np.pi) * prf)


def wrap(f, prf):
    return (np.asarray(f) + prf / 2) % prf - prf / 2


def test_inertial_zero_attitude_has_zero_doppler(orbit_scene):
    sc = orbit_scene(effects=("range_migration", "antenna_pattern"))
    raw = simulate(sc, dtype=np.complex128)
    t = raw.truth
    assert abs(cde(raw.echo, raw.radar.prf_hz)) < 1.0
    assert np.nanmax(np.abs(t["doppler_centroid_hz"])) < 1e-3
    assert abs(t["targets"]["doppler_centroid_hz"][0]) < 1e-3
    # the pitfall is real: with a geodetic-nadir flight frame the zero-Doppler beam needs a pitch of
    # ~0.01-0.1 deg (eccentric orbit, geodetic vs geocentric vertical); the product stores it, and
    # orbit.pointing with the stored attitude gives a beam perpendicular to the ECI velocity
    pitch = raw.attitude.pitch
    assert 1e-5 < np.max(np.abs(pitch)) < 3e-3
    r0, v0 = kepler_to_state(sc.platform.elements)
    r, v = propagate_j2(r0, v0, raw.attitude.time)
    L = beam_vector(r, v, raw.truth["beam_look_angle_rad"], pitch, raw.attitude.yaw)
    assert np.max(np.abs(np.einsum("ij,ij->i", L, v))) < 1e-6 * 7500
    L0 = beam_vector(r, v, raw.truth["beam_look_angle_rad"], 0.0, 0.0)
    assert np.min(np.abs(2 / raw.radar.wavelength_m * np.einsum("ij,ij->i", L0, v))) > 300.0  # Hz (-470 Hz here)


def test_earth_rotation_doppler_matches_independent_geometry(orbit_scene):
    sc = orbit_scene(effects=("range_migration", "antenna_pattern", "earth_rotation"))
    raw = simulate(sc, dtype=np.complex128)
    tg = raw.truth["targets"][0]
    prf, lam = raw.radar.prf_hz, raw.radar.wavelength_m
    # independent: R(t) of the Earth-fixed target from propagate_j2 + GMST, finite differences
    ecef = geodetic_to_ecef(tg["lat_deg"], tg["lon_deg"], tg["height_m"])
    h = 0.01
    tt = tg["beam_center_time_s"] + np.array([-h, 0.0, h])
    r0, v0 = kepler_to_state(sc.platform.elements)
    r, _ = propagate_j2(r0, v0, tt)
    R = np.linalg.norm(ecef_to_eci(sc.epoch_utc, tt, np.broadcast_to(ecef, (3, 3))) - r, axis=1)
    fdc = -2 / lam * (R[2] - R[0]) / (2 * h)
    fr = -2 / lam * (R[2] - 2 * R[1] + R[0]) / h**2
    assert abs(tg["doppler_centroid_hz"] - fdc) < 0.01
    assert abs(tg["doppler_rate_hz_per_s"] - fr) < 0.05
    assert abs(tg["beam_center_range_m"] - R[1]) < 1e-3
    assert -8000 < fdc < -5000  # Radarsat-1-like Earth-rotation Doppler at 49 N
    # the echo's centroid is the geometric one (modulo PRF)
    assert abs(wrap(cde(raw.echo, prf) - fdc, prf)) < 0.01 * prf
    # truth per range sample at the scene centre: the target (at the centre) sits on that curve
    rng = raw.slant_range()
    assert abs(np.interp(tg["beam_center_range_m"], rng, raw.truth["doppler_centroid_hz"]) - fdc) < 0.5


def test_attitude_moves_the_doppler_centroid(orbit_scene):
    extra = "[attitude]\npitch_deg = 0.05\nyaw_deg = 0.02\n"
    with_att = simulate(orbit_scene(effects=("range_migration", "attitude"), extra=extra), dtype=np.complex128)
    without = simulate(orbit_scene(effects=("range_migration",), extra=extra), dtype=np.complex128)
    prf, lam = with_att.radar.prf_hz, with_att.radar.wavelength_m
    f = with_att.truth["targets"]["doppler_centroid_hz"][0]
    # small-angle theory for an inertial scene: f = (2 v/lam) (sin(pitch) cos(look)... ) -> ~ (2v/lam) * angle
    v = 7450.0
    approx = 2 * v / lam * (np.radians(0.05) * np.cos(np.radians(33.5)) - np.radians(0.02) * np.sin(np.radians(33.5)))
    assert abs(f - approx) < 0.05 * abs(approx) and abs(f) > 50
    assert abs(wrap(cde(with_att.echo, prf) - f, prf)) < 0.01 * prf
    assert abs(cde(without.echo, prf)) < 1.0
    assert np.all(with_att.attitude.yaw == np.radians(0.02)) and np.all(without.attitude.yaw == 0)


def test_antenna_pattern_shapes_amplitude(orbit_scene):
    targets = ("[[targets]]\nslant_range_m = 994000.0\n[[targets]]\nslant_range_m = 994700.0\n"
               "azimuth_time_s = 0.05\n")
    on = simulate(orbit_scene(effects=("range_migration", "antenna_pattern"), targets=targets, n_samples=600))
    off = simulate(orbit_scene(effects=("range_migration",), targets=targets, n_samples=600))
    a_on = np.abs(on.echo[:, 100])
    a_off = np.abs(off.echo[:, 100])
    lit = a_off > 0
    assert np.allclose(a_off[lit], 1.0, atol=1e-6)  # uniform illumination inside the processed beam
    shape = a_on[lit] / a_on[lit].max()
    assert shape.min() < 0.05 and np.argmax(shape) not in (0, shape.size - 1)  # sinc^2 from the peak to the nulls
    # elevation pattern: the two targets are seen at different elevation angles -> different peak gains
    peaks_on = [np.abs(on.echo[:, s]).max() for s in (60, 340)]
    peaks_off = [np.abs(off.echo[:, s]).max() for s in (60, 340)]
    assert abs(peaks_off[0] - peaks_off[1]) < 1e-6 and abs(peaks_on[0] - peaks_on[1]) > 1e-3


def test_range_migration_moves_the_envelope(linear_scene):
    def first_sample(raw):
        lit = np.abs(raw.echo) > 0
        rows = np.flatnonzero(lit.any(axis=1))
        return np.array([np.argmax(lit[k]) for k in rows])

    on = first_sample(simulate(linear_scene(effects=("range_migration",), n_lines=2000)))
    off = first_sample(simulate(linear_scene(effects=(), n_lines=2000)))
    assert np.ptp(on) >= 5 and np.ptp(off) == 0


def test_noise_statistics_and_snr(orbit_scene):
    extra = "[noise]\nsnr_db = 6.0\n"
    clean = simulate(orbit_scene(effects=("range_migration",)), dtype=np.complex128)
    noisy = simulate(orbit_scene(effects=("range_migration", "noise"), extra=extra), dtype=np.complex128)
    n = noisy.echo - clean.echo
    pn = noisy.truth["noise_power"]
    lit = np.abs(clean.echo) > 0
    assert abs(np.mean(np.abs(n) ** 2) / pn - 1) < 0.02
    assert abs(np.var(n.real) / np.var(n.imag) - 1) < 0.03
    assert abs(np.mean(n.real * n.imag)) < 0.02 * pn
    assert abs(10 * np.log10(np.mean(np.abs(clean.echo[lit]) ** 2) / pn) - 6.0) < 1e-9
    assert np.all(clean.echo[~lit] == 0) and "noise_power" not in clean.truth


def test_chirp_replica_stored_and_consistent_with_echo(linear_scene):
    tgt = "[[targets]]\nx_m = 5095.3\ny_m = 0.0\n"
    on = simulate(linear_scene(effects=("chirp_replica",), targets=tgt), dtype=np.complex128)
    off = simulate(linear_scene(effects=(), targets=tgt))
    assert off.replica is None and on.replica is not None
    fs, K, T = on.radar.range_sampling_rate_hz, on.radar.chirp_rate_hz_per_s, on.radar.pulse_length_s
    n = round(T * fs)
    t = (np.arange(n) - (n - 1) / 2) / fs
    assert np.allclose(on.replica, np.exp(1j * np.pi * K * t * t), atol=1e-6)
    assert np.allclose(replica(linear_scene().radar), np.exp(1j * np.pi * K * t * t))
    # matched filtering a line with the replica peaks at the target's slant-range sample
    R0 = on.truth["targets"]["closest_range_m"][0]
    k = np.argmax(np.abs(on.echo).sum(axis=1))
    comp = np.correlate(on.echo[k], on.replica, mode="same")
    expected = (R0 - on.radar.first_range_m) / (C / (2 * fs))
    assert abs(np.argmax(np.abs(comp)) - expected) <= 1.0


def test_second_channel_present_only_when_listed(linear_scene):
    extra = "[second_channel]\nreceiver_offset_m = 2.0\n"
    one = simulate(linear_scene(effects=("range_migration",), extra=extra))
    two = simulate(linear_scene(effects=("range_migration", "second_channel"), extra=extra))
    assert one.echo_channels is None and one.radar.receiver_offsets_m == (0.0,)
    assert two.echo_channels.shape == (1, *two.echo.shape) and two.radar.receiver_offsets_m == (0.0, 2.0)
    assert np.array_equal(one.echo, two.echo)
    # static target: channel 1's phase history is channel 0's advanced by d/(2V) (phase centre halfway):
    # with d/(2V) = 1.5 pulses, channel 1 at pulse k matches channel 0 at k + 1.5 (midpoint of k+1, k+2)
    a = one.echo[:, 120].astype(complex)
    b = two.echo_channels[0][:, 120].astype(complex)
    lit = np.flatnonzero((np.abs(a) > 0) & (np.abs(b) > 0))[10:-10]
    mid = np.angle(a[lit + 1] * np.exp(0.5j * np.angle(a[lit + 2] / a[lit + 1])))
    assert np.max(np.abs(np.angle(np.exp(1j * (np.angle(b[lit]) - mid))))) < 0.05


@pytest.mark.parametrize("listed", [True, False])
def test_target_motion(linear_scene, listed):
    moving = "[[targets]]\nx_m = 5095.3\ny_m = 0.0\nvx_mps = 10.0\nvy_mps = 50.0\n"
    static = "[[targets]]\nx_m = 5095.3\ny_m = 0.0\n"
    eff = ("range_migration", "target_motion") if listed else ("range_migration",)
    a = simulate(linear_scene(effects=eff, targets=moving))
    b = simulate(linear_scene(effects=eff, targets=static))
    tv = a.truth["targets"][0]
    if listed:
        assert not np.array_equal(a.echo, b.echo)
        assert (tv["vel_x_mps"], tv["vel_y_mps"]) == (10.0, 50.0)
        # range rate at t = 0 is vx*x0/R0 -> Doppler -(2/lam) vx x0/R0 at the scene centre (beam centre)
        R0 = np.hypot(5095.3, 10000.0)
        assert abs(tv["doppler_centroid_hz"] - (-2 / 0.299792458 * 10.0 * 5095.3 / R0)) < 1e-6
    else:
        assert np.array_equal(a.echo, b.echo) and tv["vel_x_mps"] == 0.0


def test_sea_land_clutter_centroid_matches_truth(orbit_scene):
    """Hard case for Doppler work: contrasted clutter (sea -18 dB / land -6 dB), Earth rotation, attitude,
    4-bit AGC; the data centroid of each half-swath equals the geometric truth modulo PRF."""
    clutter = "".join(
        f"[[clutter]]\nslant_range_m = {r}\nrange_extent_m = 500.0\nazimuth_extent_m = 1500.0\n"
        f"sigma0_db = {s0}\ndensity_per_m2 = 0.01\n" for r, s0 in ((993700.0, -18.0), (994250.0, -6.0)))
    extra = "[attitude]\npitch_deg = 0.03\n[noise]\nsnr_db = 12.0\n[quantization]\nbits = 4\n"
    effects = ("range_migration", "earth_rotation", "attitude", "antenna_pattern", "noise", "quantization")
    raw = simulate(orbit_scene(effects=effects, targets=clutter, extra=extra, n_lines=700, n_samples=400))
    prf = raw.radar.prf_hz
    e = raw.echo.astype(np.complex128) * 10 ** (raw.agc_db[:, None] / 20)
    truth = raw.truth["doppler_centroid_hz"]
    for sl in (slice(40, 200), slice(200, 360)):
        assert abs(wrap(cde(e[:, sl], prf) - np.nanmean(truth[sl]), prf)) < 0.005 * prf


def test_quantization_present_only_when_listed(orbit_scene):
    extra = "[noise]\nsnr_db = 10.0\n[quantization]\nbits = 4\n"
    off = simulate(orbit_scene(effects=("range_migration", "noise"), extra=extra))
    on = simulate(orbit_scene(effects=("range_migration", "noise", "quantization", "chirp_replica"), extra=extra))
    assert off.agc_db is None and off.radar.quantization_bits == 0
    assert np.any(off.echo.real != np.round(off.echo.real))
    assert on.radar.quantization_bits == 4 and on.agc_db.shape == (on.echo.shape[0],)
    levels = np.unique(np.concatenate([on.echo.real.ravel(), on.echo.imag.ravel(), on.replica.real]))
    assert set(levels.tolist()) <= set(range(-15, 16, 2))
    # AGC undone, the quantized echo correlates with the float one as a 4-bit quantizer should (> 0.98)
    x = off.echo.astype(np.complex128)
    y = on.echo.astype(np.complex128) * 10 ** (on.agc_db[:, None] / 20)
    rho = np.abs(np.vdot(x, y)) / np.sqrt(np.vdot(x, x).real * np.vdot(y, y).real)
    assert rho > 0.98
