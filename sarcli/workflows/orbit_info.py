"""Workflow ``orbit_info``: a raw product's state vectors: frame, span, spacing, coverage of the echo,
and for ECI/ECEF orbits the scene geometry (sub-satellite point, altitude, pass direction, zero-Doppler
look and incidence angles); for CEOS products the delivered hour angle against sarcli's GMST."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ProductError
from sarcli.workflows import base


@dataclass(frozen=True)
class Config:
    """raw: raw product (HDF5) with /orbit."""

    raw: Path


@dataclass
class Report(base.Report):
    """summary: the ``--json`` keys (path, frame, epoch_utc, n_vectors, start/stop_utc, span_s, spacing_s,
    spacing_min_s/max_s, default_n_nodes, echo_start/stop_s, margin_before/after_s, echo_covered,
    orbit_radius_m, geometry, gha_minus_gmst_deg/_ground_m)."""

    summary: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.summary)

    def lines(self) -> list[str]:
        s = self.summary
        out = [f"{s['path']}: {s['n_vectors']} state vectors ({s['frame']}), {s['start_utc']} .. {s['stop_utc']}",
               f"  spacing {s['spacing_s']:.6g} s (min {s['spacing_min_s']:.6g}, max {s['spacing_max_s']:.6g}); "
               f"Hermite default N = {s['default_n_nodes']}"]
        cover = "inside" if s["echo_covered"] else "NOT inside (interpolation will refuse the lines outside)"
        out.append(f"  echo {s['echo_start_s']:.6f} .. {s['echo_stop_s']:.6f} s: {cover} the span; margins "
                   f"{s['margin_before_s']:.1f} s before, {s['margin_after_s']:.1f} s after")
        g = s.get("geometry") or {}
        if "altitude_m" in g:
            out.append(f"  scene centre t = {g['scene_center_time_s']:.6f} s: {g['pass']} pass, sub-satellite lat "
                       f"{g['sub_satellite_lat_deg']:.4f} deg, lon {g['sub_satellite_lon_deg']:.4f} deg, "
                       f"altitude {g['altitude_m'] / 1e3:.3f} km, ECEF speed {g['ecef_speed_mps']:.2f} m/s")
        if "look_angle_deg" in g:
            out.append("  zero-Doppler look / incidence at slant range " + ", ".join(
                f"{r / 1e3:.3f} km: {lk:.4f} / {ic:.4f} deg" for r, lk, ic in
                zip(g["zero_doppler_slant_range_m"], g["look_angle_deg"], g["incidence_angle_deg"], strict=True)))
        if "geometry_note" in g:
            out.append(f"  geometry: {g['geometry_note']}")
        if "gha_minus_gmst_deg" in s:
            out.append(f"  frame check: product hour angle - GMST = {s['gha_minus_gmst_deg']:.6f} deg "
                       f"({s['gha_minus_gmst_ground_m']:.1f} m at the equator)")
        return out


def state_vectors(path: Path):
    """(RawProduct without echo, StateVectors) of a raw product; one-line error if it has no orbit."""
    from orbit.statevectors import StateVectors
    from sarcli.io.raw import read_raw

    raw = read_raw(path, load_echo=False)
    if raw.orbit is None:
        raise ProductError(f"{path}: product has no /orbit state vectors")
    return raw, StateVectors.from_record(raw.orbit, raw.epoch_utc)


def _scene_geometry(raw, sv, n_samples: int) -> dict:
    """Sub-satellite point, altitude, pass direction and the zero-Doppler look and incidence angles of the
    first and last range samples, at the scene-centre line (ECI/ECEF orbits)."""
    import numpy as np

    from orbit.geodetic import ecef_to_geodetic
    from orbit.geometry import incidence_angle, look_angle, target_from_doppler
    from sarcli.model.constants import C_LIGHT

    svf = sv.to_ecef()
    t = raw.azimuth_time
    inside = t[(t >= sv.span[0]) & (t <= sv.span[1])]
    if inside.size == 0:
        return {}
    tc = float(inside[inside.size // 2])
    r, v, _ = svf.interpolate(tc)
    lat, lon, h = (float(x) for x in ecef_to_geodetic(r))
    up = np.array([np.cos(np.radians(lat)) * np.cos(np.radians(lon)),
                   np.cos(np.radians(lat)) * np.sin(np.radians(lon)), np.sin(np.radians(lat))])
    north = np.array([0.0, 0.0, 1.0]) - up * up[2]
    out = {"scene_center_time_s": tc, "sub_satellite_lat_deg": lat, "sub_satellite_lon_deg": lon,
           "altitude_m": h, "pass": "ascending" if v @ north > 0 else "descending",
           "ecef_speed_mps": float(np.linalg.norm(v))}
    rng = np.array([raw.radar.first_range_m,
                    raw.radar.first_range_m + (n_samples - 1) * C_LIGHT / (2.0 * raw.radar.range_sampling_rate_hz)])
    try:
        p = target_from_doppler(r, v, rng, raw.radar.wavelength_m, 0.0, raw.look_side)
    except ValueError as e:  # the range does not reach the Earth from this orbit: say so, don't fail
        out["geometry_note"] = str(e)
        return out
    rc = np.broadcast_to(r, p.shape)
    out.update(zero_doppler_slant_range_m=rng.tolist(), look_angle_deg=np.degrees(look_angle(rc, p)).tolist(),
               incidence_angle_deg=np.degrees(incidence_angle(rc, p)).tolist())
    return out


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Summarize the product's state vectors (module docstring)."""
    import numpy as np

    from orbit.constants import WGS84_A
    from orbit.timeutil import add_seconds
    from sarcli.io.raw import raw_shape

    with base.using(provenance):
        raw, sv = state_vectors(config.raw)
        dt = np.diff(sv.time)
        t = raw.azimuth_time
        t0, t1 = sv.span
        s: dict[str, Any] = {
            "path": str(config.raw), "frame": sv.frame, "epoch_utc": raw.epoch_utc, "n_vectors": len(sv),
            "start_utc": add_seconds(raw.epoch_utc, t0), "stop_utc": add_seconds(raw.epoch_utc, t1),
            "span_s": t1 - t0, "spacing_s": sv.spacing, "spacing_min_s": float(dt.min()),
            "spacing_max_s": float(dt.max()), "default_n_nodes": sv.default_n_nodes(),
            "echo_start_s": float(t.min()), "echo_stop_s": float(t.max()),
            "margin_before_s": float(t.min() - t0), "margin_after_s": float(t1 - t.max()),
            "echo_covered": bool(t.min() >= t0 and t.max() <= t1),
            "orbit_radius_m": np.linalg.norm(sv.position, axis=1).tolist(),
        }
        if sv.frame != "LOCAL":
            s["geometry"] = _scene_geometry(raw, sv, raw_shape(config.raw)[1])
        gha = raw.extra_attrs.get("ceos_gha_minus_gmst_deg")
        if gha is not None:  # CEOS products: the delivered hour angle tells which equinox the vectors use
            s["gha_minus_gmst_deg"] = float(gha)
            s["gha_minus_gmst_ground_m"] = abs(np.radians(float(gha))) * WGS84_A
        return Report(s)
