"""Flight frame (geodetic nadir), control rotation (exact vs small-angle), beam vectors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from orbit.errors import GeometryError
from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef
from orbit.pointing import (
    along_track_axis,
    beam_vector,
    control_rotation,
    ellipsoid_normal,
    flight_frame,
    look_vector_control,
    side_sign,
    small_angle_pointing_error,
)

RS1_PITCH, RS1_YAW = np.radians(0.03), np.radians(0.004)


def _states(ecef_truth, n=40):
    t = np.linspace(*ecef_truth.span, n)
    r, v, _ = ecef_truth.interpolate(t)
    return r, v


def test_flight_frame_is_right_handed_orthonormal(ecef_truth):
    r, v = _states(ecef_truth)
    Q = flight_frame(r, v)
    assert np.abs(np.einsum("nki,nkj->nij", Q, Q) - np.eye(3)).max() < 1e-14
    assert np.allclose(np.linalg.det(Q), 1.0)
    # Xf is the velocity direction up to its (small) component along the nadir
    vh = v - np.sum(v * Q[..., 2], -1, keepdims=True) * Q[..., 2]
    assert np.abs(Q[..., 0] - vh / np.linalg.norm(vh, axis=-1, keepdims=True)).max() < 1e-14


def test_nadir_matches_seed_construction_and_hits_the_subsatellite_point(ecef_truth):
    r, v = _states(ecef_truth)
    lat, lon, h = ecef_to_geodetic(r)
    # [Koh2003, eq. 2]: s = (rx, ry, rz + dz), dz = rho (tan phi_gd - tan phi_gc), Zf = -s/|s|
    rho = np.hypot(r[:, 0], r[:, 1])
    dz = rho * (np.tan(np.radians(lat)) - r[:, 2] / rho)
    s = r + np.stack([0 * dz, 0 * dz, dz], -1)
    zf_seed = -s / np.linalg.norm(s, axis=-1, keepdims=True)
    assert np.abs(flight_frame(r, v)[..., 2] - zf_seed).max() < 1e-12
    # independent: the sub-satellite point (same lat/lon, h = 0) lies exactly along the nadir
    foot = geodetic_to_ecef(lat, lon, 0 * h)
    d = (foot - r) / np.linalg.norm(foot - r, axis=-1, keepdims=True)
    assert np.abs(d - zf_seed).max() < 1e-11


def test_nadir_is_finite_over_the_pole():
    r = np.array([0.0, 1e-3, 6_356_752.314 + 800e3])
    n = ellipsoid_normal(r)
    assert np.allclose(n, [0, 0, 1], atol=1e-9)
    Q = flight_frame(r, np.array([7500.0, 0.0, 0.0]))
    assert np.all(np.isfinite(Q)) and np.allclose(Q[:, 1], [0, -1, 0], atol=1e-9)


def test_right_is_east_when_flying_north_over_the_equator():
    Q = flight_frame(np.array([7e6, 0.0, 0.0]), np.array([0.0, 0.0, 7500.0]))
    assert np.allclose(Q, [[0, 0, -1], [0, 1, 0], [1, 0, 0]], atol=1e-15)
    assert np.allclose(beam_vector([7e6, 0, 0], [0, 0, 7500.0], np.pi / 2), [0, 1, 0], atol=1e-15)
    assert np.allclose(beam_vector([7e6, 0, 0], [0, 0, 7500.0], np.pi / 2, side="left"), [0, -1, 0],
                       atol=1e-15)
    with pytest.raises(GeometryError, match="look side"):
        side_sign("up")


@settings(max_examples=50, deadline=None)
@given(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2))
def test_control_rotation_exact_is_rz_ry_and_small_angle_is_its_first_order(pitch, yaw):
    cp, sp, cy, sy = np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    R = control_rotation(pitch, yaw)
    assert np.abs(R - rz @ ry).max() < 1e-15
    Rs = control_rotation(pitch, yaw, exact=False)
    # the dropped terms are second order: |R - Rs| <= (|p| + |y|)^2 / 2 (elementwise)
    assert np.abs(R - Rs).max() <= 0.5 * (abs(pitch) + abs(yaw)) ** 2 + 1e-16
    assert np.array_equal(control_rotation(0.0, 0.0, exact=False), np.eye(3))


@settings(max_examples=50, deadline=None)
@given(st.floats(0.0, 1.2), st.floats(-0.05, 0.05), st.floats(-0.05, 0.05), st.sampled_from(["right", "left"]))
def test_beam_is_unit_and_lies_in_the_look_plane(look, pitch, yaw, side):
    r = np.array([-2.1e6, 4.3e6, 5.3e6])
    v = np.array([6.1e3, 3.9e3, -0.7e3])
    L = beam_vector(r, v, look, pitch, yaw, side)
    assert abs(np.linalg.norm(L) - 1) < 1e-14
    assert abs(L @ along_track_axis(r, v, pitch, yaw)) < 1e-14


def test_attitude_signs_pitch_forward_yaw_backward():
    r, v = np.array([7e6, 0.0, 0.0]), np.array([0.0, 0.0, 7500.0])  # Xf = +z
    assert beam_vector(r, v, 0.4, pitch=1e-3)[2] > 0
    assert beam_vector(r, v, 0.4, yaw=1e-3)[2] < 0
    assert beam_vector(r, v, 0.4, yaw=1e-3, side="left")[2] > 0
    assert np.allclose(look_vector_control(0.0), [0, 0, 1])


@pytest.mark.parametrize("scale", [0.0, 1.0, 100.0])
def test_small_angle_pointing_error_is_second_order(scale):
    look = np.radians(np.linspace(10, 50, 9))
    e = small_angle_pointing_error(look, scale * RS1_PITCH, scale * RS1_YAW)
    # second-order terms dropped by the small-angle matrix: (y^2/2, p y, p^2/2) -> <= (|p| + |y|)^2 / 2
    bound = 0.5 * (scale * (RS1_PITCH + RS1_YAW)) ** 2
    assert np.all(e <= 1.01 * bound + 1e-15)
    if scale == 1:
        assert e.max() < 2e-7  # < 0.2 urad at the Radarsat-1 attitude limits
    if scale == 100:
        assert e.max() > 1e-4  # ... but ~1e4 times more at 100x: the knob matters there
