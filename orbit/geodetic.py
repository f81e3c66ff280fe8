"""ECEF <-> geodetic (WGS-84) through pyproj, never hand-written. Angles in degrees at this boundary."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pyproj import Transformer


@lru_cache(maxsize=1)
def _to_geodetic() -> Transformer:
    return Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)


@lru_cache(maxsize=1)
def _to_ecef() -> Transformer:
    return Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)


def ecef_to_geodetic(r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ECEF (..., 3) m -> (lat_deg, lon_deg, h_m)."""
    r = np.asarray(r, dtype=np.float64)
    lon, lat, h = _to_geodetic().transform(r[..., 0], r[..., 1], r[..., 2])
    return np.asarray(lat), np.asarray(lon), np.asarray(h)


def geodetic_to_ecef(lat_deg, lon_deg, h_m) -> np.ndarray:
    """(lat_deg, lon_deg, h_m) -> ECEF (..., 3) m."""
    x, y, z = _to_ecef().transform(np.asarray(lon_deg, np.float64), np.asarray(lat_deg, np.float64),
                                   np.asarray(h_m, np.float64))
    return np.stack([np.asarray(x), np.asarray(y), np.asarray(z)], axis=-1)
