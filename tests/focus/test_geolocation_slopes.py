"""Geolocation on a DEM (``sarcli.focus.geolocation.geolocate_on_terrain``) on slopes that face the radar:
up to just below the incidence angle the point is found and satisfies the range, zero-Doppler and
height conditions (checked here directly); steeper (layover) is refused in one line. The plain
fixed-point iteration stalled on such slopes: its error shrinks by tan(slope) / tan(incidence) per step
(0.70 at 31 deg for 40 deg of incidence: a 2 km mountain left 0.09 m after 30 iterations)."""

from __future__ import annotations

import numpy as np
import pytest

from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef
from sarcli.errors import ProductError
from sarcli.focus.geolocation import TERRAIN_TOL_M, geolocate_on_terrain
from sarcli.model.terrain import ConstantHeight
from tests.focus.rs1_orbit import rs1_ecef_orbit

LAM = 299792458.0 / 5.3e9


class TiltedPlane:
    """Terrain rising away from the radar (facing it) at ``slope_deg`` through a centre point: the height
    grows with the horizontal distance along the look direction (local tangent plane at the centre)."""

    def __init__(self, centre: np.ndarray, away: np.ndarray, slope_deg: float, h0: float = 0.0):
        self.centre, self.away, self.tan, self.h0 = centre, away, np.tan(np.radians(slope_deg)), h0

    def height(self, lat_deg, lon_deg) -> np.ndarray:
        p = geodetic_to_ecef(lat_deg, lon_deg, np.zeros(np.shape(lat_deg)))
        return self.h0 + self.tan * np.sum((p - self.centre) * self.away, axis=-1)

    def describe(self) -> dict:
        return {"kind": "tilted plane"}


def _scene():
    sv = rs1_ecef_orbit()
    t0, rho0 = 0.0, 1000e3
    centre = geolocate_on_terrain(sv, t0, rho0, LAM, 0.0, "right", ConstantHeight(0.0))
    r, v, _ = sv.interpolate(np.array([t0]))
    up = centre / np.linalg.norm(centre)
    away = centre - r[0]
    away -= np.dot(away, up) * up
    away /= np.linalg.norm(away)
    cos_inc = np.dot(r[0] - centre, up) / np.linalg.norm(r[0] - centre)
    return sv, centre, away, float(np.degrees(np.arccos(cos_inc)))


@pytest.mark.parametrize("margin_deg", [20.0, 9.0, 3.0])
def test_points_on_slopes_below_the_incidence_are_found(margin_deg):
    sv, centre, away, incidence = _scene()
    terrain = TiltedPlane(centre, away, incidence - margin_deg)
    # near the centre: as the slope nears the incidence the range sphere and the plane become parallel,
    # and a slant-range offset dR puts the intersection dR / (cos(incidence) (1 - tan(s) / tan(incidence)))
    # away (10x at 3 deg from the incidence): +-150 m of range stays within ~2 km
    t = np.linspace(-0.2, 0.2, 5)[:, None] + np.zeros((1, 7))
    rho = 1000e3 + np.linspace(-150.0, 150.0, 7)[None, :] + np.zeros((5, 1))
    p = geolocate_on_terrain(sv, t, rho, LAM, 0.0, "right", terrain)
    r, v, _ = sv.interpolate(t)
    d = p - r
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), rho, atol=1e-3)  # on the range sphere
    assert np.max(np.abs(np.sum(d * v, axis=-1) / np.linalg.norm(d, axis=-1))) < 1e-6  # zero Doppler (m/s)
    lat, lon, h = ecef_to_geodetic(p)
    # on the terrain: the height error moves the point by dh / tan(incidence - slope ...) <= the 5 cm tolerance
    assert np.max(np.abs(h - terrain.height(lat, lon))) < TERRAIN_TOL_M


def test_layover_is_refused():
    sv, centre, away, incidence = _scene()
    terrain = TiltedPlane(centre, away, incidence + 5.0)
    with pytest.raises(ProductError, match="layover"):
        geolocate_on_terrain(sv, np.zeros(3), 1000e3 + np.array([-200.0, 0.0, 200.0]), LAM, 0.0, "right", terrain)
