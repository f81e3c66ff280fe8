"""The numba echo kernel and beam search against their plain-numpy references."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.sim.kernel import _sin_az, beam_windows, echo_kernel, echo_reference
from sarcli.sim.stripmap import _concat, kernel_args, prepare


def _args(scene):
    ctx, traj, motion, axes, rot, points, clutter, _ = prepare(scene)
    return kernel_args(scene, ctx, traj, motion, axes, rot, _concat(points, clutter))


TARGETS = """
[[targets]]
slant_range_m = 994000.0
azimuth_time_s = 0.0
[[targets]]
slant_range_m = 993700.0
azimuth_time_s = -0.08
amplitude = 0.5
phase_deg = 30.0
[[targets]]
slant_range_m = 994600.0
azimuth_time_s = 0.1
height_m = 300.0
"""


@pytest.mark.parametrize("effects", [
    ("range_migration", "antenna_pattern", "earth_rotation"),
    ("earth_rotation", "attitude", "second_channel"),
    ("range_migration", "second_channel", "antenna_pattern"),
])
def test_kernel_matches_numpy_reference(orbit_scene, effects):
    extra = "[attitude]\npitch_deg = 0.05\nyaw_deg = -0.02\n[second_channel]\nreceiver_offset_m = 7.5\n"
    sc = orbit_scene(effects=effects, targets=TARGETS, extra=extra, n_lines=300, n_samples=500)
    args = _args(sc)
    n_ch = args[12].size
    a = np.zeros((n_ch, sc.radar.n_lines, sc.radar.n_samples), np.complex128)
    b = np.zeros_like(a)
    echo_kernel(a, *args, 37)
    echo_reference(b, *args)
    assert np.abs(b).max() > 0.1
    # one ulp of a 1e6 m range is 1.2e-10 m, i.e. 2.6e-8 rad of carrier phase: the float64 floor
    assert np.max(np.abs(a - b)) < 1e-7


def test_kernel_complex64_output_close_to_complex128(linear_scene):
    sc = linear_scene(effects=("range_migration", "antenna_pattern"))
    args = _args(sc)
    a = np.zeros((1, sc.radar.n_lines, sc.radar.n_samples), np.complex128)
    b = np.zeros_like(a, dtype=np.complex64)
    echo_kernel(a, *args, 64)
    echo_kernel(b, *args, 64)
    assert np.max(np.abs(a - b)) < 1e-6


def test_beam_windows_match_brute_force(orbit_scene):
    sc = orbit_scene(effects=("earth_rotation", "attitude"), targets=TARGETS,
                     extra="[attitude]\npitch_deg = 0.1\n", n_lines=600)
    args = _args(sc)
    t, rp, ux, ue, rot, q, u, tref = args[:8]
    smax = sc.antenna.beam_extent * sc.radar.wavelength_m / sc.antenna.length_m
    k0, k1 = beam_windows(t, rp, ux, rot, q, u, tref, smax)
    buf = np.empty(3)
    for i in range(q.shape[0]):
        s = np.array([_sin_az.py_func(t, rp, ux, rot, q, u, tref, i, k, buf) for k in range(t.size)])
        assert np.all(np.diff(s) < 0)  # monotone as the target passes
        inside = np.flatnonzero(np.abs(s) <= smax)
        assert (k0[i], k1[i]) == (inside[0], inside[-1] + 1)
