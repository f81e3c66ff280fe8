"""Shared HDF5 product machinery: atomic writes, provenance, reproducibility, validation helpers.

Every sarcli product is an HDF5 file whose root carries the provenance attributes

    product_type, schema_version, software_version, created_utc, command_line,
    inputs (JSON list of {"path", "sha256"}), parameters (JSON object)

Self-description (CF-1.8 where it applies, so that netCDF tools and ``xarray.open_dataset(path,
engine="h5netcdf", group=...)`` give labelled arrays): the root has ``Conventions = "CF-1.8"``;
every dataset has ``units`` (UDUNITS strings; times after the product's epoch are
``seconds since <epoch>``, :func:`cf_time_units`) and a ``description``; the axes of every array are
HDF5 dimension scales: coordinates (:func:`coordinate`: azimuth time, slant range, frequency, rail
position, ...) attached by the writers, and, for any axis left without one when the product is
closed, a netCDF dimension without values named after the dataset (``truth_targets_0``, at the root).

Reproducibility: when ``SOURCE_DATE_EPOCH`` is set, ``created_utc`` is taken from it and no object
timestamps are stored, so the same inputs and command give a byte-identical file.
Atomicity: a product is written to a temporary file in the target folder and renamed into place,
so an interrupted run never leaves a half product behind.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import hashlib
import json
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from sarcli import __version__
from sarcli.errors import ProductError
from sarcli.io.atomic import atomic_path
from sarcli.io.provenance import current

CONVENTIONS = "CF-1.8"
#: the NAME of a netCDF-4 dimension that has no coordinate values (netCDF's and h5netcdf's convention)
_PURE_DIMENSION = "This is a netCDF dimension but not a netCDF variable."

#: units of a name by its suffix (sarcli's SI naming: ``*_hz``, ``*_m``, ...), the longest match first
_SUFFIX_UNITS = (("_hz_per_s", "Hz/s"), ("_mps", "m/s"), ("_m2", "m2"), ("_hz", "Hz"), ("_rad", "rad"),
                 ("_deg", "degree"), ("_db", "dB"), ("_dbi", "dBi"), ("_mm", "mm"), ("_s", "s"), ("_m", "m"))


def units_from_name(name: str) -> str | None:
    """The units a sarcli name says by its suffix (``closest_range_m`` -> ``m``), None if it says none."""
    for suffix, unit in _SUFFIX_UNITS:
        if name.endswith(suffix):
            return unit
    return None


PROVENANCE_ATTRS = (
    "product_type",
    "schema_version",
    "software_version",
    "created_utc",
    "command_line",
    "inputs",
    "parameters",
)


def created_utc() -> str:
    """ISO-8601 UTC creation time, from ``SOURCE_DATE_EPOCH`` when it is set."""
    sde = os.environ.get("SOURCE_DATE_EPOCH")
    if sde is not None and sde.strip():
        t = _dt.datetime.fromtimestamp(int(sde), tz=_dt.UTC)
    else:
        t = _dt.datetime.now(tz=_dt.UTC)
    return t.strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def parse_utc(iso_utc: str) -> _dt.datetime:
    """An ISO-8601 UTC time (``2008-09-27T17:49:20.123456Z``; more than 6 fractional digits are cut to
    microseconds, a missing zone is UTC) as an aware datetime."""
    import re

    s = str(iso_utc).strip().replace("Z", "+00:00")
    s = re.sub(r"(\.\d{6})\d+", r"\1", s)
    try:
        t = _dt.datetime.fromisoformat(s)
    except ValueError:
        raise ProductError(f"{iso_utc!r} is not an ISO-8601 UTC time") from None
    return t.replace(tzinfo=_dt.UTC) if t.tzinfo is None else t.astimezone(_dt.UTC)


def cf_time_units(epoch_utc: str) -> str:
    """CF time units of seconds after ``epoch_utc``: ``seconds since 2008-09-27T17:49:20.123456`` (UTC;
    the form ISCE3/NISAR products use, which xarray decodes to datetime64)."""
    return "seconds since " + parse_utc(epoch_utc).strftime("%Y-%m-%dT%H:%M:%S.%f")


def sha256_file(path: str | os.PathLike, chunk: int = 1 << 22) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(chunk):
            h.update(block)
    return h.hexdigest()


def describe_inputs(paths: Sequence[str | os.PathLike]) -> list[dict[str, str]]:
    """Provenance entries ``{"path", "sha256"}`` for input files (file name only, for portability)."""
    out = []
    for p in paths:
        p = Path(p)
        out.append({"path": p.name, "sha256": sha256_file(p) if p.is_file() else ""})
    return out


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays and paths inside ``obj`` into plain JSON types."""
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        v = float(obj)
        return v if np.isfinite(v) else None
    if isinstance(obj, float):
        return obj if np.isfinite(obj) else None
    if isinstance(obj, os.PathLike):
        return str(obj)
    if isinstance(obj, bytes):  # HDF5 fixed-length strings (NISAR/CF attributes)
        return obj.decode("utf-8", errors="replace")
    return obj


