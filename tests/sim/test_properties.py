"""Property tests (hypothesis): flat-Earth surface solve, kernel vs reference on random scenes, quantizer."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sarcli.sim.effects.quantization import quantize
from sarcli.sim.geometry import surface_point
from sarcli.sim.kernel import echo_kernel, echo_reference
from sarcli.sim.pointing import antenna_axes
from sarcli.sim.scene import parse_scene
from sarcli.sim.stripmap import _concat, kernel_args, prepare
from tests.sim.conftest import linear_scene_text


@settings(max_examples=60, deadline=None)
@given(h=st.floats(500.0, 20000.0), ratio=st.floats(1.001, 6.0), pitch=st.floats(-0.05, 0.05),
       yaw=st.floats(-0.05, 0.05), side=st.sampled_from(["right", "left"]), ground=st.floats(-200.0, 300.0))
def test_flat_surface_point_satisfies_its_three_equations(h, ratio, pitch, yaw, side, ground):
    r = np.array([[10.0, -40.0, h]])
    v = np.array([[0.0, 150.0, 0.0]])
    ux, _, ub, _ = antenna_axes(r, v, "LOCAL", 0.5, pitch, yaw, side)
    rho = np.array([ratio * (h - ground) / np.cos(pitch)])  # the tilted beam plane must reach the ground
    p = surface_point(r[0], ux[0], rho, ground, side, "LOCAL")[0]
    assert np.all(np.isfinite(p))
    d = p - r[0]
    assert abs(np.linalg.norm(d) - rho[0]) < 1e-6 * rho[0]
    assert abs(d @ ux[0]) < 1e-6 * rho[0]
    assert abs(p[2] - ground) < 1e-6 * rho[0]
    assert (1.0 if side == "right" else -1.0) * (p[0] - r[0, 0]) > 0  # on the looking side (+x right)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(x=st.floats(4900.0, 5300.0), y=st.floats(-300.0, 300.0), vx=st.floats(-20.0, 20.0),
       vy=st.floats(-60.0, 60.0), d=st.floats(-5.0, 5.0).filter(lambda z: abs(z) > 0.1),
       effects=st.sets(st.sampled_from(["range_migration", "antenna_pattern", "target_motion", "second_channel"])))
def test_kernel_equals_reference_on_random_airborne_scenes(x, y, vx, vy, d, effects):
    tg = f"[[targets]]\nx_m = {x}\ny_m = {y}\nvx_mps = {vx}\nvy_mps = {vy}\namplitude = 0.7\nphase_deg = 20\n"
    sc = parse_scene(linear_scene_text(effects=tuple(sorted(effects)), targets=tg, n_lines=300,
                                       extra=f"[second_channel]\nreceiver_offset_m = {d}\n"), "p.toml")
    ctx, traj, motion, axes, rot, points, clutter, _ = prepare(sc)
    args = kernel_args(sc, ctx, traj, motion, axes, rot, _concat(points, clutter))
    shape = (len(ctx.receiver_offsets_m), sc.radar.n_lines, sc.radar.n_samples)
    a = np.zeros(shape, np.complex128)
    b = np.zeros(shape, np.complex128)
    echo_kernel(a, *args, 23, 0, 1 << 62)
    echo_reference(b, *args)
    assert np.max(np.abs(a - b)) < 1e-9


@given(st.lists(st.floats(-40.0, 40.0), min_size=1, max_size=50), st.integers(2, 8))
def test_quantizer_odd_levels_monotone_and_within_half_step(u, bits):
    u = np.sort(np.array(u))
    q = quantize(u + 0j, bits).real.astype(float)
    top = 2**bits - 1
    assert np.all(np.mod(q, 2) == 1) and np.all(np.abs(q) <= top)
    assert np.all(np.diff(q) >= 0)
    inside = np.abs(u) < top + 1
    assert np.all(np.abs(q[inside] - u[inside]) <= 1.0 + 1e-6)
