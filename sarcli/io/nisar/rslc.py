"""NISAR L1 RSLC layout: write a sarcli SLC in it, read RSLC files (sarcli's and ISCE3's) as an SLC.

Layout (``/science/{LSAR|SSAR}/``; ISCE3 ``nisar.products.writers.SLC`` and readers, [NISAR-RSLC])::

    identification/          productType "RSLC", productLevel "L1", lookDirection, orbitPassDirection,
                             zeroDopplerStartTime/EndTime, listOfFrequencies, boundingPolygon (WKT), ...
    RSLC/swaths/zeroDopplerTime (n_lines,) s, epoch in units; zeroDopplerTimeSpacing
    RSLC/swaths/frequencyA/{HH,HV,...}  (n_lines, n_samples) complex64 (or complex32: float16 pairs)
        listOfPolarizations, slantRange (m), slantRangeSpacing, processedCenterFrequency,
        acquiredCenterFrequency, acquiredRangeBandwidth, processedRangeBandwidth,
        processedAzimuthBandwidth, nominalAcquisitionPRF, sceneCenterAlongTrackSpacing,
        sceneCenterGroundRangeSpacing, numberOfSubSwaths, validSamplesSubSwath1 (n_lines, 2)
    RSLC/metadata/orbit/{time, position, velocity, acceleration, orbitType, interpMethod}  ECEF
    RSLC/metadata/attitude/{time, quaternions, attitudeType}   RCS -> ECEF (see .attitude)
    RSLC/metadata/processingInformation/parameters/frequencyA/{dopplerCentroid, zeroDopplerTime,
        slantRange}  (Hz over zero-Doppler time x slant range; the axes also one level up),
        rangeChirpWeighting, azimuthChirpWeighting (256 values over the sampling band, fftshifted
        frequency order; attributes window_name/window_shape), referenceTerrainHeight,
        runConfigurationContents (sarcli: the processing parameters as JSON)
    RSLC/metadata/processingInformation/{algorithms, inputs}   strings (software version, inputs)
    RSLC/metadata/calibrationInformation/geometry/{beta0, sigma0, gamma0, zeroDopplerTime, slantRange}
        the SLC's radiometric LUTs (X = |DN|^2 * X), frequencyA/{pol}/nes0, absoluteCalibrationConstant
        (when the SLC carries a calibration: :mod:`sarcli.calibration.radiometry`)
    RSLC/metadata/geolocationGrid/  cubes (height, zeroDopplerTime, slantRange): coordinateX/Y (lon/lat,
        epsg 4326), incidenceAngle, elevationAngle, losUnitVectorX/Y, alongTrackUnitVectorX/Y,
        groundTrackVelocity; axes heightAboveEllipsoid (-500..9000 m, 20 levels), zeroDopplerTime,
        slantRange (about 500 m posting, 5 nodes of margin each side, as ISCE3)

sarcli writes, in addition, its provenance and SLC attributes on the root (``product_type =
"nisar_rslc"``, ``first_full_line``/``last_full_line``, ``sarcli_radar``) and reads them back when
present. Conventions: the image is on the zero-Doppler grid; zeroDopplerTime on a whole-second epoch
(NISAR's writers refuse a fractional epoch: sarcli shifts its times by the fraction); the phase
convention of sarcli (``arg(sigma) - 4 pi R0/lam`` at a target's peak) is ISCE3's. Bands: L (1-2
GHz) and S (2-4 GHz) use their own root; a product at another carrier (a C-band simulation) is written
under LSAR with ``identification/radarBand`` naming its real band, so that NISAR tools find it.

Reading (``read_rslc``) follows what ISCE3 writes and accepts the older variants its readers accept:
product group ``SLC`` instead of ``RSLC``, Doppler LUT axes one level up, complex32 images, epochs with
a space or a ``T`` and fractional seconds, missing optional items (attitude, Doppler, weighting).
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from orbit.errors import OrbitError
from orbit.statevectors import StateVectors
from sarcli import __version__
from sarcli.errors import ConfigError, FormatError, ProductError
from sarcli.io.h5common import atomic_h5, created_utc, dataset, group, to_jsonable
from sarcli.io.nisar.attitude import model_attitude, quaternions_from_model
from sarcli.io.nisar.h5util import (
    band_root,
    complex_rows,
    is_hdf5,
    member_names,
    need,
    number,
    open_h5,
    optional_text,
    seconds_between,
    text,
    text_list,
    time_axis,
    units_since,
    whole_second_epoch,
)
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import Orbit, Radar
from sarcli.model.slc import SLC, DopplerUsed

PRODUCT_TYPE = "nisar_rslc"
SCHEMA_VERSION = "1"
WEIGHTING_SIZE = 256
GRID_HEIGHTS_M = np.linspace(-500.0, 9000.0, 20)
GRID_POSTING_M = 500.0
GRID_MARGIN = 5
POLARIZATIONS = ("HH", "HV", "VH", "VV", "LH", "LV", "RH", "RV")


@dataclass
class Weighting:
    """A spectral weighting as NISAR stores it: ``values`` at the frequencies
    ``fftshift(fftfreq(len(values))) * rate`` (rate: range sampling rate, or the line rate), i.e. at
    normalized frequencies in [-1/2, 1/2) of the sampling band, zero outside the processed band;
    ``name`` "Kaiser" or "Cosine" and ``shape`` (Kaiser beta, cosine pedestal) when it is one of those."""

    values: np.ndarray
    name: str = ""
    shape: float = float("nan")


@dataclass
class RslcMeta:
    """What an RSLC holds beyond the SLC model: processed bands and weightings, names, inputs."""

    processed_range_bandwidth_hz: float
    processed_azimuth_bandwidth_hz: float
    acquired_range_bandwidth_hz: float
    range_weighting: Weighting | None = None
    azimuth_weighting: Weighting | None = None
    frequency: str = "A"
    mission_id: str = "sarcli"
    instrument: str = "sarcli"
    terrain_height_m: float = 0.0
    input_names: tuple[str, ...] = ()
    algorithms: dict[str, str] = field(default_factory=dict)


def sniff_rslc(path: str | os.PathLike) -> bool:
    """True when ``path`` is an HDF5 file with a ``/science/{L,S}SAR/{RSLC,SLC}/swaths`` group."""
    if not is_hdf5(path):
        return False
    try:
        with h5py.File(path, "r") as f:
            return any(isinstance(f.get(f"science/{b}/{p}/swaths"), h5py.Group)
                       for b in ("LSAR", "SSAR") for p in ("RSLC", "SLC"))
    except (OSError, RuntimeError, KeyError, ValueError):  # h5py on a damaged file: not sniffable
        return False


def _band_of(carrier_hz: float) -> tuple[str, str]:
    """(root group, IEEE band letter) for a carrier frequency."""
    edges = ((1e9, "P"), (2e9, "L"), (4e9, "S"), (8e9, "C"), (12e9, "X"), (18e9, "Ku"), (27e9, "K"))
    letter = next((b for top, b in edges if carrier_hz < top), "Ka")
    return ("SSAR" if letter == "S" else "LSAR"), letter


def _put(g: h5py.Group, name: str, value: Any, description: str, units: str | None = None,
         dtype: Any = None) -> h5py.Dataset:
    """A NISAR dataset: strings as fixed-length bytes (lists of strings as arrays), numbers as given,
    ``description`` and ``units`` attributes as bytes (ISCE3's spelling)."""
    if isinstance(value, str):
        data: Any = np.bytes_(value or "\x00")
    elif isinstance(value, list | tuple) and value and all(isinstance(v, str) for v in value):
        data = np.array([v.encode() for v in value])
    else:
        data = np.asarray(value, dtype=dtype)
    ds = dataset(g, name, data)
    ds.attrs["description"] = np.bytes_(description)
    if units is not None:
        ds.attrs["units"] = np.bytes_(units)
    return ds


def _ecef_sv(slc: SLC) -> StateVectors:
    if slc.orbit is None or slc.orbit.frame not in ("ECI", "ECEF"):
        raise ProductError("a NISAR RSLC needs an Earth orbit (ECI or ECEF state vectors); this SLC has "
                           f"{'none' if slc.orbit is None else 'a LOCAL (flat-Earth) orbit'}")
    try:
        return StateVectors.from_record(slc.orbit, slc.epoch_utc).to_ecef()
    except OrbitError as e:
        raise ProductError(f"SLC orbit: {e}") from None


def _geolocate(sv: StateVectors, t, r, h, lam: float, side: str) -> np.ndarray:
    from orbit.errors import GeometryError
    from orbit.geometry import geolocate

    try:
        return geolocate(sv, t, r, lam, 0.0, h, side)
    except GeometryError as e:
        raise ProductError(f"geolocation grid: {e}") from None


def _enu(lat_deg: np.ndarray, lon_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """East, north, up unit vectors (ECEF components) at geodetic latitude/longitude."""
    la, lo = np.radians(lat_deg), np.radians(lon_deg)
    east = np.stack([-np.sin(lo), np.cos(lo), np.zeros_like(lo)], -1)
    north = np.stack([-np.sin(la) * np.cos(lo), -np.sin(la) * np.sin(lo), np.cos(la)], -1)
    up = np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], -1)
    return east, north, up