def _reproducible() -> bool:
    return bool(os.environ.get("SOURCE_DATE_EPOCH", "").strip())


@contextlib.contextmanager
def atomic_h5(
    path: str | os.PathLike,
    product_type: str,
    schema_version: str,
    parameters: Mapping[str, Any] | None = None,
    inputs: Sequence[str | os.PathLike] = (),
    command_line: str | None = None,
) -> Iterator[h5py.File]:
    """Open a new product for writing; it appears at ``path`` only if the block completes.

    Yields an ``h5py.File``. Use :func:`dataset` to create datasets so that they are
    reproducible (no timestamps) and carry units.
    """
    with atomic_path(path, ".tmp") as tmp:
        with h5py.File(tmp, "w", libver=("earliest", "v110"), track_order=False) as f:
            f.attrs["product_type"] = product_type
            f.attrs["schema_version"] = schema_version
            f.attrs["software_version"] = __version__
            f.attrs["created_utc"] = created_utc()
            f.attrs["command_line"] = command_line if command_line is not None else current().command_line
            f.attrs["inputs"] = json.dumps(describe_inputs(inputs))
            f.attrs["parameters"] = json.dumps(to_jsonable(dict(parameters or {})), sort_keys=True)
            f.attrs["Conventions"] = CONVENTIONS
            yield f
            label_remaining_dimensions(f)


def dataset(
    group: h5py.Group,
    name: str,
    data: Any,
    units: str | None = None,
    description: str | None = None,
    chunks: Any = None,
    compression: str | None = None,
    maxshape: Any = None,
    dims: Sequence[h5py.Dataset | None] = (),
    level: int = 4,
) -> h5py.Dataset:
    """Create a dataset without timestamps (reproducible bytes), with ``units``/``description`` and the
    dimension scales ``dims`` attached to its first axes (None: leave that axis). ``compression``
    ("gzip" at ``level``, or "lzf") always comes after the byte shuffle."""
    kw: dict[str, Any] = {"track_times": False}
    if chunks is not None:
        kw["chunks"] = chunks
    if compression:
        kw["compression"] = compression
        if compression == "gzip":
            kw["compression_opts"] = level
        kw["shuffle"] = True
    if maxshape is not None:
        kw["maxshape"] = maxshape
    ds = group.create_dataset(name, data=data, **kw)
    if units is not None:
        ds.attrs["units"] = units
    if description is not None:
        ds.attrs["description"] = description
    attach(ds, *dims)
    return ds


def coordinate(group: h5py.Group, name: str, data: Any, units: str, description: str, **kw: Any) -> h5py.Dataset:
    """A 1-D dataset that is a dimension scale (a netCDF coordinate variable named ``name``)."""
    ds = dataset(group, name, data, units=units, description=description, **kw)
    ds.make_scale(name)
    return ds


def attach(ds: h5py.Dataset, *scales: h5py.Dataset | None) -> None:
    """Attach dimension scales to the first axes of ``ds`` (None skips an axis)."""
    for axis, sc in enumerate(scales):
        if sc is not None:
            ds.dims[axis].attach_scale(sc)


