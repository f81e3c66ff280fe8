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

Both are Cloud-Optimized GeoTIFFs (:func:`sarcli.io.images.write_geotiff`) with two bands, the amplitude
(``1``, overviews sqrt(mean |z|^2)) and the amplitude in dB (20 log10, overviews in power), the
provenance tags of the SLC (sensor, wavelength, look side, first and last zero-Doppler times, the SLC
file's SHA-256, the fully focused lines) and a QGIS style showing the dB band. Lines outside the fully
focused span (``first_full_line..last_full_line``: lines without the whole processed aperture) are
MASKED: a look cell that holds any such line is NaN (nodata) in the slant GeoTIFF, and so is every
map pixel that falls between its rows; the tag ``FULLY_FOCUSED_LINES`` gives the span.
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError
from sarcli.model.slc import SLC
from sarcli.model.terrain import ConstantHeight, Terrain

#: rows of the GeoTIFFs computed and written at a time (a multiple of their 256-row tiles)
STRIP = 512
#: pixels of the multilooked intensity the dB stretch of the QGIS style is taken from (a regular grid)
STRETCH_SAMPLES = 1 << 20


def multilook(image: np.ndarray, looks_az: int = 1, looks_rg: int = 1) -> np.ndarray:
    """Mean intensity |z|^2 over looks_az x looks_rg cells (float32; partial cells at the end dropped)."""
    if looks_az < 1 or looks_rg < 1:
        raise SarcliError("looks must be positive integers")
    n, m = image.shape[0] // looks_az, image.shape[1] // looks_rg
    if n < 1 or m < 1:
        raise SarcliError(f"image {image.shape} is smaller than one {looks_az} x {looks_rg} look cell")
    out = np.empty((n, m), np.float32)
    step = max(1, 4096 // looks_az)
    for a in range(0, n, step):
        b = min(n, a + step)
        blk = image[a * looks_az:b * looks_az, :m * looks_rg]
        p = (blk.real.astype(np.float32) ** 2 + blk.imag.astype(np.float32) ** 2)
        out[a:b] = p.reshape(b - a, looks_az, m, looks_rg).mean(axis=(1, 3))
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


def _amplitude_bands(amp, inten: np.ndarray, full: np.ndarray, geometry: str):
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
                        intensity: np.ndarray | None = None) -> None:
    """Amplitude in slant-range geometry with a lat/lon GCP grid (EPSG:4326) on ``terrain`` (default 0 m);
    ``tags``: extra tags beside :func:`slc_tags`; ``inputs``: the files it was made from (the SLC).
    ``intensity``: ``multilook(slc.image, looks_az, looks_rg)`` when the caller has it (then ``slc``
    needs no image)."""
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
                                    "slant-range geometry (lines: zero-Doppler time)")
    write_geotiff(path, bands, 4326, gcps=gcps, tags=slc_tags(slc, inputs, tags), style=style)


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
    from scipy.interpolate import LinearNDInterpolator
    from scipy.ndimage import map_coordinates

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
    rr, cc = np.meshgrid(rows.astype(float), cols.astype(float), indexing="ij")
    inv = LinearNDInterpolator(np.column_stack([x.ravel(), y.ravel()]), np.column_stack([rr.ravel(), cc.ravel()]))
    full = full_rows(slc, n, looks_az)
    xs = x0 + np.arange(nx) * spacing_m

    def strips():
        for a in range(0, ny, strip):
            b = min(ny, a + strip)
            ys = y1 - np.arange(a, b) * spacing_m
            gx, gy = np.meshgrid(xs, ys)
            rc = inv(gx.ravel(), gy.ravel())
            ok = np.all(np.isfinite(rc), axis=1)
            vals = np.full(gx.size, np.nan, np.float32)
            if np.any(ok):
                vals[ok] = map_coordinates(inten, rc[ok].T, order=1, mode="nearest")
                # a pixel between two rows takes both: masked unless both are fully focused
                lo = np.clip(np.floor(rc[ok, 0]).astype(np.int64), 0, n - 1)
                hi = np.clip(np.ceil(rc[ok, 0]).astype(np.int64), 0, n - 1)
                vals[np.flatnonzero(ok)[~(full[lo] & full[hi])]] = np.nan
            yield a, np.sqrt(vals).reshape(gx.shape)

    # pixel (i, j) centre at (x0 + j s, y1 - i s): the raster's corner is half a pixel up-left of it
    transform = Affine(spacing_m, 0.0, x0 - 0.5 * spacing_m, 0.0, -spacing_m, y1 + 0.5 * spacing_m)
    return Strips((ny, nx), strips), transform, crs


def write_map_geotiff(path, slc: SLC, looks_az: int = 1, looks_rg: int = 1, crs: str | None = None,
                      spacing_m: float | None = None, tags: dict | None = None, terrain: Terrain | None = None,
                      inputs: tuple = (), intensity: np.ndarray | None = None) -> str:
    """Map-projected amplitude COG (NaN nodata; module docstring); returns the CRS used.
    ``intensity``: as in :func:`write_slant_geotiff`."""
    from sarcli.io.images import write_geotiff

    inten = multilook(slc.image, looks_az, looks_rg) if intensity is None else intensity
    amp, transform, crs = map_strips(slc, looks_az, looks_rg, crs, spacing_m, terrain, intensity=inten)
    bands, style = _amplitude_bands(amp, inten, full_rows(slc, inten.shape[0], looks_az),
                                    "map projected (bilinear intensity resampling)")
    write_geotiff(path, bands, crs, transform=transform, tags=slc_tags(slc, inputs, tags), style=style)
    return crs
