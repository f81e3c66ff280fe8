"""ECEF <-> geodetic (WGS-84) through pyproj, never hand-written. Angles in degrees at this boundary.

PROJ's ECEF -> geodetic inverse is non-iterative: exact at the surface (< 1e-8 m) but measured 5 mm
off in height and 4 mm in latitude at 800 km altitude (see tests/orbit/test_geodetic.py). One Newton
polish step with PROJ's exact forward transform removes that: r0 = forward(lat, lon, h), then
(dlat, dlon, dh) = (north, east/cos(lat), up) . (r - r0) / (M + h, N + h, 1) with the meridian and
prime-vertical radii M, N. The result is exact to float64 rounding at any height.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pyproj import Transformer

from orbit.constants import WGS84_A, WGS84_E2


@lru_cache(maxsize=1)
def _to_geodetic() -> Transformer:
    return Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)


@lru_cache(maxsize=1)
def _to_ecef() -> Transformer:
    return Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)


def ecef_to_geodetic(r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ECEF (..., 3) m -> (lat_deg, lon_deg, h_m): PROJ inverse plus one Newton polish (module notes)."""
    r = np.asarray(r, dtype=np.float64)
    lon, lat, h = (np.asarray(a, np.float64) for a in _to_geodetic().transform(r[..., 0], r[..., 1], r[..., 2]))
    d = r - geodetic_to_ecef(lat, lon, h)
    phi, lam = np.radians(lat), np.radians(lon)
    sp, cp, sl, cl = np.sin(phi), np.cos(phi), np.sin(lam), np.cos(lam)
    w2 = 1.0 - WGS84_E2 * sp * sp
    n_rad = WGS84_A / np.sqrt(w2)
    m_rad = n_rad * (1.0 - WGS84_E2) / w2
    north = -sp * cl * d[..., 0] - sp * sl * d[..., 1] + cp * d[..., 2]
    east = -sl * d[..., 0] + cl * d[..., 1]
    up = cp * cl * d[..., 0] + cp * sl * d[..., 1] + sp * d[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        dlon = np.where(cp > 1e-12, east / ((n_rad + h) * cp), 0.0)
    return lat + np.degrees(north / (m_rad + h)), lon + np.degrees(dlon), h + up


def geodetic_to_ecef(lat_deg, lon_deg, h_m) -> np.ndarray:
    """(lat_deg, lon_deg, h_m) -> ECEF (..., 3) m."""
    x, y, z = _to_ecef().transform(np.asarray(lon_deg, np.float64), np.asarray(lat_deg, np.float64),
                                   np.asarray(h_m, np.float64))
    return np.stack([np.asarray(x), np.asarray(y), np.asarray(z)], axis=-1)
