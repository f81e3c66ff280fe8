"""Shared HDF5 product machinery: atomic writes, provenance, reproducibility, validation helpers.

Every sarcli product is an HDF5 file whose root carries the provenance attributes

    product_type, schema_version, software_version, created_utc, command_line,
    inputs (JSON list of {"path", "sha256"}), parameters (JSON object)

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
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from sarcli import __version__
from sarcli.errors import ProductError
from sarcli.io.atomic import atomic_path
from sarcli.io.provenance import current

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


def sha256_file(path: str | os.PathLike, chunk: int = 1 << 22, stop: threading.Event | None = None) -> str:
    """Hex SHA-256 of a file's bytes (``stop`` set: abandoned, returns "")."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(chunk):
            if stop is not None and stop.is_set():
                return ""
            h.update(block)
    return h.hexdigest()


def describe_inputs(paths: Sequence[str | os.PathLike], stop: threading.Event | None = None) -> list[dict[str, str]]:
    """Provenance entries ``{"path", "sha256"}`` for input files (file name only, for portability)."""
    out = []
    for p in paths:
        p = Path(p)
        out.append({"path": p.name, "sha256": sha256_file(p, stop=stop) if p.is_file() else ""})
    return out


@contextlib.contextmanager
def hashing(paths: Sequence[str | os.PathLike]) -> Iterator[Callable[[], list[dict[str, str]]]]:
    """:func:`describe_inputs` computed on a thread while the caller works (a product's inputs are read
    once more by the hash, overlapped with the processing instead of before it); yields the function
    that waits for the entries. Leaving the block early abandons the hash."""
    stop = threading.Event()
    with ThreadPoolExecutor(1, thread_name_prefix="sarcli-sha256") as pool:
        future = pool.submit(describe_inputs, list(paths), stop)
        try:
            yield future.result
        finally:
            stop.set()


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
    reproducible (no timestamps) and carry units. The inputs are hashed on a thread meanwhile
    (:func:`hashing`); their entries are written when the block completes.
    """
    with atomic_path(path, ".tmp") as tmp, hashing(inputs) as described:
        with h5py.File(tmp, "w", libver=("earliest", "v110"), track_order=False) as f:
            f.attrs["product_type"] = product_type
            f.attrs["schema_version"] = schema_version
            f.attrs["software_version"] = __version__
            f.attrs["created_utc"] = created_utc()
            f.attrs["command_line"] = command_line if command_line is not None else current().command_line
            f.attrs["parameters"] = json.dumps(to_jsonable(dict(parameters or {})), sort_keys=True)
            yield f
            f.attrs["inputs"] = json.dumps(described())


def dataset(
    group: h5py.Group,
    name: str,
    data: Any,
    units: str | None = None,
    description: str | None = None,
    chunks: Any = None,
    compression: str | None = None,
    maxshape: Any = None,
) -> h5py.Dataset:
    """Create a dataset without timestamps (reproducible bytes), with ``units``/``description``."""
    kw: dict[str, Any] = {"track_times": False}
    if chunks is not None:
        kw["chunks"] = chunks
    if compression:
        kw["compression"] = compression
        if compression == "gzip":
            kw["compression_opts"] = 4
        kw["shuffle"] = True
    if maxshape is not None:
        kw["maxshape"] = maxshape
    ds = group.create_dataset(name, data=data, **kw)
    if units is not None:
        ds.attrs["units"] = units
    if description is not None:
        ds.attrs["description"] = description
    return ds


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


def write_mapping(parent: h5py.Group, name: str, mapping: dict[str, Any]) -> h5py.Group:
    """A group holding a free-form mapping: strings as attributes, arrays as datasets, None skipped
    (used for /truth and similar tables)."""
    g = group(parent, name)
    for k in sorted(mapping):
        v = mapping[k]
        if isinstance(v, str):
            g.attrs[k] = v
        elif v is not None:
            dataset(g, k, np.asarray(v))
    return g


def read_mapping(g: h5py.Group) -> dict[str, Any]:
    """Inverse of :func:`write_mapping`."""
    out: dict[str, Any] = {k: g[k][()] for k in g}
    out.update({k: attr_str(g, k) for k in g.attrs})
    return out