def _grid_axis(a: float, b: float, spacing: float, span_lo: float, span_hi: float) -> np.ndarray:
    """Nodes a..b at about ``spacing`` (at least 2) plus GRID_MARGIN nodes beyond each end, clipped to
    [span_lo, span_hi]."""
    n = max(2, int(np.ceil(abs(b - a) / spacing)) + 1)
    step = (b - a) / (n - 1) if b != a else spacing
    x = a + step * np.arange(-GRID_MARGIN, n + GRID_MARGIN)
    return x[(x >= span_lo) & (x <= span_hi)]


def geolocation_cubes(sv: StateVectors, t: np.ndarray, r: np.ndarray, heights: np.ndarray, lam: float,
                      side: str) -> dict[str, np.ndarray]:
    """The NISAR geolocation-grid layers on the grid heights x t x r (zero-Doppler, ECEF orbit).

    LOS = unit vector target -> sensor; incidence = angle between the LOS and the ellipsoid normal at
    the target; elevation = angle between the LOS and the ellipsoid normal at the sensor (the look
    angle); along-track unit vector = the sensor velocity's horizontal direction at the target (east,
    north); ground-track velocity = |v| |p| / |r| (the velocity scaled to the target's geocentric
    radius). Angles in degrees."""
    from orbit.geodetic import ecef_to_geodetic
    from orbit.geometry import incidence_angle, look_angle

    H, T, R = np.meshgrid(heights, t, r, indexing="ij")
    p = _geolocate(sv, T, R, H, lam, side)
    pos, vel, _ = sv.interpolate(T)
    lat, lon, _ = ecef_to_geodetic(p)
    east, north, _ = _enu(lat, lon)
    los = (pos - p) / np.linalg.norm(pos - p, axis=-1, keepdims=True)
    ve, vn = np.sum(vel * east, -1), np.sum(vel * north, -1)
    vh = np.hypot(ve, vn)
    return {
        "coordinateX": lon, "coordinateY": lat,
        "incidenceAngle": np.degrees(incidence_angle(pos, p)), "elevationAngle": np.degrees(look_angle(pos, p)),
        "losUnitVectorX": np.sum(los * east, -1), "losUnitVectorY": np.sum(los * north, -1),
        "alongTrackUnitVectorX": ve / vh, "alongTrackUnitVectorY": vn / vh,
        "groundTrackVelocity": np.linalg.norm(vel, axis=-1) * np.linalg.norm(p, axis=-1)
        / np.linalg.norm(pos, axis=-1),
    }


