"""The GB-SAR scan product (``product_type = "gbsar_scan"``), schema versions 1 and 2.

One schema for simulated scans (``sarcli gbsar simulate``) and measured ones (``sarcli gbsar scan``).
Measured scans are written stop by stop: the stop axis is resizable and every completed stop is
flushed before the rail moves on, so an interrupted acquisition keeps every line it measured and
the file stays valid (``n_complete`` counts the valid stops).

Layout (SI units)::

    /                  provenance attributes, epoch_utc, polarizations (comma list, e.g. "VV,HH"),
                       n_planned (planned stops), n_complete (stops written), status
                       ("complete" | "interrupted" | "simulated"), source ("simulated" | "measured")
    /s21               complex64 (n_pol, n_stops, n_freq): S21 per polarization, rail stop, frequency
    /frequency         float64 (n_freq,) Hz, increasing
    /rail_position     float64 (n_stops,) m along the rail (x), increasing
    /rail_height       float64 (n_stops,) m, antenna phase-centre height above the reference (z)
    /stop_time         float64 (n_stops,) s after epoch_utc (start of the stop's sweeps)
    /stop_flags        uint8 (n_stops,) 0 = good, 1 = NaN/invalid sweep (skipped by focusing)
    /antenna           attributes: length_azimuth_m (L_x), length_range_m (L_R), beamwidth_rad,
                       gain_dbi
    /site              attributes: latitude_deg, longitude_deg, height_m (rail centre, WGS-84),
                       heading_deg (direction of increasing rail position, clockwise from north),
                       look_side ("right" | "left" of the rail direction)
    /instrument        attributes: settings as applied (if_bandwidth_hz, power_dbm, points, vna_idn,
                       rail_idn, settle_s, ...), free-form but JSON-serializable scalars
    /truth             optional, simulated scans: scene_toml attribute and target tables
    /antenna_position  optional (schema 2), float64 (n_stops, 3) m: antenna phase centre (x, y, z) of
                       every sweep in a local Cartesian frame (a 3-D track, e.g. an airborne phase
                       history); rail_position is then the distance along the track, rail_height its z
    /reference_range   optional (schema 2), float64 (n_stops,) m: the range r_ref each sweep's phase is
                       referenced to (de-ramped / motion-compensated phase histories, e.g. to a scene
                       centre)

Phase convention: a scatterer at one-way range R from the antenna phase centre gives
S21 ∝ exp(-j*4*pi*f*R/c), or S21 ∝ exp(-j*4*pi*f*(R - r_ref)/c) with a reference range.
A scan without the two optional datasets is written as schema 1, exactly as before they existed
(an older reader still reads it); one with either is schema 2, which an older reader refuses
instead of focusing it as a straight rail.
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any

import h5py
import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import (
    atomic_h5,
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
    write_mapping,
)
from sarcli.model.gbsar import POLARIZATIONS, Antenna, Scan, Site

PRODUCT_TYPE = "gbsar_scan"
SCHEMA_VERSION = "1"
SCHEMA_VERSION_TRACK = "2"  # with antenna_position and/or reference_range
__all__ = ["POLARIZATIONS", "PRODUCT_TYPE", "ScanWriter", "read_attr_group", "read_scan", "write_scan"]


_DESCRIPTIONS = {"s21": "S21 per polarization, rail stop, frequency",
                 "rail_height": "antenna phase-centre height above the reference (z)",
                 "stop_time": "start of each stop's sweeps",
                 "stop_flags": "0 good, 1 invalid sweep (skipped by focusing)"}


def _write_static(f: h5py.File, s: Scan) -> tuple[h5py.Dataset, h5py.Dataset]:
    """Root attributes, groups and the fixed axes; returns the (polarization, frequency) coordinates."""
    f.attrs["epoch_utc"] = s.epoch_utc
    f.attrs["polarizations"] = ",".join(s.polarizations)
    f.attrs["source"] = s.source
    freq = coordinate(f, "frequency", np.asarray(s.frequency, np.float64), "Hz", "sweep frequency")
    pol = coordinate(f, "polarization", np.array([p.encode() for p in s.polarizations]), "1",
                     "transmit-receive polarization")
    for name, obj in (("site", s.site), ("antenna", s.antenna)):
        g = group(f, name)
        for k, v in vars(obj).items():
            g.attrs[k] = v
    g = group(f, "instrument")
    for k, v in sorted(s.instrument.items()):
        g.attrs[k] = v
    if s.truth is not None:
        write_mapping(f, "truth", s.truth, s.epoch_utc)
    return pol, freq


def _stop_axes(f: h5py.File, s: Scan | None, n: int, pol: h5py.Dataset, freq: h5py.Dataset,
               resizable: bool) -> None:
    """/rail_position (the stop axis' coordinate), /s21 and the per-stop datasets (empty and
    resizable for a scan measured stop by stop)."""
    epoch = attr_str(f, "epoch_utc")
    tunits = cf_time_units(epoch) if epoch else "s"
    grow = {"chunks": (256,), "maxshape": (None,)} if resizable else {}
    zero = np.zeros(0)
    rp = coordinate(f, "rail_position", zero if s is None else np.asarray(s.rail_position, np.float64), "m",
                    "along-rail position of each stop (x)", **grow)
    n_pol, n_freq = pol.shape[0], freq.shape[0]
    s21 = np.zeros((n_pol, 0, n_freq), np.complex64) if s is None else np.asarray(s.s21, np.complex64)
    dataset(f, "s21", s21, units="1", description=_DESCRIPTIONS["s21"], dims=(pol, rp, freq),
            **({"chunks": (n_pol, 1, n_freq), "maxshape": (n_pol, None, n_freq)} if resizable else {}))
    st = np.zeros(n) if s is None or s.stop_time is None else s.stop_time
    fl = np.zeros(n, np.uint8) if s is None or s.stop_flags is None else s.stop_flags
    for name, arr, dt, unit in (("rail_height", zero if s is None else s.rail_height, np.float64, "m"),
                                ("stop_time", st, np.float64, tunits), ("stop_flags", fl, np.uint8, "1")):
        dataset(f, name, np.asarray(arr, dt), units=unit, description=_DESCRIPTIONS[name], dims=(rp,), **grow)
    if s is not None and s.antenna_position is not None:
        xyz = coordinate(f, "xyz", np.array([b"x", b"y", b"z"]), "1", "Cartesian component")
        dataset(f, "antenna_position", np.asarray(s.antenna_position, np.float64), units="m",
                description="antenna phase centre (x, y, z) of each sweep, local Cartesian frame", dims=(rp, xyz))
    if s is not None and s.reference_range is not None:
        dataset(f, "reference_range", np.asarray(s.reference_range, np.float64), units="m",
                description="range each sweep's phase is referenced to", dims=(rp,))


def write_scan(path: str | os.PathLike, s: Scan, parameters: dict | None = None, inputs: tuple = ()) -> None:
    """Validate (:meth:`Scan.validate`) and write a complete scan atomically."""
    s.validate(str(path))
    n_stops = s.n_stops
    version = SCHEMA_VERSION if s.is_rail else SCHEMA_VERSION_TRACK
    with atomic_h5(path, PRODUCT_TYPE, version, parameters, inputs) as f:
        pol, freq = _write_static(f, s)
        f.attrs["n_planned"] = s.n_planned if s.n_planned is not None else n_stops
        f.attrs["n_complete"] = n_stops
        f.attrs["status"] = s.status
        _stop_axes(f, s, n_stops, pol, freq, resizable=False)


def read_attr_group(f: h5py.Group, name: str, cls: type) -> Any:
    """A dataclass (:class:`Site`, :class:`Antenna`) from a group's attributes: unknown attributes are
    refused, text checked as UTF-8, numbers as finite scalars (the dataclass's ``validate`` checks the
    values); a missing group gives the defaults."""
    if name not in f:
        return cls()
    g = f[name]
    if not isinstance(g, h5py.Group):
        raise ProductError(f"{f.file.filename}: malformed product, '{name}' is not a group")
    fields = {fl.name: fl.type for fl in dataclasses.fields(cls)}
    kw: dict[str, Any] = {}
    for k in g.attrs:
        if k not in fields:
            raise ProductError(f"{f.file.filename}: {name} has an unknown attribute '{k}'")
        kw[k] = attr_str(g, k) if fields[k] in (str, "str") else attr_number(g, k)
    return cls(**kw)


def _instrument(f: h5py.Group) -> dict[str, Any]:
    """Instrument settings: free-form scalars (text or numbers)."""
    if "instrument" not in f:
        return {}
    g = f["instrument"]
    out: dict[str, Any] = {}
    for k in g.attrs:
        v = g.attrs[k]
        if isinstance(v, str | bytes | np.bytes_):
            out[k] = attr_str(g, k)
        elif isinstance(v, np.bool_ | bool):
            out[k] = bool(v)
        else:
            out[k] = attr_number(g, k, integer=isinstance(v, np.integer | int))
    return out


def read_scan(path: str | os.PathLike, min_usable_stops: int = 0) -> Scan:
    """Read a scan (its ``n_complete`` valid stops) and validate it (:meth:`Scan.validate`); a malformed
    or implausible file raises ProductError (one line). Focusing needs ``min_usable_stops=2``; an
    interrupted acquisition may hold fewer and is still a valid file."""
    with open_product(path, PRODUCT_TYPE) as f:
        version = attr_str(f, "schema_version")
        if version not in (SCHEMA_VERSION, SCHEMA_VERSION_TRACK):
            raise ProductError(f"{path}: unsupported gbsar_scan schema version {version}")
        s21_ds = require(f, "s21", path, shape_rank=3, dtype_kind="c")
        n = attr_number(f, "n_complete", lo=0, hi=s21_ds.shape[1], integer=True)
        per_stop = {}
        for name, kind in (("rail_position", "f"), ("rail_height", "f"), ("stop_time", "f"), ("stop_flags", "iu")):
            a = read_array(f, name, kind, ndim=1, finite=False)
            if a.shape[0] < n:
                raise ProductError(f"{path}: {name} has {a.shape[0]} value(s) for {n} complete stops")
            per_stop[name] = a[:n]
        if version == SCHEMA_VERSION_TRACK:
            for name, ndim in (("antenna_position", 2), ("reference_range", 1)):
                if name in f:
                    a = read_array(f, name, "f", ndim=ndim, finite=False)
                    if a.shape[0] < n:
                        raise ProductError(f"{path}: {name} has {a.shape[0]} value(s) for {n} complete stops")
                    per_stop[name] = a[:n]
        pols = tuple(p for p in (attr_str(f, "polarizations") or "").split(",") if p)
        s = Scan(
            s21=s21_ds[:, :n, :], frequency=read_array(f, "frequency", "f", ndim=1, finite=False),
            polarizations=pols, epoch_utc=attr_str(f, "epoch_utc") or "",
            site=read_attr_group(f, "site", Site), antenna=read_attr_group(f, "antenna", Antenna),
            instrument=_instrument(f), truth=read_mapping(f["truth"]) if "truth" in f else None,
            source=attr_str(f, "source", "unknown"), status=attr_str(f, "status", "unknown"),
            n_planned=attr_number(f, "n_planned", n, lo=0, integer=True), **per_stop,
        )
    s.validate(str(path), min_usable_stops)
    return s


class ScanWriter:
    """Append stops to a scan file as they are measured; each stop is flushed before returning.

    The file is created (atomically: it appears complete with zero stops) by :meth:`create` or
    reopened for ``--resume`` by :meth:`resume`. ``n_complete`` is updated after the stop's data
    are written and flushed, so a crash between the two leaves the previous count valid.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = str(path)
        self.f = h5py.File(self.path, "r+")
        self.n_complete = int(self.f.attrs["n_complete"])

    @classmethod
    def create(cls, path: str | os.PathLike, template: Scan, n_planned: int,
               parameters: dict | None = None) -> ScanWriter:
        """Create an empty, valid scan file for ``n_planned`` stops (template gives frequency, pols...)."""
        with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, parameters) as f:
            pol, freq = _write_static(f, template)
            f.attrs["n_planned"] = n_planned
            f.attrs["n_complete"] = 0
            f.attrs["status"] = "interrupted"
            _stop_axes(f, None, 0, pol, freq, resizable=True)
        return cls(path)

    @classmethod
    def resume(cls, path: str | os.PathLike) -> ScanWriter:
        """Reopen an interrupted scan for appending (validated first: :func:`read_scan`)."""
        read_scan(path)
        return cls(path)

    def append(self, s21_stop: np.ndarray, position_m: float, height_m: float, time_s: float,
               flag: int = 0) -> None:
        """Write one stop (``s21_stop`` is (n_pol, n_freq)) and flush it to disk."""
        f, k = self.f, self.n_complete
        for name in ("s21", "rail_position", "rail_height", "stop_time", "stop_flags"):
            ds = f[name]
            if name == "s21":
                ds.resize(k + 1, axis=1)
                ds[:, k, :] = np.asarray(s21_stop, np.complex64)
            else:
                ds.resize((k + 1,))
        f["rail_position"][k] = position_m
        f["rail_height"][k] = height_m
        f["stop_time"][k] = time_s
        f["stop_flags"][k] = flag
        f.flush()
        f.attrs["n_complete"] = k + 1
        f.flush()
        self.n_complete = k + 1

    def finish(self, status: str = "complete") -> None:
        self.f.attrs["status"] = status
        self.close()

    def close(self) -> None:
        if self.f.id.valid:
            self.f.flush()
            self.f.close()
