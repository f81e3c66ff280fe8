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
    echo_kernel(a, *args, 37, 0, 1 << 62)
    echo_reference(b, *args)
    assert np.abs(b).max() > 0.1
    # one ulp of a 1e6 m range is 1.2e-10 m, i.e. 2.6e-8 rad of carrier phase: the float64 floor
    assert np.max(np.abs(a - b)) < 1e-7


def test_kernel_complex64_output_close_to_complex128(linear_scene):
    sc = linear_scene(effects=("range_migration", "antenna_pattern"))
    args = _args(sc)
    a = np.zeros((1, sc.radar.n_lines, sc.radar.n_samples), np.complex128)
    b = np.zeros_like(a, dtype=np.complex64)
    echo_kernel(a, *args, 64, 0, 1 << 62)
    echo_kernel(b, *args, 64, 0, 1 << 62)
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


CLUTTER = """
[[clutter]]
slant_range_m = 994000.0
range_extent_m = 250.0
azimuth_extent_m = 600.0
sigma0_db = 0.0
density_per_m2 = 0.004
"""


def test_splat_kernel_matches_numpy_reference(orbit_scene):
    from sarcli.sim.kernel import splat_kernel, splat_reference

    extra = "[second_channel]\nreceiver_offset_m = 3.0\n"
    sc = orbit_scene(effects=("range_migration", "antenna_pattern", "earth_rotation", "second_channel"),
                     targets=CLUTTER, extra=extra, n_lines=200)
    args = _args(sc)
    kargs = args[:14] + (8 * sc.radar.range_sampling_rate_hz, sc.radar.window_start_s * 8
                         * sc.radar.range_sampling_rate_hz - 700.0) + args[18:]
    a = np.zeros((2, 120, 4000), np.complex128)
    b = np.zeros_like(a)
    splat_kernel(a, 50, 3900, *kargs, 16)
    splat_reference(b, 50, 3900, *kargs)
    assert np.all(a[..., 3900:] == 0)
    assert np.abs(b).max() > 0.1 and np.max(np.abs(a - b)) < 1e-7 * np.abs(b).max()  # float64 phase floor


def test_binned_clutter_close_to_exact_and_converges(orbit_scene):
    from sarcli.sim.stripmap import simulate

    err = {}
    for q in (4, 8):
        out = {}
        for model in ("exact", "binned"):
            sc = orbit_scene(effects=("range_migration", "antenna_pattern", "earth_rotation"), targets=CLUTTER,
                             n_lines=200)
            sc.clutter_model, sc.clutter_oversampling = model, q
            out[model] = simulate(sc, dtype=np.complex128).echo
        e = out["exact"]
        err[q] = 10 * np.log10(np.sum(np.abs(out["binned"] - e) ** 2) / np.sum(np.abs(e) ** 2))
    assert err[4] < -29 and err[8] < -35 and err[8] < err[4] - 3
