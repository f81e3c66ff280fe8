"""The map GeoTIFF's lattice (``sarcli.focus.geocode``, module docstring "Map lattice"): the triangulated
inverse map evaluated on a lattice of map pixels and interpolated bilinearly must stay within
``LATTICE_TOL_PX`` of the triangulated map itself at EVERY pixel, and leave exactly the same pixels NaN
(outside the image), on a Radarsat-1 swath, flat and on a 1 km hill. The reference is the former
per-pixel evaluation (scipy's LinearNDInterpolator at every map pixel, map_coordinates), written out
here (the masking of lines not fully focused by :func:`sarcli.focus.geocode.amplitude_numpy`'s rule).
The kernels against their plain-numpy references."""

from __future__ import annotations

import numpy as np
import pytest
from pyproj import Transformer
from scipy.interpolate import LinearNDInterpolator

from sarcli.focus import geocode as G
from sarcli.model.raw import Orbit, Radar
from sarcli.model.slc import SLC, DopplerUsed
from sarcli.model.terrain import ConstantHeight
from tests.focus.rs1_orbit import rs1_ecef_orbit

C = 299792458.0
F0, PRF, FS = 5.3e9, 1256.98, 32.317e6


def _slc(n_lines: int, n_samples: int) -> SLC:
    """The geometry of a Radarsat-1 fine-beam SLC (798 km orbit, ascending through ~49 N, right
    looking, 990 km near range); no image (the tests pass the intensity)."""
    sv = rs1_ecef_orbit()
    radar = Radar(F0, C / F0, PRF, FS, -0.72e12, 42e-6, 2 * 990e3 / C, 990e3)
    z = np.zeros(0)
    return SLC(image=np.zeros((0, 0), np.complex64), azimuth_time=(np.arange(n_lines) - n_lines / 2) / PRF,
               slant_range=990e3 + np.arange(n_samples) * C / (2 * FS), epoch_utc="2002-06-16T00:00:00Z",
               radar=radar, doppler=DopplerUsed(z, z, z, z, z), azimuth_spacing_m=7000.0 / PRF,
               first_full_line=0, last_full_line=n_lines - 1,
               orbit=Orbit(sv.time, sv.position, sv.velocity, "ECEF"))


class Hill:
    """A Gaussian hill ``height`` m high, ``sigma`` m wide (local east/north around its top)."""

    def __init__(self, lat0: float, lon0: float, height: float = 1000.0, sigma: float = 3000.0):
        self.lat0, self.lon0, self.h, self.s = lat0, lon0, height, sigma

    def height(self, lat_deg, lon_deg) -> np.ndarray:
        dn = np.radians(np.asarray(lat_deg) - self.lat0) * 6.371e6
        de = np.radians(np.asarray(lon_deg) - self.lon0) * 6.371e6 * np.cos(np.radians(self.lat0))
        return self.h * np.exp(-0.5 * (dn**2 + de**2) / self.s**2)

    def describe(self) -> dict:
        return {"kind": "hill"}


def _reference_positions(slc: SLC, inten: np.ndarray, terrain, crs: str, shape, transform) -> np.ndarray:
    """The former map raster's image positions: every map pixel through the triangulation (scipy's
    LinearNDInterpolator on the projected coarse grid), (rows, cols, 2)."""
    n, m = inten.shape
    coarse = 33 if isinstance(terrain, ConstantHeight) else 65
    t, r = G._look_axes(slc, 1, 1, inten.shape)
    rows, cols = G._grid_index(n, coarse), G._grid_index(m, coarse)
    lat, lon, _ = G.geolocate_grid(slc, rows, cols, t, r, terrain)
    x, y = map(np.asarray, Transformer.from_crs("EPSG:4326", crs, always_xy=True).transform(lon, lat))
    rr, cc = np.meshgrid(rows.astype(float), cols.astype(float), indexing="ij")
    inv = LinearNDInterpolator(np.column_stack([x.ravel(), y.ravel()]), np.column_stack([rr.ravel(), cc.ravel()]))
    s = transform.a
    x0, y1 = transform.c + 0.5 * s, transform.f - 0.5 * s
    gx, gy = np.meshgrid(x0 + np.arange(shape[1]) * s, y1 - np.arange(shape[0]) * s)
    return inv(gx.ravel(), gy.ravel()).reshape(shape + (2,))


