"""The single-look complex image product (``product_type = "slc"``), schema version 1.

Layout (SI units)::

    /                      provenance attributes (sarcli.io.h5common), epoch_utc, look_side, source,
                           algorithm, azimuth_spacing_m, range_spacing_m, prf_hz,
                           first_full_line / last_full_line (lines with the whole processed aperture)
    /image                 complex64 (n_lines, n_samples), chunked; azimuth along axis 0. Phase
                           convention: a scatterer at closest range R0 has phase arg(sigma) - 4 pi R0/lam
                           at its peak; the azimuth spectrum is centred on the Doppler centroid.
    /azimuth_time          float64 (n_lines,) ZERO-DOPPLER time of each line, s after epoch_utc
    /slant_range           float64 (n_samples,) closest-approach slant range of each column, m
    /doppler               the Doppler actually used, per processing block: block_time (n_blocks,) s
                           (raw time at which the model was evaluated), range_m (n_samples,),
                           fdc_hz, fr_hz_per_s, velocity_mps (n_blocks, n_samples)
    /radar                 the raw product's radar attributes
    /orbit, /attitude      copied from the raw product when present (geolocation); /orbit_ecef the
                           orbit in WGS-84 ECEF (:func:`sarcli.io.raw.write_platform`)
    /geolocation_grid      Earth orbits only: longitude, latitude, incidence_angle, look_angle (degrees) on
                           (height, azimuth_time, slant_range) nodes; root ``bounding_polygon`` (WKT)
    /truth                 copied from a simulated raw product (``sarcli quality`` compares with it)
    /calibration           radiometric LUTs (:class:`sarcli.model.slc.Calibration`,
                           :mod:`sarcli.calibration.radiometry`) on nodes azimuth_time x slant_range:
                           beta0, sigma0, gamma0 (multiplicative: beta0 = |DN|^2 * beta0), nes0 (noise-
                           equivalent sigma0, linear); attributes constant (K), applied / not_applied
                           (JSON lists of the model's terms), details (JSON); nes0_per_sample
                           (n_samples,) the noise floor of every column (on /slant_range)
    /timings               attributes: seconds per processing stage

Times are ``seconds since <epoch_utc>`` (CF); /image's axes are the dimension scales /azimuth_time and
/slant_range, so ``xarray.open_dataset(path, engine="h5netcdf")`` labels it (docs/products.md).
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterator

import h5py
import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import (
    atomic_h5,
    attach,
    attr_json,
    attr_number,
    attr_str,
    cf_time_units,
    coordinate,
    dataset,
    group,
    open_product,
    read_array,
    read_mapping,
    require,
    to_jsonable,
    write_mapping,
)
from sarcli.io.raw import read_platform, read_radar, write_platform, write_radar
from sarcli.model import checks as ck
from sarcli.model.raw import LOOK_SIDES
from sarcli.model.slc import SLC, Calibration, DopplerUsed

PRODUCT_TYPE = "slc"
SCHEMA_VERSION = "1"
AXIS_RTOL = 0.1  # zero-Doppler times and slant ranges are uniform grids: each step the mean step within 10 %


#: heights (m above the WGS-84 ellipsoid) of the geolocation grid's layers (NISAR's grid spans -500..9000 m)
GRID_HEIGHTS_M = (-500.0, 0.0, 500.0, 1000.0, 2000.0, 4000.0, 9000.0)
#: nodes of the geolocation grid along each image axis
GRID_NODES = 11


def recorded_height(parameters: dict | None) -> float:
    """The terrain height an SLC was focused with (``parameters["terrain"]``: the constant height, or the
    DEM's mean height), 0 m when it records none: a first-order height for quantities that depend
    weakly on it (ground spacings, the bounding polygon)."""
    t = parameters.get("terrain") if isinstance(parameters, dict) else None
    if isinstance(t, dict):
        for key in ("height_m", "mean_height_m"):
            if isinstance(t.get(key), int | float) and np.isfinite(t[key]):
                return float(t[key])
    return 0.0


def _write_geolocation(f: h5py.File, s: SLC, tunits: str) -> None:
    """/geolocation_grid (longitude, latitude, incidence and look angles of the zero-Doppler target on
    GRID_NODES x GRID_NODES image nodes at each of GRID_HEIGHTS_M, NISAR's layout) and the root
    ``bounding_polygon`` (WKT POLYGON of lon lat h, the image perimeter at the focusing height). An
    SLC without an Earth orbit (none, or LOCAL) gets neither; a geometry the solver cannot place
    (e.g. a range that never reaches a layer) records why in ``geolocation_note``."""
    from sarcli.io.nisar.rslc import _ecef_sv, _wkt_polygon, geolocation_cubes

    if s.orbit is None or s.orbit.frame == "LOCAL" or s.azimuth_time.size < 2 or s.slant_range.size < 2:
        f.attrs["geolocation_note"] = "no Earth orbit: no geolocation grid"
        return
    t = np.linspace(s.azimuth_time[0], s.azimuth_time[-1], GRID_NODES)
    r = np.linspace(s.slant_range[0], s.slant_range[-1], GRID_NODES)
    h = np.asarray(GRID_HEIGHTS_M)
    lam = s.radar.wavelength_m
    try:
        sv = _ecef_sv(s)
        cubes = geolocation_cubes(sv, t, r, h, lam, s.look_side)
        polygon = _wkt_polygon(sv, s.azimuth_time, s.slant_range, lam, s.look_side, recorded_height(s.parameters))
    except ProductError as e:
        f.attrs["geolocation_note"] = f"no geolocation grid: {e}"
        return
    f.attrs["bounding_polygon"] = polygon
    g = group(f, "geolocation_grid")
    g.attrs["description"] = ("zero-Doppler geolocation of image nodes on the WGS-84 ellipsoid raised by each height "
                              "(interpolate trilinearly in height, time, range)")
    hh = coordinate(g, "height", h, "m", "height above the WGS-84 ellipsoid")
    tt = coordinate(g, "azimuth_time", t, tunits, "zero-Doppler time of the grid nodes")
    rr = coordinate(g, "slant_range", r, "m", "slant range of the grid nodes")
    for name, key, units, desc in (("longitude", "coordinateX", "degree_east", "geodetic longitude (WGS-84)"),
                                   ("latitude", "coordinateY", "degree_north", "geodetic latitude (WGS-84)"),
                                   ("incidence_angle", "incidenceAngle", "degree",
                                    "angle between the line of sight and the ellipsoid normal at the target"),
                                   ("look_angle", "elevationAngle", "degree",
                                    "angle between the line of sight and the ellipsoid normal at the sensor")):
        dataset(g, name, np.asarray(cubes[key], np.float64), units=units, description=desc, dims=(hh, tt, rr))


def _write_meta(f: h5py.File, s: SLC, image: h5py.Dataset) -> None:
    tunits = cf_time_units(s.epoch_utc)
    f.attrs["parameters"] = json.dumps(to_jsonable(dict(s.parameters)), sort_keys=True)
    f.attrs["epoch_utc"] = s.epoch_utc
    f.attrs["look_side"] = s.look_side
    f.attrs["source"] = s.source
    f.attrs["algorithm"] = s.algorithm
    f.attrs["azimuth_spacing_m"] = float(s.azimuth_spacing_m)
    f.attrs["range_spacing_m"] = s.range_spacing_m
    f.attrs["prf_hz"] = s.prf_hz
    f.attrs["first_full_line"] = int(s.first_full_line)
    f.attrs["last_full_line"] = int(s.last_full_line)
    t = coordinate(f, "azimuth_time", np.asarray(s.azimuth_time, np.float64), tunits,
                   "zero-Doppler time of each image line")
    r = coordinate(f, "slant_range", np.asarray(s.slant_range, np.float64), "m",
                   "closest-approach slant range of each image column")
    attach(image, t, r)
    g = group(f, "doppler")
    g.attrs["description"] = "the Doppler used by the focuser, per processing block and range"
    d = s.doppler
    bt = coordinate(g, "block_time", np.asarray(d.block_time, np.float64), tunits,
                    "raw time at which the block's Doppler model was evaluated")
    rg = coordinate(g, "range_m", np.asarray(d.range_m, np.float64), "m", "slant range")
    for name, units, desc in (("fdc_hz", "Hz", "Doppler centroid used"), ("fr_hz_per_s", "Hz/s", "Doppler rate used"),
                              ("velocity_mps", "m/s", "effective velocity used")):
        dataset(g, name, np.asarray(getattr(d, name), np.float64), units=units, description=desc, dims=(bt, rg))
    write_radar(f, s.radar)
    write_platform(f, s.orbit, s.attitude, s.epoch_utc)
    _write_geolocation(f, s, tunits)
    if s.truth is not None:
        write_mapping(f, "truth", s.truth, s.epoch_utc)
    if s.calibration is not None:
        write_calibration(f, s.calibration, tunits, np.asarray(s.slant_range, np.float64))
    tg = group(f, "timings")
    for k, v in sorted(s.timings.items()):
        tg.attrs[k] = float(v)


def write_calibration(f: h5py.Group, cal: Calibration, tunits: str, slant_range: np.ndarray | None = None) -> None:
    """The /calibration group (module docstring), replacing one that is there; with the image's
    ``slant_range`` also ``nes0_per_sample``: the noise floor at every column (the nodes' mean over
    time, linear in range between nodes)."""
    if "calibration" in f:
        del f["calibration"]
    g = group(f, "calibration")
    g.attrs["description"] = ("radiometric look-up tables: X = |DN|^2 * X for X in beta0, sigma0, gamma0 "
                              "(bilinear between nodes; NaN: not calibrated); nes0 the noise-equivalent sigma0")
    g.attrs["constant"] = float(cal.constant)
    g.attrs["applied"] = json.dumps(list(cal.applied))
    g.attrs["not_applied"] = json.dumps(list(cal.not_applied))
    g.attrs["details"] = json.dumps(to_jsonable(dict(cal.details)), sort_keys=True)
    t = coordinate(g, "azimuth_time", np.asarray(cal.azimuth_time, np.float64), tunits,
                   "zero-Doppler time of the nodes")
    r = coordinate(g, "slant_range", np.asarray(cal.slant_range, np.float64), "m", "slant range of the nodes")
    for name, desc in (("beta0", "beta0 per |DN|^2"), ("sigma0", "sigma0 per |DN|^2 (ellipsoid incidence)"),
                       ("gamma0", "gamma0 per |DN|^2 (ellipsoid incidence)"),
                       ("nes0", "noise-equivalent sigma0 (linear)")):
        dataset(g, name, np.asarray(getattr(cal, name), np.float64), units="1", description=desc, dims=(t, r))
    if slant_range is not None and "slant_range" in f:
        with np.errstate(invalid="ignore"):
            per = np.interp(slant_range, cal.slant_range, np.mean(cal.nes0, axis=0))
        ds = dataset(g, "nes0_per_sample", per, units="1",
                     description="noise-equivalent sigma0 (linear) of every image column, mean over time")
        ds.dims[0].attach_scale(f["slant_range"])


def read_calibration(g: h5py.Group, path) -> Calibration:
    """Inverse of :func:`write_calibration` (one ProductError line on a malformed group)."""
    t = read_array(g, "azimuth_time", "f", ndim=1, min_size=1)
    r = read_array(g, "slant_range", "f", ndim=1, min_size=1)
    luts = [read_array(g, k, "f", shape=(t.size, r.size), finite=False) for k in ("beta0", "sigma0", "gamma0",
                                                                                  "nes0")]
    try:
        applied = tuple(json.loads(attr_str(g, "applied", "[]")))
        missing = tuple(json.loads(attr_str(g, "not_applied", "[]")))
        details = json.loads(attr_str(g, "details", "{}"))
    except ValueError:
        raise ProductError(f"{path}: calibration attributes are not valid JSON") from None
    return Calibration(t, r, *luts, constant=attr_number(g, "constant", lo=0.0), applied=applied,
                       not_applied=missing, details=details)


#: bytes of one ``/image`` chunk at most (HDF5's default chunk cache is 1 MiB: a chunk that a block
#: boundary splits stays in the cache until the next block completes it)
CHUNK_BYTES = 1 << 20


def image_chunks(shape: tuple[int, int]) -> tuple[int, int]:
    """HDF5 chunks of ``/image``: whole lines (no padding of the line to a multiple of a chunk width: a
    6354-sample line in 2048-wide chunks stored 29 % of padding), as many as fit in :data:`CHUNK_BYTES`."""
    n, m = (max(1, int(v)) for v in shape)
    return min(n, max(1, CHUNK_BYTES // (8 * m))), m


@contextlib.contextmanager
def slc_writer(path: str | os.PathLike, meta: SLC, shape: tuple[int, int], inputs: tuple = (),
               compression: str | None = None) -> Iterator[h5py.Dataset]:
    """Create the product atomically and yield the empty ``/image`` dataset to fill block by block
    (rows in any order).

    ``meta`` carries everything but the image (its ``image`` may be empty); metadata that is only
    known after processing (axes, Doppler, timings, parameters) can be set on ``meta`` inside the
    block (:meth:`SLC.update_from`): it is written when the block exits. The inputs are hashed
    meanwhile (:func:`sarcli.io.h5common.atomic_h5`).
    """
    chunks = image_chunks(shape)
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, meta.parameters, inputs) as f:
        ds = f.create_dataset("image", shape=shape, dtype=np.complex64, chunks=chunks, track_times=False,
                              **({"compression": compression} if compression else {}))
        ds.attrs["units"] = "1"
        ds.attrs["description"] = "focused single-look complex image (zero-Doppler line, slant-range column)"
        yield ds
        _write_meta(f, meta, ds)


def write_slc(path: str | os.PathLike, s: SLC, inputs: tuple = ()) -> None:
    """Write an in-memory SLC atomically."""
    if s.image.shape != (s.azimuth_time.size, s.slant_range.size):
        raise ProductError(f"SLC image shape {s.image.shape} does not match its axes")
    with slc_writer(path, s, s.image.shape, inputs) as ds:
        ds[...] = np.asarray(s.image, np.complex64)


def read_slc(path: str | os.PathLike, load_image: bool = True) -> SLC:
    """Read an SLC product; a malformed or implausible file raises :class:`ProductError` (one line).

    Checks: a complex (n_lines, n_samples) image (finite, when loaded); zero-Doppler times and slant
    ranges finite, strictly increasing and uniform (each step the mean step within 10 %), ranges
    positive; the radar (:meth:`Radar.validate`), orbit and attitude; the Doppler used (1-D block
    times and ranges, (n_blocks, n_ranges) finite centroid, rate and a positive velocity); typed
    scalar attributes, an ISO-8601 epoch, JSON parameters.
    """
    with open_product(path, PRODUCT_TYPE) as f:
        where = str(path)
        sv = attr_str(f, "schema_version")
        if sv != SCHEMA_VERSION:
            raise ProductError(f"{path}: slc schema version {sv} is not supported (expected {SCHEMA_VERSION})")
        img = require(f, "image", path, shape_rank=2, dtype_kind="c")
        t = read_array(f, "azimuth_time", "f", ndim=1)
        r = read_array(f, "slant_range", "f", ndim=1)
        if img.shape != (t.size, r.size) or t.size < 1 or r.size < 1:
            raise ProductError(f"{path}: malformed product, image {img.shape} vs axes ({t.size}, {r.size})")
        for name, a in (("azimuth_time", t), ("slant_range", r)):
            ck.increasing(where, name, a)
            if a.size > 1:
                ck.uniform(where, name, a, float(np.mean(np.diff(a))), AXIS_RTOL)
        if r[0] <= 0:
            raise ProductError(f"{path}: slant_range must be positive, starts at {r[0]:g} m")
        for name in ("radar", "doppler"):
            if name not in f or not isinstance(f[name], h5py.Group):
                raise ProductError(f"{path}: malformed product, missing group '{name}'")
        radar = read_radar(f["radar"], path)
        radar.validate(where)
        dg = f["doppler"]
        bt = read_array(dg, "block_time", "f", ndim=1, min_size=1)
        rm = read_array(dg, "range_m", "f", ndim=1, min_size=1)
        grid = (bt.size, rm.size)
        dop = DopplerUsed(bt, rm, *(read_array(dg, k, "f", shape=grid) for k in ("fdc_hz", "fr_hz_per_s",
                                                                                  "velocity_mps")))
        if np.any(dop.velocity_mps <= 0):
            raise ProductError(f"{path}: doppler/velocity_mps must be positive")
        orbit, attitude = read_platform(f, path)
        for part in (orbit, attitude):
            if part is not None:
                part.validate(where)
        truth = read_mapping(f["truth"]) if "truth" in f else None
        calibration = read_calibration(f["calibration"], path) if "calibration" in f else None
        timings = {}
        if "timings" in f:
            timings = {k: attr_number(f["timings"], k) for k in f["timings"].attrs}
        n = t.size
        slc = SLC(
            image=np.zeros((n, 0), np.complex64), azimuth_time=t, slant_range=r,
            epoch_utc=ck.utc(where, "epoch_utc", attr_str(f, "epoch_utc")), radar=radar, doppler=dop,
            look_side=ck.text(where, "look_side", attr_str(f, "look_side", "right"), LOOK_SIDES),
            source=attr_str(f, "source", "unknown"), algorithm=attr_str(f, "algorithm", "rd"),
            azimuth_spacing_m=attr_number(f, "azimuth_spacing_m", float("nan"), lo=0.0, unit="m"),
            first_full_line=attr_number(f, "first_full_line", 0, integer=True),
            last_full_line=attr_number(f, "last_full_line", n - 1, integer=True),
            parameters=attr_json(f, "parameters", {}), timings=timings,
            orbit=orbit, attitude=attitude, truth=truth, calibration=calibration,
        )
        if load_image:
            slc.image = ck.array(where, "image", img[()], "c")
        return slc