def _wkt_polygon(sv: StateVectors, t: np.ndarray, r: np.ndarray, lam: float, side: str, h: float) -> str:
    """WKT POLYGON (lon lat h) of the image perimeter at height h (10 points a side, closed)."""
    from orbit.geodetic import ecef_to_geodetic

    k = 10
    ti, ri = np.linspace(t[0], t[-1], k), np.linspace(r[0], r[-1], k)
    tt = np.r_[ti, np.full(k, t[-1]), ti[::-1], np.full(k, t[0])]
    rr = np.r_[np.full(k, r[0]), ri, np.full(k, r[-1]), ri[::-1]]
    lat, lon, hh = ecef_to_geodetic(_geolocate(sv, tt, rr, np.full(tt.size, h), lam, side))
    pts = [f"{a:.10f} {b:.10f} {c:.3f}" for a, b, c in zip(lon, lat, hh, strict=True)]
    return "POLYGON ((" + ",".join([*pts, pts[0]]) + "))"


def _ground_spacings(sv: StateVectors, slc: SLC, h: float) -> tuple[float, float]:
    """(along-track, ground-range) spacing in metres between neighbouring pixels at mid-scene."""
    n, m = slc.azimuth_time.size, slc.slant_range.size
    i, j = n // 2, m // 2
    i1, j1 = min(i + 1, n - 1), min(j + 1, m - 1)
    i0, j0 = i1 - 1, j1 - 1
    t = slc.azimuth_time[[i0, i1, i0]]
    r = slc.slant_range[[j0, j0, j1]]
    p = _geolocate(sv, t, r, np.full(3, h), slc.radar.wavelength_m, slc.look_side)
    return float(np.linalg.norm(p[1] - p[0])), float(np.linalg.norm(p[2] - p[0]))


def _doppler_lut(slc: SLC, t_shift: float, n_x: int = 64) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(zero-Doppler times, slant ranges, fdc (n_t, n_x)) on a uniform grid over the image: the SLC's
    per-block centroids moved from raw to zero-Doppler time by the focuser's line shift and
    interpolated (held beyond the first and last block)."""
    d = slc.doppler
    t = slc.azimuth_time + t_shift
    r = slc.slant_range
    x = np.linspace(r[0], r[-1], max(2, min(n_x, r.size)))
    shift_s = float(slc.parameters.get("shift_lines", 0)) / slc.prf_hz
    bt = np.asarray(d.block_time, np.float64).reshape(-1) - shift_s + t_shift
    fdc = np.asarray(d.fdc_hz, np.float64)
    if bt.size == 0 or fdc.ndim != 2 or fdc.shape[0] != bt.size or not np.all(np.isfinite(fdc)):
        return np.array([t[0], t[-1]]), x, np.full((2, x.size), np.nan)
    rows = np.array([np.interp(x, np.asarray(d.range_m, np.float64), f) for f in fdc])
    y = np.linspace(t[0], t[-1], max(2, bt.size))
    order = np.argsort(bt)
    lut = np.array([[np.interp(yy, bt[order], rows[order][:, k]) for k in range(x.size)] for yy in y])
    return y, x, lut


def write_rslc(path: str | os.PathLike, images: Mapping[str, SLC], meta: RslcMeta, inputs: tuple = (),
               compression: str | None = None, parameters: Mapping[str, Any] | None = None) -> None:
    """Write SLCs (one per polarization, same grid) atomically in the NISAR RSLC layout (module docstring).

    ``images``: polarization ("HH", ...) -> SLC. ``inputs``: files whose hashes go into the provenance;
    ``parameters``: added to the SLC's processing parameters in the root ``parameters`` (e.g. the
    export configuration).
    Refuses (one line) an SLC without an Earth orbit, images on different grids, unknown polarizations.
    """
    if not images:
        raise ConfigError("nothing to write: no image given")
    for pol in images:
        if pol not in POLARIZATIONS:
            raise ConfigError(f"polarization {pol!r} is not one of {', '.join(POLARIZATIONS)}")
    if len(meta.frequency) != 1 or not meta.frequency.isalpha() or not meta.frequency.isupper():
        raise ConfigError(f"frequency must be one upper-case letter (A, B), got {meta.frequency!r}")
    first = next(iter(images.values()))
    for pol, s in images.items():
        if s.image.shape != (first.azimuth_time.size, first.slant_range.size):
            raise ProductError(f"{pol}: image shape {s.image.shape} does not match its axes")
        if not (np.array_equal(s.azimuth_time, first.azimuth_time) and np.array_equal(s.slant_range, first.slant_range)
                and s.epoch_utc == first.epoch_utc):
            raise ProductError(f"{pol}: not on the grid of the first polarization: write them to separate files")
    slc = first
    n, m = slc.image.shape
    if n < 2 or m < 2:
        raise ProductError(f"SLC image {slc.image.shape} is too small for an RSLC (at least 2 x 2)")
    sv = _ecef_sv(slc)
    lam = slc.radar.wavelength_m
    epoch, frac = whole_second_epoch(slc.epoch_utc)
    units = units_since(epoch)
    sv_file = StateVectors(sv.time + frac, sv.position, sv.velocity, "ECEF", epoch)
    t = slc.azimuth_time + frac
    r = slc.slant_range
    root_name, band_letter = _band_of(slc.radar.carrier_frequency_hz)
    h = float(meta.terrain_height_m)
    ds_az, ds_gr = _ground_spacings(sv_file, _shifted(slc, frac, epoch), h)
    chunks = (min(n, 512), min(m, 512))
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, {**slc.parameters, **(parameters or {})}, inputs) as f:
        f.attrs["Conventions"] = np.bytes_("CF-1.7")
        f.attrs["title"] = np.bytes_("NISAR L1 RSLC layout, written by sarcli")
        f.attrs["reference_document"] = np.bytes_("JPL D-102268 NISAR L1 RSLC product specification (layout)")
        f.attrs["institution"] = np.bytes_("sarcli")
        f.attrs["epoch_utc"] = epoch
        f.attrs["source"] = slc.source
        f.attrs["look_side"] = slc.look_side
        f.attrs["algorithm"] = slc.algorithm
        f.attrs["first_full_line"] = int(slc.first_full_line)
        f.attrs["last_full_line"] = int(slc.last_full_line)
        f.attrs["sarcli_radar"] = json.dumps(to_jsonable(vars(slc.radar)), sort_keys=True)
        sci = group(group(f, "science"), root_name)
        prod = group(sci, "RSLC")
        sw = group(prod, "swaths")
        _put(sw, "zeroDopplerTime", t, "CF compliant dimension associated with azimuth time", units)
        _put(sw, "zeroDopplerTimeSpacing", float(np.median(np.diff(t))), "Time interval in the along-track "
             "direction for raster layers", "seconds")
        fg = group(sw, f"frequency{meta.frequency}")
        for pol, s in images.items():
            ds = dataset(fg, pol, np.asarray(s.image, np.complex64), chunks=chunks, compression=compression)
            ds.attrs["description"] = np.bytes_(f"Focused RSLC image ({pol})")
            ds.attrs["units"] = np.bytes_("1")
        _put(fg, "listOfPolarizations", list(images), f"List of processed polarization layers with frequency "
             f"{meta.frequency}")
        _put(fg, "slantRange", r, "CF compliant dimension associated with slant range", "meters")
        _put(fg, "slantRangeSpacing", float(r[1] - r[0]), "Slant range spacing of grid", "meters")
        fc = slc.radar.carrier_frequency_hz
        _put(fg, "processedCenterFrequency", fc, "Center frequency of the processed image in hertz", "hertz")
        _put(fg, "acquiredCenterFrequency", fc, "Center frequency of the acquisition in hertz", "hertz")
        _put(fg, "acquiredRangeBandwidth", meta.acquired_range_bandwidth_hz, "Acquisition range bandwidth in "
             "hertz", "hertz")
        _put(fg, "processedRangeBandwidth", meta.processed_range_bandwidth_hz, "Processed range bandwidth in "
             "hertz", "hertz")
        _put(fg, "processedAzimuthBandwidth", meta.processed_azimuth_bandwidth_hz, "Processed azimuth bandwidth "
             "in hertz", "hertz")
        _put(fg, "nominalAcquisitionPRF", slc.radar.prf_hz, "Nominal PRF of acquisition", "hertz")
        _put(fg, "sceneCenterAlongTrackSpacing", ds_az, "Nominal along-track spacing in meters between "
             "consecutive lines near mid swath of the RSLC image", "meters")
        _put(fg, "sceneCenterGroundRangeSpacing", ds_gr, "Nominal ground range spacing in meters between "
             "consecutive pixels near mid swath of the RSLC image", "meters")
        _put(fg, "numberOfSubSwaths", 1, "Number of swaths of continuous imagery, due to transmit gaps", "1",
             np.uint8)
        _put(fg, "validSamplesSubSwath1", np.tile(np.array([0, m], np.uint32), (n, 1)),
             "First and last valid sample in each line of 1st subswath", "1", np.uint32)
        md = group(prod, "metadata")
        _write_orbit(md, sv_file, units)
        if slc.attitude is not None and np.size(slc.attitude.time):
            _write_attitude(md, slc, sv, sv_file, frac, units, h)
        _write_processing(md, slc, meta, frac, units, [*meta.input_names])
        _write_geolocation_grid(md, sv_file, t, r, lam, slc.look_side, units)
        if slc.calibration is not None:
            _write_calibration(md, slc.calibration, frac, units, meta.frequency, list(images))
        _write_identification(sci, slc, sv_file, t, r, meta, band_letter, epoch, h)


def _shifted(slc: SLC, frac: float, epoch: str) -> SLC:
    """The SLC's axes on the whole-second epoch (a shallow view: the image is not copied)."""
    import dataclasses

    return dataclasses.replace(slc, azimuth_time=slc.azimuth_time + frac, epoch_utc=epoch)


