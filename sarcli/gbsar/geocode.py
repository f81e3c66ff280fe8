"""Geocoding of slant-plane GB-SAR images: local ENU and UTM (pyproj), amplitude-in-dB GeoTIFFs.

A pixel (x, R0) lies on the surface ``z = z_ref`` (metres above the local origin, default 0): its
horizontal distance from the rail line is ``y = sqrt(R0^2 - (H - z_ref)^2)`` with H the antenna
height (pixels with R0 < H - z_ref do not reach the surface and are left empty). In ENU about the
local origin (the rail centre's geodetic position at height ``site.height_m``), with heading ``hd``
(rail direction, clockwise from north) the rail direction is ``a = (sin hd, cos hd)`` and the look
direction ``l = (cos hd, -sin hd)`` for a right-looking rail (its negative for left).

UTM: the zone of the site. Over a GB-SAR scene (< ~2 km) ENU -> UTM is affine to about a millimetre
(1 mm measured over 600 m); the affine map is fitted to exact pyproj transforms (ENU -> ECEF -> geodetic -> UTM) of
the footprint's corners and its residual is reported. The ENU GeoTIFF uses the site's
orthographic projection, the tangent plane of the ellipsoid at the site (= local E, N on the surface).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.errors import SarcliError
from sarcli.model.gbsar import Site


def rail_axes(site: Site) -> tuple[np.ndarray, np.ndarray]:
    """Unit (east, north) vectors of the rail direction and the look direction."""
    hd = np.deg2rad(site.heading_deg)
    a = np.array([np.sin(hd), np.cos(hd)])
    look = np.array([np.cos(hd), -np.sin(hd)])
    return a, (look if site.look_side == "right" else -look)


def slant_to_enu(x: np.ndarray, r0: np.ndarray, site: Site, antenna_height_m: float, rail_centre_m: float,
                 z_ref_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(east, north) of pixels (x, R0) on the surface z = z_ref; NaN where R0 < H - z_ref."""
    dz = antenna_height_m - z_ref_m
    with np.errstate(invalid="ignore"):
        y = np.sqrt(np.asarray(r0, np.float64) ** 2 - dz ** 2)
    a, look = rail_axes(site)
    xr = np.asarray(x, np.float64) - rail_centre_m
    return xr * a[0] + y * look[0], xr * a[1] + y * look[1]