def label_remaining_dimensions(f: h5py.File) -> None:
    """Give every axis still without a dimension scale a netCDF dimension without values, at the root,
    named after the dataset's path and axis (``/truth/targets`` axis 0 -> ``truth_targets_0``), so
    that every group opens in netCDF tools without ``phony_dim`` names. Scales stay as they are."""
    found: list[h5py.Dataset] = []
    f.visititems(lambda name, obj: found.append(obj) if isinstance(obj, h5py.Dataset) else None)
    for ds in sorted(found, key=lambda d: d.name):
        if ds.is_scale or ds.ndim == 0:
            continue
        for axis in range(ds.ndim):
            if len(ds.dims[axis]):
                continue
            name = ds.name.strip("/").replace("/", "_") + f"_{axis}"
            n = ds.shape[axis]
            dim = f.create_dataset(name, shape=(n,), dtype="f4", track_times=False,
                                   **({"maxshape": (None,), "chunks": (max(n, 1),)}
                                      if ds.maxshape[axis] is None else {}))
            dim.make_scale(f"{_PURE_DIMENSION}{n:10d}")
            ds.dims[axis].attach_scale(dim)


def is_pure_dimension(ds: h5py.Dataset) -> bool:
    """A netCDF dimension without values (:func:`label_remaining_dimensions`): no data, only a name."""
    return str(attr_str(ds, "NAME", "") or "").startswith(_PURE_DIMENSION)


def unlabelled(f: h5py.File, skip: Sequence[str] = ()) -> list[str]:
    """What keeps a product from describing itself: datasets (outside the groups ``skip``) without
    ``units`` or ``description``, axes without a dimension scale, a missing ``Conventions``."""
    out = [] if "Conventions" in f.attrs else ["/: no Conventions attribute"]

    def visit(name: str, obj: Any) -> None:
        if not isinstance(obj, h5py.Dataset) or any(("/" + name).startswith(g) for g in skip):
            return
        if is_pure_dimension(obj):
            return
        for key in ("units", "description"):
            if key not in obj.attrs:
                out.append(f"/{name}: no {key}")
        for axis in range(obj.ndim):
            if not len(obj.dims[axis]) and not obj.is_scale:
                out.append(f"/{name}: axis {axis} has no dimension scale")

    f.visititems(visit)
    return out


def group(parent: h5py.Group, name: str) -> h5py.Group:
    """Create a sub-group (reproducible: no timestamps when SOURCE_DATE_EPOCH is set)."""
    gcpl = h5py.h5p.create(h5py.h5p.GROUP_CREATE)
    gcpl.set_obj_track_times(False)
    gid = h5py.h5g.create(parent.id, name.encode(), gcpl=gcpl)
    return h5py.Group(gid)


@contextlib.contextmanager
def open_product(path: str | os.PathLike, product_type: str | Sequence[str] | None = None,
                 mode: str = "r") -> Iterator[h5py.File]:
    """Open an existing product, refusing (one line) a missing, non-HDF5 or wrong-type file."""
    path = Path(path)
    if not path.exists():
        raise ProductError(f"{path}: no such file")
    try:
        f = h5py.File(path, mode)
    except OSError as e:
        raise ProductError(f"{path}: not a readable HDF5 product ({e.__class__.__name__})") from None
    try:
        ptype = f.attrs.get("product_type")
        if isinstance(ptype, bytes):
            ptype = ptype.decode()
        if ptype is None:
            raise ProductError(f"{path}: not a sarcli product (no product_type attribute)")
        if product_type is not None:
            wanted = [product_type] if isinstance(product_type, str) else list(product_type)
            if ptype not in wanted:
                raise ProductError(f"{path}: is a '{ptype}' product, expected {' or '.join(wanted)}")
        yield f
    finally:
        f.close()


def require(f: h5py.Group, name: str, path: str | os.PathLike, shape_rank: int | None = None,
            dtype_kind: str | None = None) -> h5py.Dataset:
    """Fetch a required dataset, refusing the file in one line if it is missing or mis-shaped."""
    if name not in f:
        raise ProductError(f"{path}: malformed product, missing '{name}'")
    ds = f[name]
    if not isinstance(ds, h5py.Dataset):
        raise ProductError(f"{path}: malformed product, '{name}' is not a dataset")
    if shape_rank is not None and ds.ndim != shape_rank:
        raise ProductError(f"{path}: malformed product, '{name}' has rank {ds.ndim}, expected {shape_rank}")
    if dtype_kind is not None and ds.dtype.kind not in dtype_kind:
        raise ProductError(f"{path}: malformed product, '{name}' has dtype {ds.dtype}")
    return ds


