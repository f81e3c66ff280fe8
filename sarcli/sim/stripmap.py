"""``simulate(scene) -> RawProduct``: the stripmap echo simulator (see ``sarcli.sim.kernel`` for the physics).

Steps: effects configure the context; platform truth at every pulse; antenna axes per pulse;
targets and clutter placed in the target frame; beam windows by bisection; numba echo kernel;
truth; post-processing effects (replica, noise, quantization) in their ORDER.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import get_num_threads

from sarcli.model.raw import Attitude, Radar, RawProduct
from sarcli.sim.binned import BLOCK_LINES, add_binned_echo
from sarcli.sim.context import SimContext
from sarcli.sim.effects import apply_all, configure_all
from sarcli.sim.geometry import Motion, closest_approach
from sarcli.sim.kernel import beam_windows, echo_kernel
from sarcli.sim.platform import Trajectory, build_trajectory
from sarcli.sim.pointing import antenna_axes
from sarcli.sim.scene import Scene
from sarcli.sim.targets import TargetSet, clutter_scatterers, point_targets
from sarcli.sim.truth import doppler_truth, targets_table

N_ATTITUDE_RECORDS = 64


def _concat(a: TargetSet, b: TargetSet) -> TargetSet:
    return TargetSet(np.concatenate([a.q, b.q]), np.concatenate([a.u, b.u]),
                     np.concatenate([a.t_ref, b.t_ref]), np.concatenate([a.amp, b.amp]))


def _by_range(ts: TargetSet, traj: Trajectory, motion: Motion) -> TargetSet:
    """Targets sorted by their range at the scene centre (neighbours write neighbouring grid bins: cache)."""
    p, _, _ = motion.state(ts.q, ts.u, ts.t_ref, np.zeros(len(ts)))
    r, _, _ = traj.state(np.zeros(1))
    o = np.argsort(np.linalg.norm(p - r, axis=-1), kind="stable")
    return TargetSet(ts.q[o], ts.u[o], ts.t_ref[o], ts.amp[o])


def prepare(scene: Scene):
    """Everything the kernel needs: (ctx, traj, motion, axes, rotations, targets, clutter summary)."""
    ctx = SimContext(scene)
    configure_all(ctx)
    traj = build_trajectory(scene)
    motion = Motion(scene.epoch_utc, scene.center_time_s, ctx.earth_rotation)
    axes = antenna_axes(traj.position, traj.velocity, traj.frame, scene.antenna.look_angle_rad,
                        ctx.pitch_rad, ctx.yaw_rad, scene.radar.look_side)
    rot = np.ascontiguousarray(motion.rotation(traj.pulse_time))
    points = point_targets(ctx, traj, motion)
    clutter, patches = clutter_scatterers(ctx, traj, motion)
    return ctx, traj, motion, axes, rot, points, clutter, patches


def kernel_args(scene: Scene, ctx: SimContext, traj: Trajectory, motion: Motion, axes, rot, ts: TargetSet):
    """Positional arguments of ``echo_kernel``/``echo_reference`` after ``out`` (before ``block``, lines)."""
    ux, ue, _, _ = axes
    rad, ant = scene.radar, scene.antenna
    lam = rad.wavelength_m
    t = traj.pulse_time
    smax = ant.beam_extent * lam / ant.length_m
    q, u, tref = (np.ascontiguousarray(x) for x in (ts.q, ts.u, ts.t_ref))
    k0, k1 = beam_windows(t, traj.position, ux, rot, q, u, tref, smax)
    if ctx.range_migration or len(ts) == 0:
        r0 = np.zeros(len(ts))
    else:
        r0 = closest_approach(traj, motion, q, u, tref)[1]
    return (t, traj.position, np.ascontiguousarray(ux), np.ascontiguousarray(ue), rot, q, u, tref,
            ts.amp.astype(np.complex128), k0, k1, r0, np.array(ctx.receiver_offsets_m, np.float64), lam,
            rad.chirp_rate_hz_per_s, rad.pulse_length_s, rad.range_sampling_rate_hz, rad.window_start_s,
            ctx.range_migration, ctx.antenna_pattern, ant.length_m / lam, ant.height_m / lam,
            ant.beam_extent * lam / ant.height_m)


def simulate(scene: Scene, dtype=np.complex64, progress: Callable[[int], None] | None = None) -> RawProduct:
    """Simulate the scene's raw echoes (complex64; complex128 for accuracy tests) with its truth.

    ``progress(n)`` is called as lines are done (total n_lines, twice that with binned clutter).
    """
    ctx, traj, motion, axes, rot, points, clutter, patches = prepare(scene)
    rad = scene.radar
    n_ch = len(ctx.receiver_offsets_m)
    out = np.zeros((n_ch, rad.n_lines, rad.n_samples), dtype)
    tick = progress or (lambda n: None)
    block = max(8, BLOCK_LINES // (4 * get_num_threads()))
    exact = _concat(points, clutter) if scene.clutter_model == "exact" else points
    args = kernel_args(scene, ctx, traj, motion, axes, rot, exact)
    for a in range(0, rad.n_lines, BLOCK_LINES):
        echo_kernel(out, *args, block, a, a + BLOCK_LINES)
        tick(min(BLOCK_LINES, rad.n_lines - a))
    if scene.clutter_model == "binned" and len(clutter):
        bargs = kernel_args(scene, ctx, traj, motion, axes, rot, _by_range(clutter, traj, motion))
        add_binned_echo(out, bargs, rad, scene.clutter_oversampling, block, tick)

    tc = scene.center_time_s
    ux, _, ub, pitch_total = axes
    idx = np.unique(np.linspace(0, rad.n_lines - 1, min(rad.n_lines, N_ATTITUDE_RECORDS)).astype(int))
    attitude = Attitude(tc + traj.pulse_time[idx], pitch_total[idx], np.zeros(idx.size),
                        np.full(idx.size, ctx.yaw_rad))
    fdc, fr = doppler_truth(ctx, traj, motion)
    truth = {
        "scene_toml": scene.source_text,
        "effects": ",".join(scene.effects),
        "targets": targets_table(ctx, traj, motion, points),
        "doppler_centroid_hz": fdc,
        "doppler_rate_hz_per_s": fr,
        "doppler_truth_time_s": np.float64(tc),
        "beam_look_angle_rad": np.float64(scene.antenna.look_angle_rad),
        "reference_height_m": np.float64(scene.reference_height_m),
        "seed": np.int64(scene.seed),
    }
    if patches:
        tab = np.zeros(len(patches), [("n_scatterers", "i8"), ("area_m2", "f8"), ("sigma0", "f8"),
                                      ("center_x_m", "f8"), ("center_y_m", "f8"), ("center_z_m", "f8"),
                                      ("reference_time_s", "f8")])
        for i, row in enumerate(patches):
            tab[i] = (row["n_scatterers"], row["area_m2"], row["sigma0"], *row["center"], tc + row["t_ref"])
        truth["clutter_patches"] = tab
    v_mid = float(np.linalg.norm(traj.velocity[rad.n_lines // 2]))
    radar = Radar(
        carrier_frequency_hz=rad.carrier_frequency_hz, wavelength_m=rad.wavelength_m, prf_hz=rad.prf_hz,
        range_sampling_rate_hz=rad.range_sampling_rate_hz, chirp_rate_hz_per_s=rad.chirp_rate_hz_per_s,
        pulse_length_s=rad.pulse_length_s, window_start_s=rad.window_start_s, first_range_m=rad.first_range_m,
        quantization_bits=0, receiver_offsets_m=tuple(ctx.receiver_offsets_m),
        platform_velocity_mps=v_mid if traj.frame == "LOCAL" else None,
        # the antenna the echoes saw (radiometry): without the pattern effect the illumination is uniform,
        # the pattern of an aperture of zero size (sinc^2(0) = 1)
        antenna_length_m=scene.antenna.length_m if ctx.antenna_pattern else 0.0,
        antenna_height_m=scene.antenna.height_m if ctx.antenna_pattern else 0.0,
        antenna_look_angle_rad=scene.antenna.look_angle_rad)
    product = RawProduct(
        echo=out[0], azimuth_time=tc + traj.pulse_time, epoch_utc=scene.epoch_utc, radar=radar,
        look_side=rad.look_side, source="simulated", echo_channels=out[1:] if n_ch > 1 else None,
        orbit=traj.product_orbit, attitude=attitude, truth=truth)
    apply_all(ctx, product)
    return product