@pytest.mark.slow
@pytest.mark.parametrize("hill", [False, True])
def test_lattice_stays_within_its_tolerance_of_the_triangulated_map(hill):
    n, m = 1600, 1000
    slc = _slc(n, m)
    terrain = ConstantHeight(0.0)
    if hill:  # the hill at the scene centre (geolocated on the ellipsoid: close enough for its position)
        t, r = G._look_axes(slc, 1, 1, (n, m))
        lat, lon, _ = G.geolocate_grid(slc, np.array([n // 2]), np.array([m // 2]), t, r, terrain)
        terrain = Hill(float(lat[0, 0]), float(lon[0, 0]))
    rows, cols = np.meshgrid(np.arange(n, dtype=np.float32), np.arange(m, dtype=np.float32), indexing="ij")
    slc.first_full_line = 100  # lines 0..99 not fully focused: masked (NaN) in both
    full = np.arange(n) >= 100
    rc = None
    for comp, ramp in enumerate((rows, cols)):
        # a linear ramp is reproduced exactly by the bilinear resampling: amplitude^2 IS the image position
        strips, transform, crs = G.map_strips(slc, terrain=terrain, intensity=ramp, strip=256)
        got = np.empty(strips.shape, np.float32)
        for a, rws in strips:
            got[a:a + rws.shape[0]] = rws
        if rc is None:
            rc = _reference_positions(slc, ramp, terrain, crs, strips.shape, transform)
            inside = np.isfinite(rc[..., 0])
            assert 0.2 < np.mean(~inside) < 0.6  # a rotated swath: the test sees both sides of the hull
            r0 = np.where(inside, rc[..., 0], 0.0)
            lo = np.clip(np.floor(r0), 0, n - 1).astype(int)
            hi = np.clip(np.ceil(r0), 0, n - 1).astype(int)
            ok = inside & full[lo] & full[hi]
            assert np.sum(inside & ~ok) > 1000  # the masked lines were exercised
        np.testing.assert_array_equal(np.isfinite(got), ok)  # outside and masked: NaN exactly as before
        # float32: amplitude^2 of values up to n carries ~2 n 2^-24 (< 2e-4 here)
        err = np.abs(got[ok].astype(np.float64) ** 2 - rc[ok, comp])
        assert np.max(err) < G.LATTICE_TOL_PX + 4 * n * 2.0**-24, (comp, np.max(err))


@pytest.mark.slow
def test_lattice_step_follows_the_terrain():
    """A flat swath: most pixels inside the image interpolated; on the hill the map bends on the scale
    of the coarse grid: a smaller step, and still part of the map interpolated."""
    n, m = 1600, 1000
    slc = _slc(n, m)
    ramp = np.zeros((n, m), np.float32)
    t, r = G._look_axes(slc, 1, 1, (n, m))
    lat, lon, _ = G.geolocate_grid(slc, np.array([n // 2]), np.array([m // 2]), t, r, ConstantHeight(0.0))
    found = []
    for terrain in (ConstantHeight(0.0), Hill(float(lat[0, 0]), float(lon[0, 0]))):
        _, transform, crs = G.map_strips(slc, terrain=terrain, intensity=ramp)
        found.append(_classes(slc, terrain, crs, transform, (n, m)))
    (flat_step, flat), (hill_step, hill) = found
    assert flat[G.LATTICE] > 0.9 * (flat[G.LATTICE] + flat[G.EXACT])
    assert hill_step < flat_step and hill[G.LATTICE] > 0.2 * (hill[G.LATTICE] + hill[G.EXACT])


def _classes(slc, terrain, crs, transform, shape):
    n, m = shape
    coarse = 33 if isinstance(terrain, ConstantHeight) else 65
    t, r = G._look_axes(slc, 1, 1, shape)
    rows, cols = G._grid_index(n, coarse), G._grid_index(m, coarse)
    lat, lon, _ = G.geolocate_grid(slc, rows, cols, t, r, terrain)
    x, y = map(np.asarray, Transformer.from_crs("EPSG:4326", crs, always_xy=True).transform(lon, lat))
    s = transform.a
    x0, y1 = transform.c + 0.5 * s, transform.f - 0.5 * s
    ny = int(np.ceil((y.max() - y.min()) / s)) + 1
    nx = int(np.ceil((x.max() - x.min()) / s)) + 1
    step, lr, lc, _, _, cls = G.map_lattice(G.MapInverse(x, y, rows, cols), x0, y1, s, (ny, nx))
    cell_px = np.diff(lr)[:, None] * np.diff(lc)[None, :]
    return step, np.bincount(cls.ravel(), weights=cell_px.ravel(), minlength=3)


def test_masked_rows_and_image_edges_match_map_coordinates():
    """points_amplitude against the plain-numpy reference (scipy's map_coordinates, order 1, edges
    extended): inside, on and beyond the image's edges, NaN positions, and rows not fully focused."""
    rng = np.random.default_rng(3)
    inten = rng.random((40, 30), dtype=np.float32) * 100
    full = np.ones(40, bool)
    full[:5] = False
    full[33] = False
    r = rng.uniform(-2.0, 42.0, 4000)
    c = rng.uniform(-2.0, 32.0, 4000)
    r[:50] = np.round(r[:50])  # exactly on rows: floor = ceil
    c[50:100] = 29.0
    r[100:110] = np.nan
    got = G.points_amplitude(r, c, inten, full)
    ref = G.amplitude_numpy(inten, full, r, c)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(ref))
    np.testing.assert_allclose(got, ref, rtol=1e-6)
    assert np.isnan(got).sum() > 100  # the masks were exercised


def test_hull_excess_kernel_and_its_meaning():
    """Kernel vs numpy; for a square hull the excess is the signed distance to the nearest side
    (inside: minus it) and beyond a side the distance to that side (closed form)."""
    x, y = np.meshgrid(np.arange(5.0), np.arange(5.0))
    inv = G.MapInverse(x, y, np.arange(5), np.arange(5))  # the square [0, 4]^2
    rng = np.random.default_rng(0)
    px, py = rng.uniform(-3, 7, 500), rng.uniform(-3, 7, 500)
    got = G.hull_excess(inv.normals, inv.offsets, px, py)
    np.testing.assert_allclose(got, G.hull_excess_numpy(inv.normals, inv.offsets, px, py), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(got, np.maximum.reduce([-px, px - 4, -py, py - 4]), atol=1e-12)
    rc = inv(px, py)
    outside = got > inv.margin
    assert np.all(np.isnan(rc[outside])) and np.all(np.isfinite(rc[got < 0]))
    np.testing.assert_allclose(rc[got < 0], np.column_stack([py, px])[got < 0], atol=1e-9)  # row = y, col = x here