def _write_orbit(md: h5py.Group, sv: StateVectors, units: str) -> None:
    og = group(md, "orbit")
    _, _, acc = sv.interpolate(sv.time)
    _put(og, "time", sv.time, "Time vector record of the position and velocity records", units)
    _put(og, "position", sv.position, "Position vector record (ECEF, WGS-84)", "meters")
    _put(og, "velocity", sv.velocity, "Velocity vector record (ECEF, WGS-84)", "meters per second")
    _put(og, "acceleration", acc, "Acceleration of the Hermite interpolant at the records (ECEF)",
         "meters per second squared")
    _put(og, "orbitType", "Custom", 'Orbit product type ("FOE", "NOE", "MOE", "POE" or "Custom")')
    _put(og, "interpMethod", "Hermite", 'Orbit interpolation method, either "Hermite" or "Legendre"')


def _write_attitude(md: h5py.Group, slc: SLC, sv: StateVectors, sv_file: StateVectors, frac: float, units: str,
                    h: float) -> None:
    """Quaternions of the model attitude with the boresight at the mid-swath look angle (the model has
    no beam elevation; see .attitude)."""
    from orbit.geometry import look_angle

    a = slc.attitude
    inside = (a.time >= sv.span[0]) & (a.time <= sv.span[1])
    if not np.any(inside):
        return
    from sarcli.model.raw import Attitude

    att = Attitude(a.time[inside], a.pitch[inside], a.roll[inside], a.yaw[inside])
    tm = float(slc.azimuth_time[slc.azimuth_time.size // 2])
    rm = float(slc.slant_range[slc.slant_range.size // 2])
    p = _geolocate(sv, np.array([tm]), np.array([rm]), np.array([h]), slc.radar.wavelength_m, slc.look_side)
    pos, _, _ = sv.interpolate(np.array([tm]))
    look = float(look_angle(pos, p)[0])
    q = quaternions_from_model(att, sv, slc.look_side, look)
    ag = group(md, "attitude")
    _put(ag, "time", att.time + frac, "Time vector record of the attitude and quaternion records", units)
    _put(ag, "quaternions", q, "Attitude quaternions (q0, q1, q2, q3): antenna (RCS) to ECEF rotation, "
         f"boresight at the mid-swath look angle {np.degrees(look):.4f} deg", "1")
    _put(ag, "attitudeType", "Custom", 'Attitude type ("FRP", "NRP", "PRP" or "Custom")')


def _write_weighting(g: h5py.Group, name: str, w: Weighting | None, what: str) -> None:
    if w is None:
        return
    v = np.asarray(w.values, np.float32).reshape(-1)
    ds = _put(g, name, v, f"1-D array in frequency domain for {what} processing (fftshifted order over the "
              "sampling band)", "1")
    if w.name:
        ds.attrs["window_name"] = np.bytes_(w.name)
        ds.attrs["window_shape"] = float(w.shape)


def _write_processing(md: h5py.Group, slc: SLC, meta: RslcMeta, frac: float, units: str, names: list[str]) -> None:
    pi = group(md, "processingInformation")
    par = group(pi, "parameters")
    y, x, lut = _doppler_lut(slc, frac)
    fq = group(par, f"frequency{meta.frequency}")
    for g in (fq, par):
        _put(g, "zeroDopplerTime", y, "Zero doppler time dimension corresponding to processing information "
             "records", units)
        _put(g, "slantRange", x, "Slant range dimension corresponding to processing information records", "meters")
    _put(fq, "dopplerCentroid", lut, f"2D LUT of Doppler centroid for frequency {meta.frequency} (the centroid "
         "used by the focuser)", "hertz")
    _write_weighting(par, "rangeChirpWeighting", meta.range_weighting, "range")
    _write_weighting(par, "azimuthChirpWeighting", meta.azimuth_weighting, "azimuth")
    _put(par, "referenceTerrainHeight", np.full(y.size, meta.terrain_height_m, np.float32),
         "Reference terrain height as a function of time", "meters")
    _put(par, "runConfigurationContents", json.dumps(to_jsonable(dict(slc.parameters)), sort_keys=True),
         "sarcli processing parameters (JSON)")
    alg = group(pi, "algorithms")
    algorithms = {"softwareVersion": f"sarcli {__version__}", "rangeCompression": "matched filter (FFT)",
                  "azimuthCompression": slc.algorithm, "dopplerCentroidEstimation": "sarcli doppler",
                  "azimuthPresumming": "none", "rfiDetection": "disabled", "rfiMitigation": "disabled",
                  "elevationAntennaPatternCorrection": "disabled", "rangeSpreadingLossCorrection": "disabled",
                  "demInterpolation": "none (constant height)", **meta.algorithms}
    for k, v in algorithms.items():
        _put(alg, k, v, "Algorithm or software used for this processing step")
    inp = group(pi, "inputs")
    _put(inp, "l0bGranules", names or [""], "List of input products used")
    for k in ("orbitFiles", "attitudeFiles", "auxcalFiles", "configFiles"):
        _put(inp, k, [""], f"List of input {k[:-5]} files used")
    _put(inp, "demSource", "", "Description of the input digital elevation model (DEM)")


def _write_calibration(md: h5py.Group, cal, frac: float, units: str, frequency: str, pols: list[str]) -> None:
    """metadata/calibrationInformation: the SLC's radiometric LUTs (:class:`sarcli.model.slc.Calibration`) in
    the RSLC layout: geometry/{beta0, sigma0, gamma0} on (zeroDopplerTime, slantRange), multiplicative
    (X = |DN|^2 * X), NaN where not calibrated; frequencyX/{pol}/nes0 the noise-equivalent sigma0 (linear)."""
    ci = group(md, "calibrationInformation")
    geo = group(ci, "geometry")
    _put(geo, "zeroDopplerTime", cal.azimuth_time + frac, "Zero doppler time dimension of the calibration LUTs",
         units)
    _put(geo, "slantRange", cal.slant_range, "Slant range dimension of the calibration LUTs", "meters")
    for name, what in (("beta0", "beta0"), ("sigma0", "sigma0 (ellipsoid incidence)"),
                       ("gamma0", "gamma0 (ellipsoid incidence)")):
        _put(geo, name, np.asarray(getattr(cal, name), np.float32), f"2D LUT to convert |DN|^2 to {what}: "
             f"{name} = |DN|^2 * LUT (sarcli radiometric model; not applied: "
             f"{'; '.join(cal.not_applied) or 'none'})", "1")
    fq = group(ci, f"frequency{frequency}")
    for pol in pols:
        pg = group(fq, pol)
        _put(pg, "nes0", np.asarray(cal.nes0, np.float32), "Noise equivalent sigma0 (linear) on the calibration "
             "LUT grid", "1")
    _put(ci, "absoluteCalibrationConstant", float(cal.constant), "sarcli's absolute calibration constant K "
         "(|DN|^2 = K F beta0)", "1")


def _write_geolocation_grid(md: h5py.Group, sv: StateVectors, t: np.ndarray, r: np.ndarray, lam: float, side: str,
                            units: str) -> None:
    span = sv.span
    v = float(np.linalg.norm(sv.interpolate(np.array([t[t.size // 2]]))[1]))
    tg = _grid_axis(float(t[0]), float(t[-1]), GRID_POSTING_M / v, span[0], span[1])
    rg = _grid_axis(float(r[0]), float(r[-1]), GRID_POSTING_M, 0.0, np.inf)
    cubes = geolocation_cubes(sv, tg, rg, GRID_HEIGHTS_M, lam, side)
    gg = group(md, "geolocationGrid")
    _put(gg, "zeroDopplerTime", tg, "Zero Doppler time values corresponding to the geolocation grid", units)
    _put(gg, "slantRange", rg, "Slant range values corresponding to the geolocation grid", "meters")
    _put(gg, "heightAboveEllipsoid", GRID_HEIGHTS_M, "Height values above WGS84 Ellipsoid corresponding to the "
         "location grid", "meters")
    _put(gg, "epsg", 4326, "EPSG code corresponding to coordinate system used for representing geolocation grid",
         None, np.int32)
    desc = {"coordinateX": ("Longitude (EPSG 4326)", "degree_east"),
            "coordinateY": ("Latitude (EPSG 4326)", "degree_north"),
            "incidenceAngle": ("Angle between the LOS vector and the normal to the ellipsoid at the target", "degrees"),
            "elevationAngle": ("Angle between the LOS vector and the normal to the ellipsoid at the sensor", "degrees"),
            "losUnitVectorX": ("East component of unit vector of LOS from target to sensor", "1"),
            "losUnitVectorY": ("North component of unit vector of LOS from target to sensor", "1"),
            "alongTrackUnitVectorX": ("East component of unit vector along ground track", "1"),
            "alongTrackUnitVectorY": ("North component of unit vector along ground track", "1"),
            "groundTrackVelocity": ("Platform velocity scaled to the target's geocentric radius", "meters / second")}
    for k, (d, u) in desc.items():
        dt = np.float64 if k in ("coordinateX", "coordinateY", "groundTrackVelocity") else np.float32
        _put(gg, k, cubes[k].astype(dt), d, u)


def _iso9(epoch: str, seconds: float) -> str:
    """ISO-8601 with nine fraction digits, no zone (ISCE3's DateTime spelling)."""
    from orbit.timeutil import add_seconds

    whole = np.floor(seconds)
    s = add_seconds(epoch, float(whole)).replace("Z", "")
    return s.split(".")[0] + f".{int(round((seconds - whole) * 1e9)):09d}"


def _write_identification(sci: h5py.Group, slc: SLC, sv: StateVectors, t: np.ndarray, r: np.ndarray,
                          meta: RslcMeta, band_letter: str, epoch: str, h: float) -> None:
    _, v, _ = sv.interpolate(np.array([t[t.size // 2]]))
    ident = group(sci, "identification")
    items = {
        "productType": ("RSLC", "Product type"), "productLevel": ("L1", "Product level"),
        "missionId": (meta.mission_id, "Mission identifier"),
        "instrumentName": (meta.instrument, "Name of the instrument used to collect the data"),
        "radarBand": (band_letter, "Acquired frequency band"),
        "lookDirection": (slc.look_side.capitalize(), 'Look direction, either "Left" or "Right"'),
        "orbitPassDirection": ("Ascending" if v[0, 2] > 0 else "Descending",
                               'Orbit direction, either "Ascending" or "Descending"'),
        "zeroDopplerStartTime": (_iso9(epoch, float(t[0])), "Azimuth start time of the product"),
        "zeroDopplerEndTime": (_iso9(epoch, float(t[-1])), "Azimuth stop time of the product"),
        "boundingPolygon": (_wkt_polygon(sv, t, r, slc.radar.wavelength_m, slc.look_side, h),
                            "OGR compatible WKT representation of bounding polygon of the image"),
        "isGeocoded": ("False", "Flag to indicate radar geometry or map geometry"),
        "isUrgentObservation": ("False", "Flag indicating if observation is nominal or urgent"),
        "isDithered": ("False", '"True" if the pulse timing was varied (dithered) during acquisition'),
        "isMixedMode": ("False", '"True" if this product is a composite of data collected in multiple modes'),
        "processingType": ("CUSTOM", "NOMINAL (or) URGENT (or) CUSTOM (or) UNDEFINED"),
        "processingCenter": ("sarcli", "Data processing center"),
        "processingDateTime": (created_utc()[:19], "Processing UTC date and time in the format YYYY-MM-DDTHH:MM:SS"),
        "productVersion": (__version__, "Product version (sarcli version)"),
        "granuleId": ("None", "Unique granule identification name"),
    }
    for k, (val, d) in items.items():
        ds = _put(ident, k, val, d)
        if k == "boundingPolygon":
            ds.attrs["epsg"] = 4326
            ds.attrs["ogr_geometry"] = np.bytes_("polygon")
    _put(ident, "listOfFrequencies", [meta.frequency], "List of frequency layers available in the product")
    _put(ident, "plannedDatatakeId", ["0"], "List of planned datatakes included in the product")
    _put(ident, "plannedObservationId", ["0"], "List of planned observations included in the product")
    _put(ident, "absoluteOrbitNumber", 0, "Absolute orbit number", None, np.uint32)
    _put(ident, "trackNumber", 0, "Track number", "1", np.uint8)
    _put(ident, "frameNumber", 0, "Frame number", "1", np.uint16)
    _put(ident, "diagnosticModeFlag", 0, "Radar operation mode: DBFed science (0)", None, np.uint8)


# ----------------------------------------------------------------------------------------------- reading


@dataclass
class RslcContents:
    """Frequencies -> polarizations of an RSLC and its image shape (for ``info`` and for choosing)."""

    band: str
    frequencies: dict[str, list[str]]
    shape: tuple[int, int]
    mission_id: str
    written_by_sarcli: bool


def _frequencies(sw: h5py.Group, ident: h5py.Group | None) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for name in member_names(sw):
        if not (name.startswith("frequency") and len(name) == 10 and isinstance(sw[name], h5py.Group)):
            continue
        fg = sw[name]
        pols = [p.upper() for p in text_list(fg["listOfPolarizations"])] if "listOfPolarizations" in fg else []
        pols = [p for p in pols if p in fg] or [p for p in POLARIZATIONS if p in fg]
        out[name[-1]] = pols
    return out


def rslc_contents(path: str | os.PathLike) -> RslcContents:
    """What an RSLC file holds (one line on a bad file)."""
    path = Path(path)
    with open_h5(path) as f:
        band, sci, pname = band_root(f, path, ("RSLC", "SLC"))
        sw = need(sci[pname], "swaths", path, "group")
        ident = sci.get("identification") if isinstance(sci.get("identification"), h5py.Group) else None
        freqs = _frequencies(sw, ident)
        if not freqs or not any(freqs.values()):
            raise FormatError(f"{path}: incomplete NISAR RSLC: no frequency group with an image under {sw.name}")
        fa, pols = next((k, v) for k, v in freqs.items() if v)
        return RslcContents(band, freqs, tuple(sw[f"frequency{fa}"][pols[0]].shape),
                            optional_text(ident, "missionId") if ident is not None else "",
                            text(f.attrs.get("product_type", b"")) == PRODUCT_TYPE)


def _lut2d(par: h5py.Group, fq: h5py.Group, name: str, path: Path, epoch: str,
           r: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(zero-Doppler times after ``epoch``, values interpolated to the slant ranges r) of a LUT2d, the
    axes next to it or one level up (older RSLCs); None when absent or inconsistent."""
    if not isinstance(fq.get(name), h5py.Dataset):
        return None
    for g in (fq, par):
        if isinstance(g.get("zeroDopplerTime"), h5py.Dataset) and isinstance(g.get("slantRange"), h5py.Dataset):
            e, y = time_axis(g["zeroDopplerTime"], path)
            x = np.asarray(g["slantRange"][()], np.float64).reshape(-1)
            z = np.asarray(fq[name][()], np.float64)
            if z.shape != (y.size, x.size) or x.size < 1 or not np.all(np.diff(x) > 0):
                return None
            y = y + seconds_between(e, epoch)
            return y, np.array([np.interp(r, x, row) for row in z])
    return None


def _radar(f: h5py.File, fg: h5py.Group, r: np.ndarray, path: Path) -> Radar:
    if text(f.attrs.get("product_type", b"")) == PRODUCT_TYPE and "sarcli_radar" in f.attrs:
        kw = json.loads(text(f.attrs["sarcli_radar"]))
        kw["receiver_offsets_m"] = tuple(kw.get("receiver_offsets_m", (0.0,)))
        optional = {fl.name for fl in dataclasses.fields(Radar) if fl.default is None}
        kw = {k: (np.nan if v is None and k not in optional else v) for k, v in kw.items()}
        return Radar(**kw)
    fc_name = "processedCenterFrequency" if "processedCenterFrequency" in fg else "acquiredCenterFrequency"
    fc = number(fg, fc_name, path, positive=True)
    dr = float(r[1] - r[0])
    prf = number(fg, "nominalAcquisitionPRF", path, positive=True) if "nominalAcquisitionPRF" in fg else np.nan
    return Radar(carrier_frequency_hz=fc, wavelength_m=C_LIGHT / fc, prf_hz=prf,
                 range_sampling_rate_hz=C_LIGHT / (2 * dr), chirp_rate_hz_per_s=np.nan, pulse_length_s=np.nan,
                 window_start_s=2 * float(r[0]) / C_LIGHT, first_range_m=float(r[0]))


def _weighting(par: h5py.Group, name: str) -> dict[str, Any] | None:
    ds = par.get(name)
    if not isinstance(ds, h5py.Dataset) or ds.ndim != 1 or ds.size < 8:
        return None  # absent, or not a 1-D spectral weighting (early products stored a LUT here)
    v = np.asarray(ds[()], np.float64)
    if not np.all(np.isfinite(v)) or not np.any(v > 0):
        return None
    out: dict[str, Any] = {"values": v.tolist()}
    if "window_name" in ds.attrs:
        out["name"] = text(ds.attrs["window_name"])
        out["shape"] = float(np.asarray(ds.attrs.get("window_shape", np.nan)))
    return out


def read_rslc(path: str | os.PathLike, frequency: str | None = None, polarization: str | None = None,
              load_image: bool = True) -> SLC:
    """An RSLC (sarcli's or ISCE3's) as a sarcli :class:`SLC` (module docstring).

    ``frequency`` (default: the first with an image), ``polarization`` (default HH if present, else the
    first). Fields an RSLC does not hold are NaN (chirp rate, pulse length, Doppler rate unless the file
    has azimuthFMRate). The processed bandwidths and spectral weightings go to ``parameters["nisar"]``
    (``sarcli.calibration`` derives the theoretical resolution from them).
    """
    path = Path(path)
    with open_h5(path) as f:
        band, sci, pname = band_root(f, path, ("RSLC", "SLC"))
        prod = sci[pname]
        ident = sci.get("identification") if isinstance(sci.get("identification"), h5py.Group) else None
        sw = need(prod, "swaths", path, "group")
        freqs = _frequencies(sw, ident)
        if frequency is None:
            frequency = next((k for k, v in freqs.items() if v), None)
            if frequency is None:
                raise FormatError(f"{path}: incomplete NISAR RSLC: no frequency group with an image under {sw.name}")
        if frequency not in freqs:
            raise ConfigError(f"{path}: no frequency {frequency}; the file has {', '.join(freqs) or 'none'}")
        pols = freqs[frequency]
        if polarization is None:
            if not pols:
                raise FormatError(f"{path}: frequency{frequency} holds no image")
            polarization = "HH" if "HH" in pols else pols[0]
        if polarization not in pols:
            raise ConfigError(f"{path}: frequency {frequency} has polarizations {', '.join(pols) or 'none'}, "
                              f"not {polarization}")
        fg = sw[f"frequency{frequency}"]
        tname = "zeroDopplerTime" if "zeroDopplerTime" in sw else None
        if tname is None:
            raise FormatError(f"{path}: incomplete NISAR RSLC: {sw.name}/zeroDopplerTime missing")
        epoch, t = time_axis(sw[tname], path)
        r = np.asarray(need(fg, "slantRange", path)[()], np.float64).reshape(-1)
        img = need(fg, polarization, path)
        if img.ndim != 2 or img.shape != (t.size, r.size):
            raise FormatError(f"{path}: {img.name} has shape {img.shape}, axes say ({t.size}, {r.size})")
        if t.size < 2 or r.size < 2 or not np.all(np.diff(t) > 0) or not np.all(np.diff(r) > 0):
            raise FormatError(f"{path}: zeroDopplerTime and slantRange must be increasing with 2+ values")
        image = complex_rows(img, 0, t.size) if load_image else np.zeros((t.size, 0), np.complex64)
        if load_image and not np.all(np.isfinite(image.view(np.float32))):
            raise FormatError(f"{path}: {img.name} holds NaN or inf pixels")
        radar = _radar(f, fg, r, path)
        side = text(ident["lookDirection"]).lower() if ident is not None and "lookDirection" in ident else ""
        if side not in ("right", "left"):
            raise FormatError(f"{path}: identification/lookDirection missing or not Right/Left")
        md = prod.get("metadata") if isinstance(prod.get("metadata"), h5py.Group) else None
        orbit, sv = _read_orbit(md, path, epoch)
        attitude, notes = None, []
        if md is not None and isinstance(md.get("attitude"), h5py.Group) and sv is not None:
            ag = md["attitude"]
            try:
                a_epoch, ta = time_axis(need(ag, "time", path), path)
                ta = ta + seconds_between(a_epoch, epoch)
                q = np.asarray(need(ag, "quaternions", path)[()], np.float64)
                keep = (ta >= sv.span[0]) & (ta <= sv.span[1])
                if q.shape == (ta.size, 4) and np.any(keep):
                    attitude = model_attitude(ta[keep], q[keep], sv, side, where=f"{path}: {ag.name}")
            except FormatError as e:
                notes.append(f"attitude not used: {e}")
        par = md.get("processingInformation/parameters") if md is not None else None
        dop, nisar = _read_parameters(par, frequency, path, epoch, t, r)
        nisar.update({"file": path.name, "band": band, "frequency": frequency, "polarization": polarization,
                      "polarizations": pols, "notes": notes,
                      "mission_id": optional_text(ident, "missionId") if ident is not None else ""})
        for key, name in (("processed_range_bandwidth_hz", "processedRangeBandwidth"),
                          ("processed_azimuth_bandwidth_hz", "processedAzimuthBandwidth"),
                          ("acquired_range_bandwidth_hz", "acquiredRangeBandwidth")):
            if name in fg:
                nisar[key] = number(fg, name, path, positive=True)
        ours = text(f.attrs.get("product_type", b"")) == PRODUCT_TYPE
        params: dict[str, Any] = {}
        if ours and par is not None and "runConfigurationContents" in par:
            try:
                params = json.loads(text(par["runConfigurationContents"]))
            except json.JSONDecodeError:
                params = {}
        params["nisar"] = nisar
        spacing = number(fg, "sceneCenterAlongTrackSpacing", path, positive=True) \
            if "sceneCenterAlongTrackSpacing" in fg else np.nan
        alg = text(f.attrs["algorithm"]) if ours and "algorithm" in f.attrs else (
            optional_text(md["processingInformation/algorithms"], "azimuthCompression", "unknown")
            if md is not None and isinstance(md.get("processingInformation/algorithms"), h5py.Group) else "unknown")
        first = int(f.attrs["first_full_line"]) if ours and "first_full_line" in f.attrs else 0
        last = int(f.attrs["last_full_line"]) if ours and "last_full_line" in f.attrs else t.size - 1
        source = text(f.attrs["source"]) if ours and "source" in f.attrs else \
            f"nisar-rslc ({nisar['mission_id'] or 'unknown mission'})"
        return SLC(image=image, azimuth_time=t, slant_range=r, epoch_utc=epoch, radar=radar, doppler=dop,
                   look_side=side, source=source, algorithm=alg or "unknown", azimuth_spacing_m=spacing,
                   first_full_line=first, last_full_line=last, parameters=params, orbit=orbit, attitude=attitude)


def _read_orbit(md: h5py.Group | None, path: Path, epoch: str) -> tuple[Orbit | None, StateVectors | None]:
    if md is None or not isinstance(md.get("orbit"), h5py.Group):
        return None, None
    og = md["orbit"]
    e, t = time_axis(need(og, "time", path), path)
    t = t + seconds_between(e, epoch)
    pos = np.asarray(need(og, "position", path)[()], np.float64)
    vel = np.asarray(need(og, "velocity", path)[()], np.float64)
    try:
        sv = StateVectors(t, pos, vel, "ECEF", epoch)
    except OrbitError as err:
        raise FormatError(f"{path}: {og.name}: {err}") from None
    return Orbit(t, pos, vel, "ECEF"), sv


def _read_parameters(par: h5py.Group | None, frequency: str, path: Path, epoch: str, t: np.ndarray,
                     r: np.ndarray) -> tuple[DopplerUsed, dict[str, Any]]:
    """Doppler (block_time = the LUT's zero-Doppler times) and the weightings."""
    nan_rows = np.full((1, r.size), np.nan)
    dop = DopplerUsed(np.array([0.5 * (t[0] + t[-1])]), r.copy(), nan_rows, nan_rows.copy(), nan_rows.copy())
    nisar: dict[str, Any] = {}
    if par is None:
        return dop, nisar
    fq = par.get(f"frequency{frequency}")
    if isinstance(fq, h5py.Group):
        found = _lut2d(par, fq, "dopplerCentroid", path, epoch, r)
        if found is not None:
            y, fdc = found
            fr = _lut2d(par, fq, "azimuthFMRate", path, epoch, r)
            vel = _lut2d(par, par, "effectiveVelocity", path, epoch, r)
            def same(x):
                return x is not None and x[1].shape == fdc.shape

            dop = DopplerUsed(y, r.copy(), fdc, fr[1] if same(fr) else np.full(fdc.shape, np.nan),
                              vel[1] if same(vel) else np.full(fdc.shape, np.nan))
    for key, name in (("range_weighting", "rangeChirpWeighting"), ("azimuth_weighting", "azimuthChirpWeighting")):
        w = _weighting(par, name)
        if w is not None:
            nisar[key] = w
    if isinstance(par.get("referenceTerrainHeight"), h5py.Dataset):
        hgt = np.asarray(par["referenceTerrainHeight"][()], np.float64).reshape(-1)
        if hgt.size and np.all(np.isfinite(hgt)):
            nisar["terrain_height_m"] = float(np.mean(hgt))
    return dop, nisar


def read_image(path: str | os.PathLike, frequency: str | None = None, polarization: str | None = None) -> SLC:
    """A focused image as an :class:`SLC`: a NISAR RSLC (sarcli's or ISCE3's; ``frequency`` and
    ``polarization`` choose the layer) or a sarcli ``slc`` product (which has one layer)."""
    from sarcli.io.slc import read_slc

    if sniff_rslc(path):
        return read_rslc(path, frequency, polarization)
    if frequency is not None or polarization is not None:
        if not Path(path).exists():
            raise ProductError(f"{path}: no such file")
        raise ConfigError(f"{path}: a sarcli SLC product has one image: --frequency/--polarization apply to NISAR "
                          "RSLC files only")
    return read_slc(path)
