"""Where the configuration's areas, watch points and DEM fall on the campaign's image grid.

The grid is the slant plane of the rail: rows R0 (distance from the rail line), columns x (along the
rail). A point of the site frame (x along the rail, y across it on the look side, z up; the antenna at
height h) is at ``R0 = sqrt(y^2 + (z - h)^2)``; a pixel (x, R0) on the ground of height z is at
``y = sqrt(R0^2 - (h - z)^2)`` (:func:`sarcli.gbsar.geocode.slant_to_enu`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sarcli.errors import ConfigError
from sarcli.gbsar.geocode import enu_to_utm_affine, slant_to_enu, utm_epsg
from sarcli.model.gbsar import GbsarImage
from sarcli.monitor.config import AreaEntry, WatchPoint


def inside_polygon(px: np.ndarray, py: np.ndarray, polygon: tuple[tuple[float, float], ...]) -> np.ndarray:
    """Even-odd rule: True for points (px, py) inside the polygon (vertices in order, closed implicitly)."""
    inside = np.zeros(np.broadcast(px, py).shape, bool)
    n = len(polygon)
    for i in range(n):
        (x1, y1), (x2, y2) = polygon[i], polygon[(i + 1) % n]
        if y1 == y2:
            continue
        crosses = (py >= min(y1, y2)) & (py < max(y1, y2))
        x_at = x1 + (py - y1) * (x2 - x1) / (y2 - y1)
        inside ^= crosses & (px < x_at)
    return inside


def area_masks(areas: tuple[AreaEntry, ...], img: GbsarImage) -> np.ndarray:
    """(n_areas, n_r, n_x) bool: polygons in the image frame (azimuth, range) or the site frame (x, y on
    flat ground z = 0), or boolean ``.npy`` masks of the grid's shape."""
    shape = (img.range_m.size, img.azimuth_m.size)
    rr, xx = np.meshgrid(img.range_m, img.azimuth_m, indexing="ij")
    out = np.zeros((len(areas), *shape), bool)
    for k, a in enumerate(areas):
        if a.mask is not None:
            try:
                m = np.load(Path(a.mask), allow_pickle=False)
            except (OSError, ValueError) as e:
                raise ConfigError(f"[[areas]] {a.name}: cannot read the mask {a.mask} ({e})") from None
            if m.shape != shape:
                raise ConfigError(f"[[areas]] {a.name}: the mask {a.mask} has shape {m.shape}, the image grid "
                                  f"{shape} (range x azimuth)")
            out[k] = m.astype(bool)
        elif a.frame == "image":
            out[k] = inside_polygon(xx, rr, a.polygon)
        else:
            with np.errstate(invalid="ignore"):
                y = np.sqrt(rr ** 2 - img.rail_height_m ** 2)
            out[k] = inside_polygon(xx, y, a.polygon) & np.isfinite(y)
        if not out[k].any():
            raise ConfigError(f"[[areas]] {a.name}: no pixel of the image grid is inside it (range "
                              f"{img.range_m[0]:.1f}-{img.range_m[-1]:.1f} m, azimuth {img.azimuth_m[0]:.1f}-"
                              f"{img.azimuth_m[-1]:.1f} m)")
    return out


def watch_pixels(watch: tuple[WatchPoint, ...], img: GbsarImage, amplitude: np.ndarray) -> np.ndarray:
    """(n, 2) (row, column) of each watch point: the brightest pixel of ``amplitude`` within its radius
    (the nearest pixel with radius 0)."""
    out = np.zeros((len(watch), 2), np.int64)
    for k, w in enumerate(watch):
        if w.azimuth_m is not None:
            x, r0 = w.azimuth_m, w.range_m
        else:
            x, r0 = w.x_m, math.hypot(w.y_m, w.z_m - img.rail_height_m)
        dr = img.range_m[:, None] - r0
        dx = img.azimuth_m[None, :] - x
        dist = np.hypot(dr, dx)
        cell = math.hypot(*(float(np.ptp(a[:2])) if a.size > 1 else 0.0 for a in (img.range_m, img.azimuth_m)))
        if float(dist.min()) > max(w.radius_m, cell):
            raise ConfigError(f"[[watch]] {w.name}: (azimuth {x:.1f} m, range {r0:.1f} m) is outside the image grid")
        near = dist <= max(w.radius_m, float(dist.min()))
        cand = np.where(near, np.nan_to_num(amplitude), -1.0)
        out[k] = np.unravel_index(int(np.argmax(cand)), cand.shape)
    return out


def pixel_heights(dem_path: str | Path, img: GbsarImage, iterations: int = 6) -> np.ndarray:
    """Height z (m, site frame) of the ground under every pixel, from a GeoTIFF DEM in the site's local
    east/north frame (the orthographic CRS of ``gbsar focus --enu-geotiff``) or in the site's UTM zone
    (heights relative to the site's origin height). The ground position of a pixel depends on its
    height: ``y = sqrt(R0^2 - (h - z)^2)`` is iterated from z = 0. NaN outside the DEM."""
    import rasterio

    try:
        ds = rasterio.open(dem_path)
    except rasterio.errors.RasterioIOError as e:
        raise ConfigError(f"[aps] dem: cannot read {dem_path} ({e})") from None
    site = img.site
    with ds:
        band = ds.read(1, masked=True).astype(np.float64).filled(np.nan)
        crs = ds.crs.to_dict() if ds.crs else {}
        epsg = ds.crs.to_epsg() if ds.crs else None
        inv = ~ds.transform
    utm = None
    ortho = (crs.get("proj") == "ortho" and abs(crs.get("lat_0", 1e9) - site.latitude_deg) < 1e-7
             and abs(crs.get("lon_0", 1e9) - site.longitude_deg) < 1e-7)
    if epsg == utm_epsg(site):
        utm, _ = enu_to_utm_affine(site, float(img.range_m[-1]) + float(np.ptp(img.azimuth_m)))
    elif not ortho:
        raise ConfigError(f"[aps] dem: {dem_path} must be in the site's local east/north frame (+proj=ortho about "
                          f"the site, as 'gbsar focus --enu-geotiff' writes) or in UTM EPSG:{utm_epsg(site)}")
    rr, xx = np.meshgrid(img.range_m, img.azimuth_m, indexing="ij")
    z = np.zeros(rr.shape)
    for _ in range(iterations):
        e, n = slant_to_enu(xx, rr, site, img.rail_height_m, img.rail_centre_m, np.nan_to_num(z))
        if utm is not None:
            mx = utm.a[0, 0] * e + utm.a[0, 1] * n + utm.b[0]
            my = utm.a[1, 0] * e + utm.a[1, 1] * n + utm.b[1]
        else:
            mx, my = e, n
        mx, my = np.nan_to_num(mx, nan=-1e12), np.nan_to_num(my, nan=-1e12)
        col, row = inv.a * mx + inv.b * my + inv.c, inv.d * mx + inv.e * my + inv.f
        ci, ri = np.floor(col).astype(np.int64), np.floor(row).astype(np.int64)
        ok = np.isfinite(e) & (ri >= 0) & (ri < band.shape[0]) & (ci >= 0) & (ci < band.shape[1])
        z = np.full(rr.shape, np.nan)
        z[ok] = band[ri[ok], ci[ok]]
    return z.astype(np.float32)
