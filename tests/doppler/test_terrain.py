"""The terrain under the beam (``OrbitGeometry.heights``) and its use by the Doppler estimate: a constant
height, tilted planes (gentle, and steeper than the incidence, where the plain iteration h <- T(h)
diverges), a cliff, a terrain that exists only under the scene, and the simulator's reference height
given explicitly (processing never reads /truth).

Every expected value is a property of the geometry checked with the orbit library directly: the
beam-centre-plane target at the returned height lies on the terrain (|T(lat, lon) - h| <= 2 mm: the
solver's 1 mm plus the 0.1 mm of the height surfaces)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pytest

from orbit import geometry as og
from orbit.frames import eci_to_ecef
from orbit.geodetic import ecef_to_geodetic
from sarcli.doppler.api import estimate_doppler
from sarcli.doppler.geometry import OrbitGeometry
from sarcli.doppler.options import DopplerOptions
from sarcli.errors import ProductError
from sarcli.model.terrain import ConstantHeight
from tests.doppler.conftest import scene_text, simulate_text

R_EARTH = 6371e3  # local tangent-plane coordinates of the test terrains (any smooth map will do)


def beam_centre(geo: OrbitGeometry, rho, t, h):
    """(lat, lon, geodetic height) of the beam-centre-plane target at (rho, t) on the surface h, from
    the orbit library (independent of the height solver)."""
    rho, t, h = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (rho, t, h)))
    r, v, _ = geo.sv_eci.interpolate(t)
    pp, py = geo.attitude(t)
    p = og.target_from_look_plane(r, v, rho, pp, py, geo.side, h, geo.exact_attitude)
    return ecef_to_geodetic(eci_to_ecef(geo.sv_eci.epoch_utc, t, p))


@dataclass(frozen=True)
class Plane:
    """h = h0 + slope * u, u the ground distance (m) along the unit direction (east, north) from (lat0, lon0);
    ``cliff``: instead a step from ``h0`` (u < 0) down to 0 (u >= 0)."""

    lat0: float
    lon0: float
    east: float
    north: float
    h0: float = 0.0
    slope: float = 0.0
    cliff: bool = False

    def u(self, lat, lon):
        dn = np.radians(np.asarray(lat) - self.lat0) * R_EARTH
        de = np.radians(np.asarray(lon) - self.lon0) * R_EARTH * np.cos(np.radians(self.lat0))
        return self.east * de + self.north * dn

    def height(self, lat, lon):
        u = self.u(lat, lon)
        return np.where(u < 0, self.h0, 0.0) if self.cliff else self.h0 + self.slope * u

    def describe(self):
        return {"kind": "test plane", **dataclasses.asdict(self)}


@pytest.fixture(scope="module")
def geo(clutter_raw):
    return OrbitGeometry.from_raw(clutter_raw)


@pytest.fixture(scope="module")
def probe(clutter_raw, geo):
    """Scene-centre range and time, and the ground-range direction (unit east, north) there."""
    rho = clutter_raw.slant_range()
    rc, tc = float(rho[rho.size // 2]), 0.5 * float(clutter_raw.azimuth_time[0] + clutter_raw.azimuth_time[-1])
    lat, lon, _ = beam_centre(geo, [rc, rc + 2000.0], tc, 0.0)
    de = np.radians(lon[1] - lon[0]) * R_EARTH * np.cos(np.radians(lat[0]))
    dn = np.radians(lat[1] - lat[0]) * R_EARTH
    n = np.hypot(de, dn)
    return rc, tc, float(lat[0]), float(lon[0]), de / n, dn / n


def _on_terrain(geo, terrain, rho, t, h):
    lat, lon, hh = beam_centre(geo, rho, t, h)
    np.testing.assert_allclose(hh, h, atol=2e-4)
    return np.abs(terrain.height(lat, lon) - h)


def test_constant_height_is_exact(clutter_raw, geo):
    g = dataclasses.replace(geo, terrain=ConstantHeight(1234.5))
    rho, t = clutter_raw.slant_range()[::50], np.linspace(-0.1, 0.1, 8)[:, None]
    h = g.heights(rho, t)
    assert h.shape == (8, rho.size) and np.all(h == 1234.5)
    np.testing.assert_array_equal(g.fdc_vector(rho, t), geo.fdc_vector(rho, t, 1234.5))
    assert np.all(geo.heights(rho, t) == 0.0)


@pytest.mark.parametrize("slope", [0.3, -0.3, -2.0])
def test_tilted_plane_heights_lie_on_the_terrain(geo, probe, slope):
    """Planes rising (0.3) and falling (-0.3, -2.0) away from the radar; on the -2.0 backslope (63 deg,
    steeper than the incidence) the plain iteration oscillates with growing steps (checked below), the
    bracketing solver converges."""
    rc, tc, lat0, lon0, east, north = probe
    plane = Plane(lat0, lon0, east, north, h0=800.0, slope=slope)
    g = dataclasses.replace(geo, terrain=plane)
    rho = rc + np.linspace(-600.0, 600.0, 7)
    t = tc + np.linspace(-0.15, 0.15, 7)
    h = g.heights(rho, t)
    assert np.all(_on_terrain(geo, plane, rho, t, h) <= 2e-3)
    assert np.ptp(h) > 100.0  # the plane is really tilted under these points
    if slope == -2.0:  # precondition: h <- T(x(h)) runs away on this slope
        hk = [0.0]
        for _ in range(4):
            lat, lon, _ = beam_centre(geo, rc, tc, hk[-1])
            hk.append(float(plane.height(lat, lon)))
        steps = np.abs(np.diff(hk))
        assert np.all(steps[1:] > 2.0 * steps[:-1])


def test_layover_ramp_gives_a_height_on_the_terrain(geo, probe):
    """A 1500 m escarpment facing the radar, slope 2 (63 deg, steeper than the incidence: layover, where
    several ground points share one slant range): the returned height is one of them."""
    rc, tc, lat0, lon0, east, north = probe

    @dataclass(frozen=True)
    class Ramp(Plane):
        def height(self, lat, lon):
            return np.clip(super().height(lat, lon), 0.0, 1500.0)

    ramp = Ramp(lat0, lon0, east, north, h0=700.0, slope=2.0)
    rho = rc + np.linspace(-900.0, 900.0, 9)
    h = dataclasses.replace(geo, terrain=ramp).heights(rho, tc)
    assert np.all(_on_terrain(geo, ramp, rho, tc, h) <= 2e-3)
    # precondition: layover is really there, some ranges reach both the foot and the top of the ramp
    foot = _on_terrain(geo, ramp, rho, tc, np.zeros_like(rho)) == 0
    top = _on_terrain(geo, ramp, rho, tc, np.full_like(rho, 1500.0)) == 0
    assert np.any(foot & top)


def test_cliff_gives_the_edge(geo, probe):
    """A step 500 m -> 0 m across the range line, placed so that no height lies on the terrain: the
    point at the returned height is on the cliff edge (u = 0) to 1 mm x cot(incidence)."""
    rc, tc, lat0, lon0, east, north = probe
    lat, lon, _ = beam_centre(geo, rc, tc, [0.0, 500.0])
    base = Plane(lat0, lon0, east, north)
    u0, u500 = base.u(lat, lon)
    assert u500 - u0 > 400.0  # raising the surface moves the point away from the radar
    mid = 0.5 * (u0 + u500)  # edge half-way: T(x(0)) = 500 > 0 and T(x(500)) = 0 < 500
    shift = mid * np.array([east, north])
    cliff = Plane(lat0 + np.degrees(shift[1] / R_EARTH),
                  lon0 + np.degrees(shift[0] / (R_EARTH * np.cos(np.radians(lat0)))), east, north, h0=500.0,
                  cliff=True)
    h = float(dataclasses.replace(geo, terrain=cliff).heights(rc, tc))
    la, lo, _ = beam_centre(geo, rc, tc, h)
    assert 0.0 < h < 500.0 and abs(float(cliff.u(la, lo))) < 1e-2


def test_a_terrain_without_height_is_one_clear_error(geo, probe):
    rc, tc, *_ = probe

    class Void:
        def height(self, lat, lon):
            return np.full(np.shape(lat), np.nan)

        def describe(self):
            return {"kind": "void"}

    with pytest.raises(ProductError, match="no height at latitude"):
        dataclasses.replace(geo, terrain=Void()).heights(rc, tc)


def test_the_estimate_asks_the_terrain_only_about_the_scene(clutter_raw, geo):
    """A terrain defined only over the scene's footprint (as a DEM cut to the scene would be): the model
    grid, which extends 2 % in range and 1 s in time beyond the scene, takes the edge heights, so the
    estimate works and equals the one over the same constant height everywhere."""
    rho, t = clutter_raw.slant_range(), clutter_raw.azimuth_time
    lat, lon, _ = beam_centre(geo, [rho[0], rho[-1], rho[0], rho[-1]], [t[0], t[0], t[-1], t[-1]], 300.0)
    pad = 0.01  # deg, ~1 km

    @dataclass(frozen=True)
    class SceneOnly:
        def height(self, la, lo):
            la, lo = np.asarray(la), np.asarray(lo)
            inside = (np.abs(la - lat.mean()) <= np.ptp(lat) / 2 + pad) & \
                (np.abs(lo - lon.mean()) <= np.ptp(lon) / 2 + pad)
            if not np.all(inside):
                raise ProductError("terrain asked outside the scene")
            return np.full(la.shape, 300.0)

        def describe(self):
            return {"kind": "scene only"}

    opts = DopplerOptions(az_block=256, rg_block=96)
    m = estimate_doppler(clutter_raw, opts, terrain=SceneOnly())
    ref = estimate_doppler(clutter_raw, opts, terrain=ConstantHeight(300.0))
    np.testing.assert_array_equal(m.blocks["fdc_orbit_hz"], ref.blocks["fdc_orbit_hz"])
    np.testing.assert_array_equal(m.fdc_poly.coef, ref.fdc_poly.coef)
    assert m.parameters["terrain"] == {"kind": "scene only"}


def test_tilted_terrain_reaches_the_geometric_model(clutter_raw, geo, probe):
    """The orbit model of every block is evaluated on the terrain under that block."""
    rc, tc, lat0, lon0, east, north = probe
    plane = Plane(lat0, lon0, east, north, h0=600.0, slope=0.2)
    opts = DopplerOptions(az_block=256, rg_block=96)
    m = estimate_doppler(clutter_raw, opts, terrain=plane)
    flat = estimate_doppler(clutter_raw, opts)
    b = m.blocks
    h = dataclasses.replace(geo, terrain=plane).heights(b["range_m"], b["azimuth_time_s"])
    assert np.all(_on_terrain(geo, plane, b["range_m"], b["azimuth_time_s"], h) <= 2e-3)
    np.testing.assert_allclose(b["fdc_orbit_hz"], geo.fdc_vector(b["range_m"], b["azimuth_time_s"], h), atol=1e-9)
    assert np.min(np.abs(b["fdc_orbit_hz"] - flat.blocks["fdc_orbit_hz"])) > 1.0


@pytest.fixture(scope="module")
def high_raw():
    """The clutter scene simulated 1500 m above the ellipsoid (the truth knows; processing must be told)."""
    text = scene_text().replace("center_time_s = 0.0\n", "center_time_s = 0.0\nreference_height_m = 1500.0\n")
    return simulate_text(text)


def test_reference_height_is_an_input_not_read_from_the_truth(high_raw, cli, tmp_path):
    """The geometric centroid agrees with the simulator's truth when the height is given (--height),
    and not at the default 0 m: the truth is never read."""
    from sarcli.io.doppler_product import read_doppler
    from sarcli.io.raw import write_raw

    assert float(high_raw.truth["reference_height_m"]) == 1500.0
    tf, rho = high_raw.truth["doppler_centroid_hz"], high_raw.slant_range()
    g = OrbitGeometry.from_raw(high_raw, ConstantHeight(1500.0))
    np.testing.assert_allclose(g.fdc_vector(rho[::64], 0.0), tf[::64], atol=1e-4)
    path = tmp_path / "high.h5"
    write_raw(path, high_raw)
    errs = {}
    for height in (0.0, 1500.0):
        out = tmp_path / f"d{height:.0f}.h5"
        r = cli("doppler", path, "--height", height, "--az-block", "512", "--rg-block", "96", "-o", out)
        assert r.exit_code == 0, r.stderr
        m = read_doppler(out)
        assert m.parameters["height_m"] == height
        b = m.blocks
        errs[height] = np.max(np.abs(b["fdc_orbit_hz"] - np.interp(b["range_m"], rho, tf)))
    assert errs[1500.0] < 0.01 < 1.0 < errs[0.0]


def test_dem_terrain_equals_the_constant_height_it_holds(high_raw, cli, tmp_path):
    """``--dem`` reaches the geometry: a flat DEM 1500 m above the ellipsoid (EPSG:4326, covering the scene)
    gives the same orbit-model centroid as ``--height 1500``, to the DEM's bilinear exactness (a plane)."""
    import rasterio
    from rasterio.transform import from_origin

    from orbit.geodetic import ecef_to_geodetic
    from sarcli.focus.geolocation import zero_doppler_points
    from sarcli.io.doppler_product import read_doppler
    from sarcli.io.raw import write_raw

    r = high_raw.radar
    rho = high_raw.slant_range()
    p = zero_doppler_points(high_raw.orbit, high_raw.epoch_utc, np.array([0.0]), np.array([rho[rho.size // 2]]),
                            r.wavelength_m, high_raw.look_side, ConstantHeight(1500.0))
    lat, lon, _ = ecef_to_geodetic(np.asarray(p).reshape(-1, 3))
    step = 0.01  # deg; the scene spans ~0.1 deg: a 2 x 2 deg DEM covers it with any squint
    z = np.full((200, 200), 1500.0)
    with rasterio.open(tmp_path / "flat.tif", "w", driver="GTiff", height=200, width=200, count=1, dtype="float64",
                       crs="EPSG:4326", transform=from_origin(float(lon[0]) - 1.0, float(lat[0]) + 1.0, step,
                                                              step)) as ds:
        ds.write(z, 1)
    path = tmp_path / "high.h5"
    write_raw(path, high_raw)
    out = {}
    for name, args in (("dem", ("--dem", tmp_path / "flat.tif")), ("height", ("--height", 1500.0))):
        o = tmp_path / f"{name}.h5"
        res = cli("doppler", path, *args, "--az-block", "512", "--rg-block", "96", "-o", o)
        assert res.exit_code == 0, res.stderr
        out[name] = read_doppler(o).blocks["fdc_orbit_hz"]
    np.testing.assert_allclose(out["dem"], out["height"], atol=1e-4)
