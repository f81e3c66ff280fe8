"""Point targets and clutter scatterers placed in the target frame (see ``sarcli.sim.geometry``).

Placement: ('geodetic', lat, lon, h) -> WGS-84 via pyproj; ('slant', rho, t_b, h) -> the point at
slant range rho in the beam-centre plane at relative time t_b, on the surface at height h, on the
looking side (so it crosses the beam centre at t_b whatever effects are listed); ('local', x, y, z).
Geodetic and local targets are referenced to the scene centre (t_ref = 0), slant ones to t_b.

Clutter patch: n = round(density * area) scatterers uniformly placed in a ground rectangle centred
on the patch centre, axes along track (the beam's along-track axis projected on the ground) and
across it; each has amplitude sqrt(sigma0 * area / n) and a uniform random phase (seeded stream
"clutter<j>"), so the mean backscattered power per m^2 is sigma0 and the speckle is fully developed
when several scatterers share a resolution cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from orbit.geodetic import geodetic_to_ecef
from sarcli.errors import FormatError
from sarcli.sim.geometry import Motion, enu_basis, snap_to_height, surface_point
from sarcli.sim.pointing import antenna_axes


@dataclass
class TargetSet:
    q: np.ndarray  # (n, 3) target-frame position at t_ref
    u: np.ndarray  # (n, 3) target-frame velocity
    t_ref: np.ndarray  # (n,) relative s
    amp: np.ndarray  # (n,) complex128 reflectivity (amplitude units: sqrt of RCS)

    def __len__(self) -> int:
        return self.amp.size


def _axes_at(ctx, traj, t: float):
    r, v, _ = traj.state(np.array([t]))
    a = ctx.scene.antenna
    ux, _, _, _ = antenna_axes(r, v, traj.frame, a.look_angle_rad, ctx.pitch_rad, ctx.yaw_rad,
                               ctx.scene.radar.look_side)
    return r[0], ux[0]


def place(ctx, traj, motion: Motion, where: tuple) -> tuple[np.ndarray, float, np.ndarray]:
    """(q target frame, t_ref, along-track unit vector in the target frame) of one position spec."""
    kind = where[0]
    if kind == "local":
        q = np.array(where[1:4], np.float64)
        t_ref = 0.0
    elif kind == "geodetic":
        ecef = geodetic_to_ecef(where[1], where[2], where[3])
        eci = Motion(motion.epoch_utc, motion.center_time_s, True).rotation(np.array(0.0)) @ ecef
        q = ecef if motion.earth_rotation else eci
        t_ref = 0.0
    else:
        rho, t_ref, h = where[1], where[2], where[3]
        r, ux = _axes_at(ctx, traj, t_ref)
        p = surface_point(r, ux, np.array([rho]), h, ctx.scene.radar.look_side, traj.frame)[0]
        if not np.all(np.isfinite(p)):
            raise FormatError(f"{ctx.scene.path}: slant range {rho:.1f} m at azimuth time {t_ref:g} s "
                              "does not reach the ground (shorter than the altitude or beyond the horizon)")
        q = motion.to_target_frame(p, np.array(t_ref))
    along = motion.to_target_frame(_axes_at(ctx, traj, t_ref)[1], np.array(t_ref))
    return q, float(t_ref), along


def point_targets(ctx, traj, motion: Motion) -> TargetSet:
    sc = ctx.scene
    qs, trefs, us = [], [], []
    for tg in sc.targets:
        q, t_ref, _ = place(ctx, traj, motion, tg.where)
        qs.append(q)
        trefs.append(t_ref)
        vel = np.array(tg.velocity) if ctx.target_motion else np.zeros(3)
        us.append(enu_basis(q, traj.frame) @ vel)
    n = len(qs)
    return TargetSet(np.array(qs).reshape(n, 3), np.array(us).reshape(n, 3), np.array(trefs, np.float64),
                     np.array([tg.reflectivity for tg in sc.targets], np.complex128))


def clutter_scatterers(ctx, traj, motion: Motion) -> tuple[TargetSet, list[dict]]:
    """All clutter scatterers of the scene and a summary row per patch."""
    qs, trefs, amps, rows = [], [], [], []
    for j, patch in enumerate(ctx.scene.clutter):
        qc, t_ref, along = place(ctx, traj, motion, patch.where)
        up = enu_basis(qc, traj.frame)[:, 2]
        e_al = along - (along @ up) * up
        e_al /= np.linalg.norm(e_al)
        e_cr = np.cross(up, e_al)
        area = patch.range_extent_m * patch.azimuth_extent_m
        n = max(1, round(patch.density_per_m2 * area))
        rng = ctx.rng(f"clutter{j}")
        a = rng.uniform(-0.5, 0.5, n) * patch.azimuth_extent_m
        c = rng.uniform(-0.5, 0.5, n) * patch.range_extent_m
        phase = rng.uniform(0.0, 2.0 * np.pi, n)
        q = qc + a[:, None] * e_al + c[:, None] * e_cr
        if traj.frame == "LOCAL":
            q[:, 2] = qc[2]
        else:
            q = snap_to_height(q, patch.where[3])
        qs.append(q)
        trefs.append(np.full(n, t_ref))
        amps.append(np.sqrt(patch.sigma0 * area / n) * np.exp(1j * phase))
        rows.append({"n_scatterers": n, "area_m2": area, "sigma0": patch.sigma0, "center": qc, "t_ref": t_ref})
    if not qs:
        return TargetSet(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.complex128)), rows
    q = np.concatenate(qs)
    return TargetSet(q, np.zeros_like(q), np.concatenate(trefs), np.concatenate(amps)), rows
