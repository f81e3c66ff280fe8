"""Terrain: the height of the ground under a pixel, for Doppler geometry, focusing and geocoding.

Processing never guesses the ground: it is an explicit input, a constant height (``--height``,
default 0 m) or a DEM (``--dem``, read by ``sarcli.io.dem``). Heights are metres above the WGS-84
ellipsoid; latitudes and longitudes are geodetic degrees (WGS-84).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Terrain(Protocol):
    """Height above the WGS-84 ellipsoid (m) at geodetic latitude/longitude (deg), vectorized."""

    def height(self, lat_deg: Any, lon_deg: Any) -> np.ndarray: ...

    def describe(self) -> dict[str, Any]:
        """What the products record about the terrain used (JSON-able)."""
        ...


@dataclass(frozen=True)
class ConstantHeight:
    """The same ellipsoidal height everywhere (a flat scene, or a first guess)."""

    height_m: float = 0.0

    def height(self, lat_deg: Any, lon_deg: Any) -> np.ndarray:
        shape = np.broadcast(np.asarray(lat_deg), np.asarray(lon_deg)).shape
        return np.full(shape, float(self.height_m))

    def describe(self) -> dict[str, Any]:
        return {"kind": "constant", "height_m": float(self.height_m)}