def enu_to_slant(e: np.ndarray, n: np.ndarray, site: Site, antenna_height_m: float, rail_centre_m: float,
                 z_ref_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`slant_to_enu` (points behind the rail get NaN)."""
    a, look = rail_axes(site)
    xr = e * a[0] + n * a[1]
    y = e * look[0] + n * look[1]
    r0 = np.where(y >= 0, np.hypot(y, antenna_height_m - z_ref_m), np.nan)
    return xr + rail_centre_m, r0


def utm_epsg(site: Site) -> int:
    zone = int((site.longitude_deg + 180) // 6) % 60 + 1
    return (32600 if site.latitude_deg >= 0 else 32700) + zone


def enu_crs(site: Site) -> str:
    return f"+proj=ortho +lat_0={site.latitude_deg!r} +lon_0={site.longitude_deg!r} +ellps=WGS84 +units=m +no_defs"


@dataclass
class Affine2:
    """``[X, Y] = A @ [e, n] + b`` (fitted ENU -> map) and its max residual over the fit points (m)."""

    a: np.ndarray
    b: np.ndarray
    residual_m: float

    def inverse(self, xx: np.ndarray, yy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ai = np.linalg.inv(self.a)
        d0, d1 = xx - self.b[0], yy - self.b[1]
        return ai[0, 0] * d0 + ai[0, 1] * d1, ai[1, 0] * d0 + ai[1, 1] * d1


def enu_to_utm_affine(site: Site, half_extent_m: float, z_m: float = 0.0) -> tuple[Affine2, int]:
    """Fit the ENU -> UTM affine map over a square of half-size ``half_extent_m`` (exact pyproj points)."""
    from pyproj import Transformer

    from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef

    lat, lon = np.deg2rad(site.latitude_deg), np.deg2rad(site.longitude_deg)
    g = np.linspace(-half_extent_m, half_extent_m, 5)
    e, n = (v.ravel() for v in np.meshgrid(g, g))
    u = np.full(e.shape, z_m)
    east = np.array([-np.sin(lon), np.cos(lon), 0.0])
    north = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
    up = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    o = np.asarray(geodetic_to_ecef(site.latitude_deg, site.longitude_deg, site.height_m), np.float64).reshape(3)
    ecef = o[None, :] + e[:, None] * east + n[:, None] * north + u[:, None] * up
    la, lo, _ = ecef_to_geodetic(ecef)
    epsg = utm_epsg(site)
    tr = Transformer.from_crs("EPSG:4326", f"EPSG:{epsg}", always_xy=True)
    xx, yy = tr.transform(np.asarray(lo), np.asarray(la))
    m = np.column_stack([e, n, np.ones_like(e)])
    coef, *_ = np.linalg.lstsq(m, np.column_stack([xx, yy]), rcond=None)
    res = float(np.max(np.hypot(*(m @ coef - np.column_stack([xx, yy])).T)))
    return Affine2(a=coef[:2].T.copy(), b=coef[2].copy(), residual_m=res), epsg


def resample_to_map(amplitude_db: np.ndarray, ranges: np.ndarray, azimuths: np.ndarray, site: Site,
                    antenna_height_m: float, rail_centre_m: float, pixel_m: float, frame: str = "utm",
                    z_ref_m: float = 0.0) -> tuple[np.ndarray, object, str, dict]:
    """Resample an amplitude (dB) slant image onto a north-up map grid -> (raster, Affine, crs, info).

    Nearest slant pixel per map pixel (amplitudes, not complex values, are mapped).
    """
    from rasterio.transform import Affine

    if pixel_m <= 0:
        raise SarcliError("the map pixel size must be > 0")
    rr, xx = np.meshgrid(ranges, azimuths, indexing="ij")
    e, n = slant_to_enu(xx, rr, site, antenna_height_m, rail_centre_m, z_ref_m)
    ok = np.isfinite(e)
    if not ok.any():
        raise SarcliError("no image pixel reaches the ground (all ranges are shorter than the antenna height)")
    ext = float(np.nanmax(np.hypot(e, n))) + pixel_m
    if frame == "utm":
        aff, epsg = enu_to_utm_affine(site, ext, z_ref_m)
        mx, my = aff.a @ np.vstack([e[ok], n[ok]]) + aff.b[:, None]
        crs, info = f"EPSG:{epsg}", {"enu_to_utm_residual_m": aff.residual_m, "epsg": epsg}
    elif frame == "enu":
        aff, (mx, my) = None, (e[ok], n[ok])
        crs, info = enu_crs(site), {}
    else:
        raise SarcliError(f"unknown map frame '{frame}' (use utm or enu)")
    x0, x1 = np.floor(mx.min() / pixel_m) * pixel_m, np.ceil(mx.max() / pixel_m) * pixel_m
    y0, y1 = np.floor(my.min() / pixel_m) * pixel_m, np.ceil(my.max() / pixel_m) * pixel_m
    ncol, nrow = int(round((x1 - x0) / pixel_m)), int(round((y1 - y0) / pixel_m))
    if ncol * nrow > 50_000_000:
        raise SarcliError(f"map grid of {nrow} x {ncol} pixels is too large; use a coarser --map-pixel")
    cx = x0 + (np.arange(ncol) + 0.5) * pixel_m
    cy = y1 - (np.arange(nrow) + 0.5) * pixel_m
    gx, gy = np.meshgrid(cx, cy)
    ge, gn = (aff.inverse(gx, gy) if aff is not None else (gx, gy))
    sx, sr = enu_to_slant(ge, gn, site, antenna_height_m, rail_centre_m, z_ref_m)
    fi = np.rint((sr - ranges[0]) / (ranges[1] - ranges[0])) if ranges.size > 1 else np.zeros_like(sr)
    fj = np.rint((sx - azimuths[0]) / (azimuths[1] - azimuths[0])) if azimuths.size > 1 else np.zeros_like(sx)
    inside = np.isfinite(fi) & np.isfinite(fj) & (fi >= 0) & (fi < ranges.size) & (fj >= 0) & (fj < azimuths.size)
    out = np.full(gx.shape, np.nan, np.float32)
    out[inside] = amplitude_db[fi[inside].astype(np.int64), fj[inside].astype(np.int64)]
    return out, Affine(pixel_m, 0, x0, 0, -pixel_m, y1), crs, info
