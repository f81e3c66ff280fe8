"""Amplitude GeoTIFFs of an SLC: slant-range geometry with a lat/lon GCP grid, and map-projected (UTM).

Geolocation of a pixel (line time t = zero-Doppler time, column = slant range R) is the zero-Doppler
target on the terrain (``--height`` / ``--dem``, :mod:`sarcli.io.dem`; default 0 m above the
ellipsoid): :func:`sarcli.focus.geolocation.zero_doppler_points` (orbit.geometry, WGS-84, iterated
with the DEM height under the point). A pixel placed at a height dh too low lands dh / tan(incidence)
too far from the track on the ground (a 1 km hill at Radarsat-1's incidence of about 38 deg: 1.3 km).

- Slant-range GeoTIFF: the (multilooked) amplitude as it is, with a ``gcp_lines x gcp_cols`` grid of
  ground control points (pixel centres, EPSG:4326 lon/lat/h).
- Map-projected GeoTIFF: UTM zone of the scene centre (EPSG:326zz north / 327zz south) unless a CRS is
  given. A coarse grid (``coarse`` x ``coarse`` nodes) is geolocated and projected; the inverse map
  (x, y) -> (line, column) is linear over its Delaunay triangles (the map is smooth: the error of the
  linear pieces is below 0.01 pixel for a Radarsat-1 swath), and the intensity is resampled
  bilinearly (sqrt after resampling), NaN outside the image. Pixel spacing: the larger of the ground
  range and azimuth spacings of the looks (no aliasing) unless given. Computed and written in row
  strips (the map raster of a full scene is never held whole).

  Map lattice. Locating every map pixel in the triangulation cost 0.2 us a pixel inside the hull and
  far more outside (scipy searches every triangle when its walk leaves the hull): 34 s for the
  17751 x 9346 map of a 23000 x 6354 Radarsat-1 scene. So the triangulated map T is evaluated on a
  lattice of nodes every h map pixels (and the last row and column) and interpolated bilinearly in
  between (:func:`map_lattice`, kernel :func:`lattice_amplitude`), where that provably stays within
  ``LATTICE_TOL_PX`` (0.01 pixel) of T. The bilinear interpolant B reproduces affine functions and
  its weights are >= 0 with sum 1, so |B - T| <= 2 max_cell |T - l| for any affine l; with l the
  piece of T on a triangle meeting the cell, |B - T| <= 2 d G (d: the cell's diagonal, G: the
  largest gradient difference between the triangles that meet the cell,
  :func:`cell_gradient_spread`). A cell inside one triangle thus adds nothing (round-off); where a
  triangle edge crosses it, G is T's gradient jump there, about the map's second derivative times
  the triangle size (for the smooth map g itself the familiar bound is (h^2 / 8)(|g_ii| + |g_jj|);
  T's kinks, not g's curvature, dominate at h << the triangles). Cells that fail the bound, and
  every cell the hull may cross (its centre within half its diagonal of a hull edge line,
  :func:`hull_excess`), are evaluated exactly pixel by pixel: NaN outside the image exactly as the
  triangulation says, and points clearly outside the hull are not searched. h is chosen per map
  from ``LATTICE_STEPS`` (fewest exact evaluations): 8 for a flat Radarsat-1 swath (97 % of the
  pixels inside interpolated), smaller where a DEM bends the map on the scale of the coarse grid.
  Measured against T at every pixel (tests: simulated Radarsat-1 swath, flat and on a 1 km hill):
  below 1e-3 pixel, the bound 0.01.

Both are Cloud-Optimized GeoTIFFs (:func:`sarcli.io.images.write_geotiff`) with two bands, the amplitude
(``1``, overviews sqrt(mean |z|^2)) and the amplitude in dB (20 log10, overviews in power), the
provenance tags of the SLC (sensor, wavelength, look side, first and last zero-Doppler times, the SLC
file's SHA-256, the fully focused lines) and a QGIS style showing the dB band. Lines outside the fully
focused span (``first_full_line..last_full_line``: lines without the whole processed aperture) are
MASKED: a look cell that holds any such line is NaN (nodata) in the slant GeoTIFF, and so is every
map pixel that falls between its rows; the tag ``FULLY_FOCUSED_LINES`` gives the span.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from sarcli.errors import SarcliError
from sarcli.model.slc import SLC
from sarcli.model.terrain import ConstantHeight, Terrain

#: rows of the GeoTIFFs computed and written at a time (a multiple of their 256-row tiles)
STRIP = 512
#: pixels of the multilooked intensity the dB stretch of the QGIS style is taken from (a regular grid)
STRETCH_SAMPLES = 1 << 20
#: map pixels between the nodes where the triangulated inverse map is evaluated: the candidates (module
#: docstring, :func:`map_lattice`)
LATTICE_STEPS = (16, 8, 4, 2)
#: image pixels the lattice may add to the triangulated inverse map's position (module docstring)
LATTICE_TOL_PX = 0.01
#: cell classes of :func:`map_lattice`
OUTSIDE, LATTICE, EXACT = 0, 1, 2


def multilook(image: np.ndarray, looks_az: int = 1, looks_rg: int = 1) -> np.ndarray:
    """Mean intensity |z|^2 over looks_az x looks_rg cells (float32; partial cells at the end dropped).
    Each cell is summed in float64 by one thread in a fixed order (:func:`_multilook`): a cell's value
    depends only on its own pixels, not on the rows around it nor on the thread count."""
    if looks_az < 1 or looks_rg < 1:
        raise SarcliError("looks must be positive integers")
    n, m = image.shape[0] // looks_az, image.shape[1] // looks_rg
    if n < 1 or m < 1:
        raise SarcliError(f"image {image.shape} is smaller than one {looks_az} x {looks_rg} look cell")
    return _multilook(np.asarray(image), looks_az, looks_rg)


@njit(cache=True, parallel=True)
def _multilook(image: np.ndarray, la: int, lr: int) -> np.ndarray:
    n, m = image.shape[0] // la, image.shape[1] // lr
    out = np.empty((n, m), np.float32)
    scale = 1.0 / (la * lr)
    for c in prange(n):
        acc = np.zeros(m)
        for r in range(c * la, (c + 1) * la):
            for j in range(m):
                for k in range(j * lr, (j + 1) * lr):
                    z = image[r, k]
                    acc[j] += np.float64(z.real) * np.float64(z.real) + np.float64(z.imag) * np.float64(z.imag)
        for j in range(m):
            out[c, j] = acc[j] * scale
    return out


def full_rows(slc: SLC, n_rows: int, looks_az: int) -> np.ndarray:
    """Per multilooked row, whether all its ``looks_az`` lines are fully focused (first_full_line ..
    last_full_line; a product that records no span counts as fully focused)."""
    last = slc.last_full_line if slc.last_full_line >= 0 else slc.azimuth_time.size - 1
    lines = np.arange(n_rows) * looks_az
    return (lines >= slc.first_full_line) & (lines + looks_az - 1 <= last)


def slc_tags(slc: SLC, inputs: tuple = (), extra: dict | None = None) -> dict[str, str]:
    """The GeoTIFF provenance tags of an image made from ``slc`` (:func:`sarcli.io.images.provenance_tags`)."""
    from sarcli.io.images import provenance_tags

    last = slc.last_full_line if slc.last_full_line >= 0 else slc.azimuth_time.size - 1
    return provenance_tags(
        inputs, sensor=slc.source, wavelength_m=slc.radar.wavelength_m, look_side=slc.look_side,
        acquisition=(slc.epoch_utc, float(slc.azimuth_time[0]), float(slc.azimuth_time[-1])),
        LINE_TIME="zero-Doppler", ALGORITHM=slc.algorithm,
        FULLY_FOCUSED_LINES=f"{slc.first_full_line}..{last} of {slc.azimuth_time.size} (others masked: nodata)",
        **(extra or {}))


def _amplitude_bands(amp, inten: np.ndarray, full: np.ndarray, geometry: str, radiometry: str | None = None):
    """The two bands of an amplitude GeoTIFF from ``amp`` (array or Strips): the amplitude and its dB,
    and the QGIS style of the dB band, stretched over the fully focused rows of the intensity ``inten``
    (the multilooked image the amplitude is resampled from: the same distribution, held anyway), taken
    on a regular grid of at most :data:`STRETCH_SAMPLES` pixels (a full scene's float64 copies would
    double the peak memory; the percentiles of 2^20 samples are within ~0.01 dB of the whole image's)."""
    from sarcli.io.images import Band, Style, amplitude_db, db_stretch

    rows = np.flatnonzero(full)
    step = max(1, int(np.ceil(np.sqrt(rows.size * inten.shape[1] / STRETCH_SAMPLES))))
    with np.errstate(divide="ignore"):
        lo, hi = db_stretch(10.0 * np.log10(inten[rows[::step], ::step].astype(np.float64)))
    if radiometry:  # the intensity is calibrated backscatter (sarcli.calibration.products)
        return ([Band(amp, f"sqrt({radiometry}), calibrated amplitude, {geometry}", "1", "power"),
                 Band(amp, f"{radiometry} 10 log10, {geometry}", "dB", "power_db",
                      derive=lambda a: amplitude_db(a, floor_db=None))],
                Style(2, lo, hi, "gray", f"{radiometry} (dB)"))
    return ([Band(amp, f"amplitude, {geometry}", "1", "power"),
             Band(amp, f"amplitude 20 log10|z|, {geometry}", "dB", "power_db",
                  derive=lambda a: amplitude_db(a, floor_db=None))],
            Style(2, lo, hi, "gray", "amplitude (dB)"))


def recorded_height(slc: SLC) -> float:
    """The terrain height the product was focused with (:func:`sarcli.io.slc.recorded_height`)."""
    from sarcli.io.slc import recorded_height as from_parameters

    return from_parameters(slc.parameters)


def _look_axes(slc: SLC, looks_az: int, looks_rg: int, shape: tuple[int, int]):
    """Zero-Doppler time and slant range at the centres of the look cells."""
    t = slc.azimuth_time[: shape[0] * looks_az].reshape(shape[0], looks_az).mean(axis=1)
    r = slc.slant_range[: shape[1] * looks_rg].reshape(shape[1], looks_rg).mean(axis=1)
    return t, r


def geolocate_grid(slc: SLC, rows: np.ndarray, cols: np.ndarray, t: np.ndarray, r: np.ndarray,
                   terrain: Terrain) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lat_deg, lon_deg, h) at the grid rows x cols of axes t (lines) and r (columns)."""
    from orbit.geodetic import ecef_to_geodetic
    from sarcli.focus.geolocation import zero_doppler_points

    if slc.orbit is None or slc.orbit.frame == "LOCAL":
        raise SarcliError("GeoTIFF needs an Earth orbit (ECI/ECEF state vectors); this product has "
                          f"{'none' if slc.orbit is None else 'a LOCAL (flat) frame'}")
    tt, rr = np.meshgrid(t[rows], r[cols], indexing="ij")
    p = zero_doppler_points(slc.orbit, slc.epoch_utc, tt, rr, slc.radar.wavelength_m, slc.look_side, terrain)
    return ecef_to_geodetic(p)


def _grid_index(n: int, k: int) -> np.ndarray:
    return np.unique(np.round(np.linspace(0, n - 1, max(2, min(k, n)))).astype(int))


def slant_gcps(slc: SLC, shape: tuple[int, int], looks_az: int, looks_rg: int, terrain: Terrain,
               gcp_lines: int = 10, gcp_cols: int = 10) -> list[tuple[float, float, float, float, float]]:
    """GCPs (row, col, lon, lat, h) at pixel centres of the multilooked raster."""
    t, r = _look_axes(slc, looks_az, looks_rg, shape)
    rows, cols = _grid_index(shape[0], gcp_lines), _grid_index(shape[1], gcp_cols)
    lat, lon, h = geolocate_grid(slc, rows, cols, t, r, terrain)
    return [(rows[i] + 0.5, cols[j] + 0.5, float(lon[i, j]), float(lat[i, j]), float(h[i, j]))
            for i in range(rows.size) for j in range(cols.size)]


def utm_epsg(lat_deg: float, lon_deg: float) -> int:
    """EPSG code of the UTM zone (WGS-84) containing (lat, lon)."""
    zone = int(np.floor((lon_deg + 180.0) / 6.0)) % 60 + 1
    return (32600 if lat_deg >= 0 else 32700) + zone


def write_slant_geotiff(path, slc: SLC, looks_az: int = 1, looks_rg: int = 1, tags: dict | None = None,
                        terrain: Terrain | None = None, inputs: tuple = (),
                        intensity: np.ndarray | None = None, compression: str = "deflate",
                        radiometry: str | None = None) -> None:
    """Amplitude in slant-range geometry with a lat/lon GCP grid (EPSG:4326) on ``terrain`` (default 0 m);
    ``tags``: extra tags beside :func:`slc_tags`; ``inputs``: the files it was made from (the SLC).
    ``intensity``: ``multilook(slc.image, looks_az, looks_rg)`` when the caller has it (then ``slc``
    needs no image); ``compression``: ``sarcli.io.images.COMPRESSIONS``; ``radiometry``: as in
    :func:`write_map_geotiff`."""
    from sarcli.io.images import Strips, write_geotiff

    inten = multilook(slc.image, looks_az, looks_rg) if intensity is None else intensity
    gcps = slant_gcps(slc, inten.shape, looks_az, looks_rg, terrain or ConstantHeight(0.0))
    full = full_rows(slc, inten.shape[0], looks_az)

    def strips():
        for a in range(0, inten.shape[0], STRIP):
            amp = np.sqrt(inten[a:a + STRIP])
            amp[~full[a:a + STRIP]] = np.nan
            yield a, amp

    bands, style = _amplitude_bands(Strips(inten.shape, strips), inten, full,
                                    "slant-range geometry (lines: zero-Doppler time)", radiometry)
    write_geotiff(path, bands, 4326, gcps=gcps, tags=slc_tags(slc, inputs, tags), style=style,
                  compression=compression)


def map_project(slc: SLC, looks_az: int = 1, looks_rg: int = 1, crs: str | None = None,
                spacing_m: float | None = None, terrain: Terrain | None = None, coarse: int = 33, strip: int = STRIP,
                intensity: np.ndarray | None = None):
    """(amplitude float32 with NaN outside the image and its fully focused lines, rasterio Affine
    transform, CRS string) in a map projection, pixels placed on ``terrain`` (default 0 m). With a DEM
    the coarse grid is made denser (``coarse`` at least 65): the inverse map is linear per triangle,
    and the terrain bends it on the scale of the hills. ``intensity``: as in
    :func:`write_slant_geotiff`."""
    strips, transform, crs = map_strips(slc, looks_az, looks_rg, crs, spacing_m, terrain, coarse, strip, intensity)
    out = np.empty(strips.shape, np.float32)
    for a, rows in strips:
        out[a:a + rows.shape[0]] = rows
    return out, transform, crs


def map_strips(slc: SLC, looks_az: int = 1, looks_rg: int = 1, crs: str | None = None,
               spacing_m: float | None = None, terrain: Terrain | None = None, coarse: int = 33, strip: int = STRIP,
               intensity: np.ndarray | None = None):
    """:func:`map_project` as (:class:`sarcli.io.images.Strips` of ``strip`` map rows, transform, CRS): the
    map raster is computed strip by strip as it is written, never held whole."""
    from pyproj import Transformer
    from rasterio.transform import Affine

    from sarcli.io.images import Strips

    inten = multilook(slc.image, looks_az, looks_rg) if intensity is None else intensity
    n, m = inten.shape
    t, r = _look_axes(slc, looks_az, looks_rg, inten.shape)
    rows, cols = _grid_index(n, coarse), _grid_index(m, coarse)
    terrain = terrain or ConstantHeight(0.0)
    if not isinstance(terrain, ConstantHeight):
        coarse = max(coarse, 65)
        rows, cols = _grid_index(n, coarse), _grid_index(m, coarse)
    lat, lon, _ = geolocate_grid(slc, rows, cols, t, r, terrain)
    if crs is None:
        crs = f"EPSG:{utm_epsg(float(np.mean(lat)), float(np.mean(lon)))}"
    try:
        tr = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
        x, y = tr.transform(lon, lat)
    except Exception as e:  # pyproj raises several types for bad CRS strings
        raise SarcliError(f"cannot project to {crs}: {e}") from None
    x, y = np.asarray(x), np.asarray(y)
    if spacing_m is None:
        d_az = np.hypot(np.diff(x, axis=0), np.diff(y, axis=0)) / np.diff(rows)[:, None]
        d_rg = np.hypot(np.diff(x, axis=1), np.diff(y, axis=1)) / np.diff(cols)[None, :]
        spacing_m = float(max(np.median(d_az), np.median(d_rg)))
    if not spacing_m > 0:
        raise SarcliError(f"pixel spacing must be positive, got {spacing_m}")
    x0, x1, y0, y1 = x.min(), x.max(), y.min(), y.max()
    nx = int(np.ceil((x1 - x0) / spacing_m)) + 1
    ny = int(np.ceil((y1 - y0) / spacing_m)) + 1
    if nx * ny > 4e9 / 4:
        raise SarcliError(f"map raster {ny} x {nx} is too large: increase the pixel spacing or the looks")
    inverse = MapInverse(x, y, rows, cols)
    full = full_rows(slc, n, looks_az)
    step, lat_rows, lat_cols, node_r, node_c, cls = map_lattice(inverse, x0, y1, spacing_m, (ny, nx))
    col_cell = np.minimum(np.arange(nx) // step, cls.shape[1] - 1)

    def strips():
        for a in range(0, ny, strip):
            b = min(ny, a + strip)
            amp = np.empty((b - a, nx), np.float32)
            lattice_amplitude(amp, a, step, lat_rows, lat_cols, node_r, node_c, cls, inten, full)
            i, j = _exact_pixels(cls, col_cell, lat_rows, step, a, b)
            if i.size:
                rc = inverse(x0 + j * spacing_m, y1 - i * spacing_m)
                amp[i - a, j] = points_amplitude(np.ascontiguousarray(rc[:, 0]), np.ascontiguousarray(rc[:, 1]),
                                                 inten, full)
            yield a, amp

    # pixel (i, j) centre at (x0 + j s, y1 - i s): the raster's corner is half a pixel up-left of it
    transform = Affine(spacing_m, 0.0, x0 - 0.5 * spacing_m, 0.0, -spacing_m, y1 + 0.5 * spacing_m)
    return Strips((ny, nx), strips), transform, crs


class MapInverse:
    """The triangulated inverse map (x, y) -> (row, column) of the multilooked image: linear over the
    Delaunay triangles of the projected coarse grid (``x``, ``y`` at image ``rows`` x ``cols``), NaN
    outside their convex hull.

    Locating a point outside the hull costs scipy a search of every triangle (its walk from the last
    triangle fails), so points beyond the hull by more than ``margin`` (1e-6 of the grid's extent:
    far beyond qhull's tolerance of 1.5e-7 of a triangle in barycentric coordinates) are NaN at once,
    from :func:`hull_excess`; the others are scipy's LinearNDInterpolator's values.
    """

    def __init__(self, x: np.ndarray, y: np.ndarray, rows: np.ndarray, cols: np.ndarray):
        from scipy.interpolate import LinearNDInterpolator
        from scipy.spatial import Delaunay

        rr, cc = np.meshgrid(rows.astype(float), cols.astype(float), indexing="ij")
        tri = Delaunay(np.column_stack([np.ravel(x), np.ravel(y)]))
        self.interpolator = LinearNDInterpolator(tri, np.column_stack([rr.ravel(), cc.ravel()]))
        p, e = tri.points, tri.convex_hull
        d = p[e[:, 1]] - p[e[:, 0]]
        nrm = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
        off = np.einsum("ij,ij->i", nrm, p[e[:, 0]])
        inward = np.einsum("ij,j->i", nrm, p.mean(axis=0)) - off > 0  # the centroid lies inside
        self.normals = np.ascontiguousarray(np.where(inward[:, None], -nrm, nrm))
        self.offsets = np.where(inward, -off, off)
        self.margin = 1e-6 * float(max(np.ptp(p[:, 0]), np.ptp(p[:, 1])))

    def excess(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """:func:`hull_excess` of the points (x, y) (arrays of one shape)."""
        x, y = np.broadcast_arrays(np.asarray(x, np.float64), np.asarray(y, np.float64))
        return hull_excess(self.normals, self.offsets, x.ravel(), y.ravel()).reshape(x.shape)

    def __call__(self, x: np.ndarray, y: np.ndarray, excess: np.ndarray | None = None) -> np.ndarray:
        """(row, col) at the points (x, y) (arrays of one shape), shape + (2,); ``excess``: their
        :meth:`excess` when the caller has it."""
        x, y = np.broadcast_arrays(np.asarray(x, np.float64), np.asarray(y, np.float64))
        near = (self.excess(x, y) if excess is None else excess) <= self.margin
        out = np.full(x.shape + (2,), np.nan)
        out[near] = self.interpolator(x[near], y[near])
        return out


@njit(parallel=True, cache=True)
def hull_excess(normals, offsets, x, y):
    """max_e (n_e . (x, y) - o_e) over the hull edges e (outward unit normals n_e, offsets o_e): the
    signed distance beyond the nearest edge line, negative inside the hull (minus the distance to the
    nearest edge line), positive outside (there a lower bound of the distance to the hull);
    1-Lipschitz in (x, y). ``x``, ``y``: 1-D."""
    out = np.empty(x.size)
    for p in prange(x.size):
        v = -np.inf
        for e in range(offsets.size):
            v = max(v, normals[e, 0] * x[p] + normals[e, 1] * y[p] - offsets[e])
        out[p] = v
    return out


def hull_excess_numpy(normals: np.ndarray, offsets: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Plain-numpy reference of :func:`hull_excess`."""
    return np.max(normals[:, 0, None] * x[None, :] + normals[:, 1, None] * y[None, :] - offsets[:, None], axis=0)


def _exact_pixels(cls: np.ndarray, col_cell: np.ndarray, lat_rows: np.ndarray, step: int, a: int, b: int):
    """(rows, columns) of the map pixels in rows [a, b) that lie in ``EXACT`` cells of :func:`map_lattice`
    (nodes every ``step`` pixels; ``col_cell``: the cell column of each pixel column)."""
    ii, jj = [], []
    last = cls.shape[0] - 1
    for k in range(min(a // step, last), last + 1):
        lo, hi = max(a, lat_rows[k]), (b if k == last else min(b, lat_rows[k + 1]))
        if lo >= b:
            break
        cols_k = np.flatnonzero(cls[k, col_cell] == EXACT)
        if cols_k.size and hi > lo:
            ii.append(np.repeat(np.arange(lo, hi), cols_k.size))
            jj.append(np.tile(cols_k, hi - lo))
    if not ii:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(ii), np.concatenate(jj)


def map_lattice(inverse: MapInverse, x0: float, y1: float, spacing: float, shape: tuple[int, int],
                steps: tuple[int, ...] = LATTICE_STEPS):
    """The lattice of the map raster (module docstring): (step, lattice rows, lattice columns, image row
    and image column at the nodes (n_rows_l, n_cols_l), class of each cell (n_rows_l - 1, n_cols_l - 1):
    ``OUTSIDE`` the hull, ``LATTICE`` (bilinear from its nodes) or ``EXACT``).

    Raster pixel (i, j) of ``shape`` (rows, columns) is at (x0 + j spacing, y1 - i spacing). Nodes
    every ``step`` pixels and at the last row/column. A cell inside the hull is ``LATTICE`` when the
    bound 2 d G of :func:`cell_gradient_spread` (d: the cell's diagonal) is within ``LATTICE_TOL_PX``.
    The step: of ``steps`` (decreasing), the one with the fewest exact evaluations (nodes plus the
    pixels of ``EXACT`` cells), trying smaller steps while that number decreases and their nodes
    alone would not cost more.
    """
    best = None
    for step in steps:
        if best is not None and (shape[0] // step + 1) * (shape[1] // step + 1) >= best[0]:
            break  # its nodes alone cost more
        lr, lc, cls = _lattice_classes(inverse, x0, y1, spacing, shape, step)
        cell_px = np.diff(lr)[:, None] * np.diff(lc)[None, :]
        cost = lr.size * lc.size + int(np.sum(cell_px[cls == EXACT]))
        if best is not None and cost >= best[0]:
            break
        best = (cost, step, lr, lc, cls)
    _, step, lr, lc, cls = best
    node = inverse(x0 + lc[None, :] * spacing, y1 - lr[:, None] * spacing)
    return (step, lr.astype(np.int64), lc.astype(np.int64), np.ascontiguousarray(node[..., 0]),
            np.ascontiguousarray(node[..., 1]), cls)


def _lattice_classes(inverse: MapInverse, x0: float, y1: float, spacing: float, shape: tuple[int, int], step: int):
    """(lattice rows, lattice columns, cell classes) of :func:`map_lattice` for one step."""
    ny, nx = shape
    lr = np.r_[np.arange(0, max(ny - 1, 1), step), max(ny - 1, 1)]
    lc = np.r_[np.arange(0, max(nx - 1, 1), step), max(nx - 1, 1)]
    diag = np.hypot(np.diff(lr)[:, None], np.diff(lc)[None, :])
    ci, cj = 0.5 * (lr[:-1] + lr[1:]), 0.5 * (lc[:-1] + lc[1:])
    centre = inverse.excess(x0 + cj[None, :] * spacing, y1 - ci[:, None] * spacing)
    # wholly inside (outside) the hull: the centre deeper than half the diagonal (hull_excess is 1-Lipschitz)
    cls = np.full(centre.shape, EXACT, np.int8)
    cls[centre > 0.5 * diag * spacing + inverse.margin] = OUTSIDE
    inside = centre < -(0.5 * diag * spacing + inverse.margin)
    spread = cell_gradient_spread(inverse, x0, y1, spacing, lr, lc)
    cls[inside & (2.0 * diag * spread <= LATTICE_TOL_PX)] = LATTICE
    return lr, lc, cls


def cell_gradient_spread(inverse: MapInverse, x0: float, y1: float, spacing: float, lat_rows: np.ndarray,
                         lat_cols: np.ndarray) -> np.ndarray:
    """Per lattice cell, G: the largest |grad T_a - grad T_b| (image pixels per map pixel, of the row or
    the column) between the triangles a, b that meet the cell, T_a the affine piece of the
    triangulated map on triangle a.

    The error bound: B reproduces an affine l, and its weights are >= 0 and sum to 1, so
    |B - T| <= |B(T - l)| + |T - l| <= 2 max_cell |T - l|; with l = T_a for a triangle a meeting the
    cell, T - l vanishes at a point q of the cell and grows from there by at most G per map pixel:
    |B - T| <= 2 d G (d: the cell's diagonal). Zero for a cell inside one triangle; a degenerate
    (sliver) triangle has an infinite G.
    """
    tri = inverse.interpolator.tri
    pts = np.column_stack([(tri.points[:, 0] - x0) / spacing, (y1 - tri.points[:, 1]) / spacing])  # (j, i)
    val = inverse.interpolator.values  # (row, col) at the points
    p, v = pts[tri.simplices], val[tri.simplices]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    d1, d2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        # grad . e1 = d1, grad . e2 = d2 (per output component): Cramer's rule, (n, 2 outputs, 2 coordinates)
        g = np.stack([(d1 * e2[:, 1, None] - d2 * e1[:, 1, None]) / det[:, None],
                      (d2 * e1[:, 0, None] - d1 * e2[:, 0, None]) / det[:, None]], axis=2)
    g = np.where(np.isfinite(g), g, np.inf).reshape(-1, 4)
    nk, nl = lat_rows.size - 1, lat_cols.size - 1
    step_r = max(int(lat_rows[1] - lat_rows[0]), 1)
    step_c = max(int(lat_cols[1] - lat_cols[0]), 1)
    lo_j, hi_j = np.floor(p[..., 0].min(axis=1)), np.ceil(p[..., 0].max(axis=1))
    lo_i, hi_i = np.floor(p[..., 1].min(axis=1)), np.ceil(p[..., 1].max(axis=1))
    k0 = np.clip(lo_i // step_r, 0, nk - 1).astype(int)
    k1 = np.clip(hi_i // step_r, 0, nk - 1).astype(int)
    l0 = np.clip(lo_j // step_c, 0, nl - 1).astype(int)
    l1 = np.clip(hi_j // step_c, 0, nl - 1).astype(int)
    # kept in float32 (a full scene's lattice at step 8 has 2.6 million cells: 166 MB of float64 extremes),
    # each value rounded outward (the max up, the min down): the ranges only grow, the bound stays one
    g_up, g_down = _float32_outward(g, np.inf), _float32_outward(g, -np.inf)
    gmax = np.full((nk, nl, 4), -np.inf, np.float32)
    gmin = np.full((nk, nl, 4), np.inf, np.float32)
    for t in range(g.shape[0]):
        box = (slice(k0[t], k1[t] + 1), slice(l0[t], l1[t] + 1))
        # the cells of the bounding box that the triangle meets: no edge line of the triangle has all four
        # corners of the cell strictly on its outer side (separating axes of a triangle and a box: the
        # box's own axes are the bounding box's)
        ci0, ci1 = lat_rows[k0[t]:k1[t] + 1, None], lat_rows[k0[t] + 1:k1[t] + 2, None]
        cj0, cj1 = lat_cols[None, l0[t]:l1[t] + 1], lat_cols[None, l0[t] + 1:l1[t] + 2]
        meets = np.ones((ci0.size, cj0.size), bool)
        for q in range(3):
            a, b, c = p[t, q], p[t, (q + 1) % 3], p[t, (q + 2) % 3]
            nj, ni = b[1] - a[1], a[0] - b[0]  # a normal of edge a-b, pointing away from c
            if nj * (c[0] - a[0]) + ni * (c[1] - a[1]) > 0:
                nj, ni = -nj, -ni
            lowest = (np.minimum(nj * (cj0 - a[0]), nj * (cj1 - a[0]))
                      + np.minimum(ni * (ci0 - a[1]), ni * (ci1 - a[1])))  # the corner least beyond the edge
            meets &= ~(lowest > 0)
        sub_max, sub_min = gmax[box], gmin[box]
        sub_max[meets] = np.maximum(sub_max[meets], g_up[t])
        sub_min[meets] = np.minimum(sub_min[meets], g_down[t])
    spread = np.zeros((nk, nl))
    for a, b in ((0, 1), (2, 3)):  # the row's gradient, the column's: one pair of components at a time
        np.maximum(spread, np.hypot(_value_range(gmax[..., a], gmin[..., a]),
                                    _value_range(gmax[..., b], gmin[..., b])), out=spread)
    return spread


def _float32_outward(x: np.ndarray, toward: float) -> np.ndarray:
    """``x`` in float32, each value rounded toward ``toward`` (+inf: never below x; -inf: never above)."""
    f = x.astype(np.float32)
    off = (f < x) if toward > 0 else (f > x)
    f[off] = np.nextafter(f[off], np.float32(toward))
    return f


def _value_range(hi: np.ndarray, lo: np.ndarray) -> np.ndarray:
    """hi - lo in float64 where a cell met a triangle (hi >= lo), 0 where none did; inf for a degenerate
    triangle's (infinite) gradient."""
    with np.errstate(invalid="ignore"):
        r = np.where(hi >= lo, hi.astype(np.float64) - lo, 0.0)
    r[np.isnan(r)] = np.inf
    return r


@njit(cache=True, inline="always")
def _amplitude_at(inten, full, r, c):
    """sqrt of ``inten`` bilinear at (row r, column c) (edges extended: scipy's map_coordinates
    order=1, mode="nearest"), NaN where r is not finite or either row around r is not fully
    focused."""
    if not (np.isfinite(r) and np.isfinite(c)):
        return np.float32(np.nan)
    n, m = inten.shape
    lo = min(max(int(math.floor(r)), 0), n - 1)
    hi = min(max(int(math.ceil(r)), 0), n - 1)
    if not (full[lo] and full[hi]):
        return np.float32(np.nan)
    rr = min(max(r, 0.0), n - 1.0)
    cc = min(max(c, 0.0), m - 1.0)
    i0 = min(int(rr), n - 1)
    j0 = min(int(cc), m - 1)
    i1 = min(i0 + 1, n - 1)
    j1 = min(j0 + 1, m - 1)
    fr = rr - i0
    fc = cc - j0
    v = ((1.0 - fr) * ((1.0 - fc) * inten[i0, j0] + fc * inten[i0, j1])
         + fr * ((1.0 - fc) * inten[i1, j0] + fc * inten[i1, j1]))
    return np.sqrt(np.float32(v))


@njit(parallel=True, cache=True)
def lattice_amplitude(out, first, step, lat_rows, lat_cols, node_r, node_c, cls, inten, full):
    """Map rows ``first ..`` of the amplitude into ``out`` (rows x nx): at a pixel of a ``LATTICE`` cell
    of :func:`map_lattice` (nodes every ``step`` pixels) the image position bilinear between the
    cell's nodes, then :func:`_amplitude_at`; NaN in ``OUTSIDE`` and ``EXACT`` cells (the caller fills
    the latter). Along a map row the position is linear inside a cell: one addition per pixel."""
    rows, nx = out.shape
    nk = cls.shape[0]
    for q in prange(rows):
        i = first + q
        k = min(i // step, nk - 1)
        wr = (i - lat_rows[k]) / (lat_rows[k + 1] - lat_rows[k])
        for lc in range(cls.shape[1]):
            j0 = lat_cols[lc]
            j1 = lat_cols[lc + 1] if lc < cls.shape[1] - 1 else nx
            if cls[k, lc] != LATTICE:
                out[q, j0:j1] = np.nan
                continue
            r0 = (1.0 - wr) * node_r[k, lc] + wr * node_r[k + 1, lc]
            r1 = (1.0 - wr) * node_r[k, lc + 1] + wr * node_r[k + 1, lc + 1]
            c0 = (1.0 - wr) * node_c[k, lc] + wr * node_c[k + 1, lc]
            c1 = (1.0 - wr) * node_c[k, lc + 1] + wr * node_c[k + 1, lc + 1]
            width = lat_cols[lc + 1] - j0
            for j in range(j0, j1):
                wc = (j - j0) / width
                out[q, j] = _amplitude_at(inten, full, r0 + wc * (r1 - r0), c0 + wc * (c1 - c0))


@njit(parallel=True, cache=True)
def points_amplitude(r, c, inten, full):
    """:func:`_amplitude_at` at the image positions (r, c) (NaN where they are not finite)."""
    out = np.empty(r.size, np.float32)
    for p in prange(r.size):
        out[p] = _amplitude_at(inten, full, r[p], c[p])
    return out


def amplitude_numpy(inten: np.ndarray, full: np.ndarray, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Plain-numpy reference of :func:`points_amplitude` (scipy's map_coordinates)."""
    from scipy.ndimage import map_coordinates

    ok = np.isfinite(r) & np.isfinite(c)
    vals = np.full(r.shape, np.nan, np.float32)
    vals[ok] = map_coordinates(inten, np.stack([r[ok], c[ok]]), order=1, mode="nearest")
    lo = np.clip(np.floor(r[ok]).astype(np.int64), 0, inten.shape[0] - 1)
    hi = np.clip(np.ceil(r[ok]).astype(np.int64), 0, inten.shape[0] - 1)
    vals[np.flatnonzero(ok)[~(full[lo] & full[hi])]] = np.nan
    return np.sqrt(vals)


def write_map_geotiff(path, slc: SLC, looks_az: int = 1, looks_rg: int = 1, crs: str | None = None,
                      spacing_m: float | None = None, tags: dict | None = None, terrain: Terrain | None = None,
                      inputs: tuple = (), intensity: np.ndarray | None = None, compression: str = "deflate",
                      radiometry: str | None = None) -> str:
    """Map-projected amplitude COG (NaN nodata; module docstring); returns the CRS used.
    ``intensity`` and ``compression``: as in :func:`write_slant_geotiff`; ``radiometry``: the intensity is
    that calibrated backscatter (beta0, sigma0, gamma0: :mod:`sarcli.calibration.products`), the bands
    are labelled so."""
    from sarcli.io.images import write_geotiff

    inten = multilook(slc.image, looks_az, looks_rg) if intensity is None else intensity
    amp, transform, crs = map_strips(slc, looks_az, looks_rg, crs, spacing_m, terrain, intensity=inten)
    bands, style = _amplitude_bands(amp, inten, full_rows(slc, inten.shape[0], looks_az),
                                    "map projected (bilinear intensity resampling)", radiometry)
    write_geotiff(path, bands, crs, transform=transform, tags=slc_tags(slc, inputs, tags), style=style,
                  compression=compression)
    return crs