def attr_str(obj: h5py.HLObject, key: str, default: str | None = None) -> str | None:
    """Read a string attribute (bytes or str) or ``default``."""
    v = obj.attrs.get(key, default)
    if isinstance(v, bytes):
        return v.decode()
    return v if v is None else str(v)


def provenance(f: h5py.File) -> dict[str, Any]:
    """The root provenance attributes, JSON fields decoded."""
    out: dict[str, Any] = {}
    for k in PROVENANCE_ATTRS:
        v = attr_str(f, k)
        if k in ("inputs", "parameters") and v is not None:
            try:
                v = json.loads(v)
            except json.JSONDecodeError:
                pass
        out[k] = v
    return out


#: units and descriptions of the truth arrays of sarcli's simulators (others: units by their suffix)
TRUTH_FIELDS: dict[str, tuple[str, str]] = {
    "targets": ("1", "point targets, one row per target: units of each field in field_units"),
    "clutter_patches": ("1", "clutter patches, one row per patch: units of each field in field_units"),
    "doppler_centroid_hz": ("Hz", "Doppler centroid of the static ground at reference_height_m per range sample, "
                                  "at doppler_truth_time_s (NaN where the beam misses the ground)"),
    "doppler_rate_hz_per_s": ("Hz/s", "Doppler rate of the static ground per range sample, at doppler_truth_time_s"),
    "doppler_truth_time_s": ("s", "time of the Doppler truth arrays (the scene centre)"),
    "beam_look_angle_rad": ("rad", "antenna beam look angle"),
    "reference_height_m": ("m", "height of the ground of the Doppler truth above the ellipsoid"),
    "seed": ("1", "seed of the scene's numpy random Generator"),
    "noise_power": ("1", "thermal noise power per complex sample (squared digital units)"),
    "receiver_gain_db": ("dB", "receiver gain applied by the simulated receiver"),
    "scatterer_position": ("m", "scatterer positions (x along the rail, y across, z up) in the scan frame"),
    "scatterer_reflectivity": ("1", "complex reflectivity of each scatterer (per polarization)"),
    "scatterer_kind": ("1", "scatterer kind code"),
    "scatterer_displacement": ("m", "scatterer displacement vector at this scan"),
    "scatterer_los_displacement": ("m", "scatterer displacement along the line of sight (+ away from the radar)"),
}


def write_mapping(parent: h5py.Group, name: str, mapping: dict[str, Any], epoch_utc: str | None = None,
                  fields: Mapping[str, tuple[str, str]] = TRUTH_FIELDS) -> h5py.Group:
    """A group holding a free-form mapping: strings as attributes, arrays as datasets, None skipped
    (used for /truth and similar tables). Units and description from ``fields`` or, for other names,
    units by their suffix; ``*_time_s`` names are ``seconds since epoch_utc`` when it is given; a
    compound table gets ``field_units`` (JSON: each field's units by its suffix)."""
    g = group(parent, name)
    for k in sorted(mapping):
        v = mapping[k]
        if isinstance(v, str):
            g.attrs[k] = v
        elif v is not None:
            a = np.asarray(v)
            units, description = fields.get(k, (units_from_name(k) or "1", f"{name}: {k.replace('_', ' ')}"))
            if epoch_utc and k.endswith("_time_s"):
                units = cf_time_units(epoch_utc)
            ds = dataset(g, k, a, units=units, description=description)
            if a.dtype.names:
                ds.attrs["field_units"] = json.dumps(
                    {n: (cf_time_units(epoch_utc) if epoch_utc and n.endswith("_time_s") else units_from_name(n) or "1")
                     for n in a.dtype.names})
    return g


def read_mapping(g: h5py.Group) -> dict[str, Any]:
    """Inverse of :func:`write_mapping`."""
    out: dict[str, Any] = {k: g[k][()] for k in g}
    out.update({k: attr_str(g, k) for k in g.attrs})
    return out
