"""Calibrated backscatter images: beta0, sigma0 and terrain-flattened gamma0 of a multilooked SLC.

beta0 and sigma0 come from the SLC's look-up tables (:mod:`sarcli.calibration.radiometry`). gamma0 is
normalised by the projected-area method [Small2011]: gamma0 = beta0 A_beta / A_gamma, with A_beta = dr dx
the reference area of a radar pixel in the slant plane (dr the slant-range spacing, dx the line spacing
on the ground) and A_gamma the area of the terrain that the pixel sees, projected on the plane normal to
the line of sight, summed over every DEM facet that maps into the pixel (several in layover, none in
shadow). Over flat ground A_gamma = A_beta cot(theta_i), giving gamma0 = beta0 tan(theta_i), which is the
LUT's ellipsoid gamma0: without a DEM that is what is written.

Facets: the DEM is sampled on a latitude/longitude lattice over the image's footprint at about half a
multilooked pixel; each lattice cell is two triangles with ECEF vertices. Per triangle: its area vector
N (outward, up), its zero-Doppler time and range (``orbit.geometry.doppler_time``) and the unit line
of sight l from the platform there; A_gamma contribution = -N . l when the facet faces the radar.
Masked (NaN): pixels that receive a facet facing away from the radar (shadow: local incidence beyond
90 deg) or a facet whose orientation in radar coordinates is reversed (layover: the terrain rises
toward the radar faster than the look angle, so range decreases with ground range), and pixels with
no facet (radar shadow cast by a neighbour leaves them empty). Cost: a Doppler solve per facet
centroid (vectorized); meant for scenes of a few thousand multilooked pixels a side.
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError
from sarcli.model.slc import SLC
from sarcli.model.terrain import ConstantHeight, Terrain


def _look_axes(slc: SLC, looks_az: int, looks_rg: int, shape: tuple[int, int]):
    n, m = shape
    t = slc.azimuth_time[: n * looks_az].reshape(n, looks_az).mean(axis=1)
    r = slc.slant_range[: m * looks_rg].reshape(m, looks_rg).mean(axis=1)
    return t, r


def flattening(slc: SLC, looks_az: int, looks_rg: int, shape: tuple[int, int], terrain: Terrain) -> np.ndarray:
    """A_beta / A_gamma per multilooked pixel (module docstring), NaN where shadow, layover or no facet."""
    from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef
    from orbit.geometry import doppler_time
    from sarcli.calibration.radiometry import node_geometry
    from sarcli.focus.geolocation import platform_state, state_vectors, zero_doppler_points

    if slc.orbit is None or slc.orbit.frame == "LOCAL":
        raise SarcliError("gamma0 over a DEM needs an Earth orbit")
    n, m = shape
    t, r = _look_axes(slc, looks_az, looks_rg, shape)
    lam = slc.radar.wavelength_m
    # footprint: the image corners on the ellipsoid, widened by 4 pixels and by the ground shift of the
    # highest and lowest terrain there (h / tan(incidence)); the lattice at half a pixel
    tt, rr = np.meshgrid(t[[0, -1]], r[[0, -1]], indexing="ij")
    corners = zero_doppler_points(slc.orbit, slc.epoch_utc, tt, rr, lam, slc.look_side, ConstantHeight(0.0))
    lat, lon, _ = ecef_to_geodetic(corners.reshape(-1, 3))
    prf = float(slc.parameters.get("prf_hz") or slc.prf_hz)
    geo = node_geometry(slc, t[[0, n // 2]], r[[0, m // 2]], 0.0)
    dx = float(geo.v_g[1, 1]) / prf * looks_az
    dg = slc.range_spacing_m * looks_rg / float(np.sin(geo.incidence[1, 1]))
    step_m = 0.5 * min(dx, dg)
    cla, clo = np.meshgrid(np.linspace(lat.min(), lat.max(), 33), np.linspace(lon.min(), lon.max(), 33), indexing="ij")
    relief = float(np.max(np.abs(np.asarray(terrain.height(cla, clo), np.float64))))
    pad = (4.0 * max(dx, dg) + 1.2 * relief / np.tan(float(geo.incidence[0, 0]))) / 111e3
    lat0, lat1 = float(lat.min()) - pad, float(lat.max()) + pad
    lon0, lon1 = float(lon.min()) - pad, float(lon.max()) + pad
    coslat = max(np.cos(np.radians(0.5 * (lat0 + lat1))), 0.05)
    n_lat = int(np.ceil((lat1 - lat0) * 111e3 / step_m)) + 1
    n_lon = int(np.ceil((lon1 - lon0) * 111e3 * coslat / step_m)) + 1
    if n_lat * n_lon > 4e7:
        raise SarcliError(f"gamma0 terrain flattening would need {n_lat} x {n_lon} DEM facets: use more looks")
    la, lo = np.meshgrid(np.linspace(lat0, lat1, n_lat), np.linspace(lon0, lon1, n_lon), indexing="ij")
    p = geodetic_to_ecef(la, lo, np.asarray(terrain.height(la, lo), np.float64))
    a, b, c, d = p[:-1, :-1], p[:-1, 1:], p[1:, :-1], p[1:, 1:]  # (south-west, south-east, north-west, north-east)
    tris = [(a, b, d), (a, d, c)]  # counter-clockwise seen from above: area vectors point up
    sv = state_vectors(slc.orbit, slc.epoch_utc)
    area = np.zeros(n * m)
    bad = np.zeros(n * m, bool)
    hit = np.zeros(n * m, bool)
    t_mid = float(0.5 * (slc.azimuth_time[0] + slc.azimuth_time[-1]))
    # the orientation a facet of FLAT ground has in radar coordinates (the lattice's centre cell at height 0):
    # a facet whose orientation is reversed is in layover
    ic, jc = n_lat // 2, n_lon // 2
    flat = geodetic_to_ecef(la[ic:ic + 2, jc:jc + 2], lo[ic:ic + 2, jc:jc + 2], np.zeros((2, 2)))
    ref = [doppler_time(sv, v.reshape(1, 3), t_guess=np.array([t_mid])) for v in (flat[0, 0], flat[0, 1], flat[1, 1])]
    flat_sign = np.sign(((ref[1][0] - ref[0][0]) * (ref[2][1] - ref[0][1])
                         - (ref[1][1] - ref[0][1]) * (ref[2][0] - ref[0][0]))[0])
    for v0, v1, v2 in tris:
        cen = ((v0 + v1 + v2) / 3.0).reshape(-1, 3)
        nvec = 0.5 * np.cross(v1 - v0, v2 - v0).reshape(-1, 3)
        tz, r0 = doppler_time(sv, cen, t_guess=np.full(cen.shape[0], t_mid))
        row = np.floor((tz - t[0]) / (t[1] - t[0] if n > 1 else 1.0) + 0.5).astype(np.int64)
        col = np.floor((r0 - r[0]) / (r[1] - r[0] if m > 1 else 1.0) + 0.5).astype(np.int64)
        inside = (row >= 0) & (row < n) & (col >= 0) & (col < m)
        pos, _ = platform_state(slc.orbit, slc.epoch_utc, tz[inside])
        los = cen[inside] - pos
        los /= np.linalg.norm(los, axis=1, keepdims=True)
        proj = -np.sum(nvec[inside] * los, axis=1)
        # orientation in radar coordinates: the sign of the ground->radar Jacobian along the triangle
        rad = []
        for v in (v0, v1, v2):
            tv, rv = doppler_time(sv, v.reshape(-1, 3)[inside], t_guess=tz[inside])
            rad.append((tv, rv))
        jac = (rad[1][0] - rad[0][0]) * (rad[2][1] - rad[0][1]) - (rad[1][1] - rad[0][1]) * (rad[2][0] - rad[0][0])
        k = row[inside] * m + col[inside]
        area += np.bincount(k, weights=np.maximum(proj, 0.0), minlength=n * m)
        bad |= np.bincount(k, weights=((proj <= 0.0) | (np.sign(jac) != flat_sign)).astype(float),
                           minlength=n * m) > 0
        hit |= np.bincount(k, minlength=n * m) > 0
    a_beta = slc.range_spacing_m * looks_rg * dx
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(hit & ~bad & (area > 0), a_beta / area, np.nan)
    return ratio.reshape(n, m)


def radiometric_intensity(slc: SLC, inten: np.ndarray, looks_az: int, looks_rg: int, kind: str,
                          terrain: Terrain | None, noise_subtraction: bool, tags: dict) -> tuple[np.ndarray, dict]:
    """(calibrated intensity float32 with NaN where not calibrated, the tags with the radiometry added)
    for the GeoTIFFs of ``slc``'s multilooked intensity ``inten``."""
    import warnings

    from sarcli.calibration.radiometry import calibrated_intensity

    cal = slc.calibration
    if cal is None:
        raise SarcliError("--radiometry: the SLC carries no radiometric calibration (focus it with this sarcli)")
    dem = terrain is not None and not isinstance(terrain, ConstantHeight)
    if kind == "gamma0" and dem:
        out = calibrated_intensity(slc, inten, looks_az, looks_rg, "beta0", noise_subtraction)
        out = (out * flattening(slc, looks_az, looks_rg, inten.shape, terrain)).astype(np.float32)
        how = "gamma0 terrain-flattened over the DEM (projected area, Small 2011); shadow and layover: nodata"
    else:
        out = calibrated_intensity(slc, inten, looks_az, looks_rg, kind, noise_subtraction)
        how = {"beta0": "beta0 (radar brightness)", "sigma0": "sigma0 on the ellipsoid at the focusing height",
               "gamma0": "gamma0 on the ellipsoid at the focusing height (no DEM: not terrain-flattened)"}[kind]
    if cal.not_applied:
        warnings.warn(f"{kind}: not applied: {'; '.join(cal.not_applied)} (relative backscatter)", stacklevel=2)
    nes0 = cal.nes0[np.isfinite(cal.nes0)]
    tags = {**(tags or {}), "RADIOMETRY": kind, "RADIOMETRY_DEFINITION": how,
            "RADIOMETRY_UNITS": f"band 1: sqrt({kind}) (linear amplitude, 1); band 2: {kind} in dB (10 log10)",
            "RADIOMETRY_APPLIED": "; ".join(cal.applied),
            "RADIOMETRY_NOT_APPLIED": "; ".join(cal.not_applied) or "none",
            "CALIBRATION_CONSTANT_K": f"{cal.constant:.9g}",
            "NOISE_SUBTRACTED": "yes" if noise_subtraction else "no",
            "NESZ_SIGMA0_DB_MEDIAN": f"{10 * np.log10(np.median(nes0)):.2f}" if nes0.size else "unknown",
            "NOISE_SOURCE": str(cal.details.get("noise_source", "unknown"))}
    return out, tags
