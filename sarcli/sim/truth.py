"""Truth for simulated products (/truth): point-target table and the Doppler truth per range sample.

Targets table (one row per point target; clutter patches in ``clutter_patches``):
position x/y/z in the product frame at the scene centre (ECI or LOCAL), lat/lon/h (WGS-84, Earth
attitude at the scene centre; NaN for LOCAL), reflectivity, velocity in the target frame (ECEF or
ECI: m/s in those axes; LOCAL: vx, vy, vz), zero-Doppler time and closest-approach range, beam-centre
time (the target crosses the antenna's along-track-axis-normal plane) and range, and the Doppler
centroid and rate at the beam-centre time. Times are absolute (s after epoch_utc).

Doppler truth (``doppler_centroid_hz``, ``doppler_rate_hz_per_s``, per range sample, at the scene
centre time ``doppler_truth_time_s``): for each slant range the static ground point (height
``reference_height_m``, Earth-fixed with earth_rotation, else inertial) in the beam-centre plane,
with f_dc = -(2/lam) R' and f_R = -(2/lam) R'' (``sarcli.sim.geometry``). NaN where the range does
not reach the ground. This is the geometric centroid of the beam-centre plane: with a symmetric
antenna pattern it is the centre of the azimuth spectrum.
"""

from __future__ import annotations

import numpy as np

from orbit.geodetic import ecef_to_geodetic
from sarcli.sim.geometry import Motion, closest_approach, range_derivatives, surface_point
from sarcli.sim.pointing import antenna_axes

TARGET_DTYPE = np.dtype([
    ("id", "i4"), ("x_m", "f8"), ("y_m", "f8"), ("z_m", "f8"),
    ("lat_deg", "f8"), ("lon_deg", "f8"), ("height_m", "f8"),
    ("reflectivity_re", "f8"), ("reflectivity_im", "f8"),
    ("vel_x_mps", "f8"), ("vel_y_mps", "f8"), ("vel_z_mps", "f8"),
    ("zero_doppler_time_s", "f8"), ("closest_range_m", "f8"),
    ("beam_center_time_s", "f8"), ("beam_center_range_m", "f8"),
    ("doppler_centroid_hz", "f8"), ("doppler_rate_hz_per_s", "f8"),
])


def _axes(ctx, traj, t):
    r, v, a = traj.state(t)
    ant = ctx.scene.antenna
    ux, _, ub, _ = antenna_axes(r, v, traj.frame, ant.look_angle_rad, ctx.pitch_rad, ctx.yaw_rad,
                                ctx.scene.radar.look_side)
    return r, v, a, ux, ub


def beam_center_time(ctx, traj, motion, ts, t_start, iterations: int = 10, h: float = 1e-3):
    """Relative time when each target crosses the beam-centre plane: Newton on (p - r).ux = 0."""
    lo, hi = traj.span
    t = np.array(t_start, np.float64)

    def g(tt):
        r, _, _, ux, _ = _axes(ctx, traj, tt)
        p, _, _ = motion.state(ts.q, ts.u, ts.t_ref, tt)
        return np.einsum("...i,...i->...", p - r, ux)

    for _ in range(iterations):
        f = g(t)
        fp = (g(t + h) - g(t - h)) / (2 * h)
        t = np.clip(t - f / fp, lo, hi)
    return t


def targets_table(ctx, traj, motion: Motion, ts) -> np.ndarray:
    sc = ctx.scene
    lam = sc.radar.wavelength_m
    n = len(ts)
    out = np.zeros(n, TARGET_DTYPE)
    if n == 0:
        return out
    t0, r0 = closest_approach(traj, motion, ts.q, ts.u, ts.t_ref)
    tb = beam_center_time(ctx, traj, motion, ts, t0)
    r, v, a = traj.state(tb)
    p, pd, pdd = motion.state(ts.q, ts.u, ts.t_ref, tb)
    rb, rd, rdd = range_derivatives(r, v, a, p, pd, pdd)
    pc, _, _ = motion.state(ts.q, ts.u, ts.t_ref, np.zeros(n))
    out["id"] = np.arange(n)
    out["x_m"], out["y_m"], out["z_m"] = pc.T
    if traj.frame == "LOCAL":
        for k in ("lat_deg", "lon_deg", "height_m"):
            out[k] = np.nan
    else:
        ecef = Motion(motion.epoch_utc, motion.center_time_s, True).to_target_frame(pc, np.zeros(n))
        out["lat_deg"], out["lon_deg"], out["height_m"] = ecef_to_geodetic(ecef)
    out["reflectivity_re"], out["reflectivity_im"] = ts.amp.real, ts.amp.imag
    out["vel_x_mps"], out["vel_y_mps"], out["vel_z_mps"] = ts.u.T
    tc = sc.center_time_s
    out["zero_doppler_time_s"] = tc + t0
    out["closest_range_m"] = r0
    out["beam_center_time_s"] = tc + tb
    out["beam_center_range_m"] = rb
    out["doppler_centroid_hz"] = -2.0 / lam * rd
    out["doppler_rate_hz_per_s"] = -2.0 / lam * rdd
    return out


def doppler_truth(ctx, traj, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """(f_dc, f_R) per range sample at the scene centre (module docstring)."""
    sc = ctx.scene
    rho = sc.radar.slant_range()
    r, v, a, ux, _ = _axes(ctx, traj, np.zeros(1))
    p = surface_point(r[0], ux[0], rho, sc.reference_height_m, sc.radar.look_side, traj.frame)
    good = np.isfinite(p[:, 0])
    fdc = np.full(rho.size, np.nan)
    fr = np.full(rho.size, np.nan)
    if np.any(good):
        t = np.zeros(int(good.sum()))
        q = motion.to_target_frame(p[good], t)
        pp, pd, pdd = motion.state(q, np.zeros_like(q), t, t)
        _, rd, rdd = range_derivatives(r, v, a, pp, pd, pdd)
        fdc[good] = -2.0 / sc.radar.wavelength_m * rd
        fr[good] = -2.0 / sc.radar.wavelength_m * rdd
    return fdc, fr
