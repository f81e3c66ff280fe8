"""Quaternion algebra against scipy, the model-attitude conversion both ways, and the NISAR time units."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sarcli.errors import FormatError
from sarcli.io.nisar.attitude import (
    antenna_axes_ecef,
    matrices_to_quaternions,
    model_attitude,
    quaternion_matrices,
    quaternions_from_model,
)
from sarcli.io.nisar.h5util import parse_epoch, units_since, whole_second_epoch
from sarcli.model.raw import Attitude

unit = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=60)
@given(st.tuples(unit, unit, unit, unit).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_quaternion_matrix_and_inverse_match_scipy(q):
    q = np.array(q) / np.linalg.norm(q)
    m = quaternion_matrices(q[None, :])[0]
    ref = Rotation.from_quat(q[[1, 2, 3, 0]]).as_matrix()
    np.testing.assert_allclose(m, ref, atol=1e-14)
    back = matrices_to_quaternions(m[None])[0]
    assert back[0] >= 0  # q and -q are one rotation: the inverse returns w >= 0
    assert min(np.max(np.abs(back - q)), np.max(np.abs(back + q))) < 1e-12


def test_non_unit_or_nan_quaternions_refused_in_one_line():
    for bad in (np.array([[2.0, 0, 0, 0]]), np.array([[np.nan, 0, 0, 1.0]]), np.zeros((3, 3))):
        with pytest.raises(FormatError) as e:
            quaternion_matrices(bad)
        assert "\n" not in str(e.value)


def test_slerp_midpoint_is_half_the_rotation():
    r0 = Rotation.from_euler("z", 0.0)
    r1 = Rotation.from_euler("z", 0.2)
    q = np.stack([r0.as_quat()[[3, 0, 1, 2]], -r1.as_quat()[[3, 0, 1, 2]]])  # sign flip: same rotation
    m = antenna_axes_ecef(np.array([0.0, 1.0]), q, np.array([0.5, -3.0, 9.0]))
    np.testing.assert_allclose(m[0], Rotation.from_euler("z", 0.1).as_matrix(), atol=1e-14)
    np.testing.assert_allclose(m[1], r0.as_matrix(), atol=1e-14)  # held at the ends
    np.testing.assert_allclose(m[2], r1.as_matrix(), atol=1e-14)


@pytest.fixture(scope="module")
def sv():
    from synth import EPOCH, orbit_ecef

    from orbit.statevectors import StateVectors

    t = np.arange(3500.0, 3710.0, 10.0)
    p, v = orbit_ecef(t)
    return StateVectors(t, p, v, "ECEF", EPOCH)


@settings(max_examples=25, deadline=None)
@given(st.floats(-0.02, 0.02), st.floats(-0.1, 0.1), st.floats(0.3, 0.8), st.sampled_from(["right", "left"]))
def test_model_attitude_round_trip(sv, pitch, yaw, look, side):
    t = np.array([3590.0, 3600.0, 3610.0])
    att = Attitude(t, np.full(3, pitch), np.zeros(3), np.full(3, yaw))
    q = quaternions_from_model(att, sv, side, look)
    back = model_attitude(t, q, sv, side)
    np.testing.assert_allclose(back.pitch, att.pitch, atol=1e-12)
    np.testing.assert_allclose(back.yaw, att.yaw, atol=1e-12)
    with pytest.raises(FormatError, match="looking"):
        model_attitude(t, q, sv, "left" if side == "right" else "right")


@pytest.mark.parametrize("units, epoch, frac", [
    ("seconds since 2011-01-13 00:00:00", "2011-01-13T00:00:00.000000Z", 0.0),
    ("seconds since 2011-01-13T00:00:00.000000000", "2011-01-13T00:00:00.000000Z", 0.0),
    ("seconds since 2006-07-20T03:15:55.594911995", "2006-07-20T03:15:55.000000Z", 0.594911995),
    ("Seconds since 2020-02-29 23:59:59Z", "2020-02-29T23:59:59.000000Z", 0.0),
])
def test_time_units(units, epoch, frac):
    e, fr = parse_epoch(units, "x")
    assert e == epoch and fr == pytest.approx(frac, abs=1e-15)


@pytest.mark.parametrize("units", ["days since 2011-01-13", "seconds since 2011-13-01 00:00:00", "", "seconds"])
def test_bad_time_units_refused(units):
    with pytest.raises(FormatError, match="units"):
        parse_epoch(units, "f.h5: /t")


def test_whole_second_epoch_and_units():
    e, frac = whole_second_epoch("2002-06-16T15:41:00.250000Z")
    assert e == "2002-06-16T15:41:00.000000Z" and frac == 0.25
    assert units_since(e) == "seconds since 2002-06-16T15:41:00"
    with pytest.raises(ValueError):
        units_since("2002-06-16T15:41:00.5Z")
