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
import contextvars
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
from sarcli.errors import MissingFileError, ProductError
from sarcli.io.atomic import atomic_path, readable_name
from sarcli.io.provenance import current
from sarcli.model import checks as ck

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


#: finished hashes by file version (device, inode, size, modification time in ns), the most recent
#: :data:`_HASHED_KEPT`: one product's several images (the focus's two GeoTIFFs of one SLC) read a large
#: input once, and a process that runs for months (gbsar monitor) keeps a bounded table
_hashed: dict[tuple[int, int, int, int], str] = {}
_HASHED_KEPT = 64


def sha256_file(path: str | os.PathLike, chunk: int = 1 << 22, stop: threading.Event | None = None) -> str:
    """Hex SHA-256 of a file's bytes (``stop`` set: abandoned, returns "")."""
    st = os.stat(path)
    key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
    if key in _hashed:
        return _hashed[key]
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(chunk):
            if stop is not None and stop.is_set():
                return ""
            h.update(block)
    _hashed[key] = h.hexdigest()
    while len(_hashed) > _HASHED_KEPT:
        del _hashed[next(iter(_hashed))]  # the oldest (dicts keep insertion order)
    return _hashed[key]


def describe_inputs(paths: Sequence[str | os.PathLike], stop: threading.Event | None = None) -> list[dict[str, str]]:
    """Provenance entries ``{"path", "sha256"}`` for input files (file name only, for portability; the
    bytes of a product still waiting in an :func:`sarcli.io.atomic.all_or_nothing` block are hashed)."""
    out = []
    for p in paths:
        p, now = Path(p), readable_name(p)
        out.append({"path": p.name, "sha256": sha256_file(now, stop=stop) if now.is_file() else ""})
    return out


@contextlib.contextmanager
def hashing(paths: Sequence[str | os.PathLike]) -> Iterator[Callable[[], list[dict[str, str]]]]:
    """:func:`describe_inputs` computed on a thread while the caller works (a product's inputs are read
    once more by the hash, overlapped with the processing instead of before it); yields the function
    that waits for the entries. Leaving the block early abandons the hash."""
    stop = threading.Event()
    with ThreadPoolExecutor(1, thread_name_prefix="sarcli-sha256") as pool:
        # the worker thread does not see this context's all_or_nothing block: run it in a copy
        future = pool.submit(contextvars.copy_context().run, describe_inputs, list(paths), stop)
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


def reproducible() -> bool:
    """Whether ``SOURCE_DATE_EPOCH`` is set: products then store nothing that depends on the clock."""
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
            f.attrs["Conventions"] = CONVENTIONS
            yield f
            label_remaining_dimensions(f)
            f.attrs["inputs"] = json.dumps(described())
        _probed.add(_version_key(tmp))  # written here and now: reading it back needs no probe (a rename
        # keeps the device, inode, size and modification time the key is made of)


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


def _raised_by_h5py(e: BaseException) -> bool:
    """True when the innermost frame of ``e``'s traceback is h5py's (a damaged file, not a sarcli bug)."""
    tb, last = e.__traceback__, None
    while tb is not None:
        last, tb = tb.tb_frame.f_code.co_filename, tb.tb_next
    return last is not None and "h5py" in Path(last).parts


def _h5_reason(e: BaseException) -> str:
    msg = " ".join(str(e).split())
    return f"{e.__class__.__name__}: {msg[:160]}" if msg else e.__class__.__name__


#: Seconds a metadata probe may take (a small product's metadata read in milliseconds; a damaged one
#: can send the HDF5 library into an endless loop, e.g. a global-heap object size bit-flipped).
PROBE_TIMEOUT_S = 20.0
_probed: set[tuple] = set()


def _version_key(path: str | os.PathLike) -> tuple[int, int, int, int]:
    st = os.stat(path)
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


def _walk_metadata(path: Path) -> None:
    """Read every attribute and every dataset's shape, type and chunk index (no data): what a reader
    touches before the samples."""
    with h5py.File(path, "r") as f:
        def visit(obj: Any) -> None:
            for k in obj.attrs:
                obj.attrs[k]
            if isinstance(obj, h5py.Dataset):
                obj.shape, obj.dtype  # noqa: B018
                if obj.chunks is not None:
                    obj.id.get_num_chunks()
        visit(f)
        f.visititems(lambda name, obj: visit(obj))


def probe_metadata(path: str | os.PathLike) -> None:
    """Refuse (one line) an HDF5 file whose metadata send the HDF5 library into a hang or a crash.

    A hang in C code cannot be interrupted from Python, so the metadata are first walked
    (:func:`_walk_metadata`) in another process that is killed after :data:`PROBE_TIMEOUT_S`; errors
    the walk meets are left to the caller, which meets them again in-process and reports them. The
    walk runs in a child forked by a small helper interpreter (:func:`_probe_server`, started once per
    process): forking the caller itself would copy its threads' locks (numba, OpenMP, h5py's own) into
    the child and cost tens of milliseconds. Once per file version (device, inode, size, modification
    time) and process; a no-op where ``fork`` is not available.
    """
    key = _version_key(path)
    if key in _probed or not hasattr(os, "fork"):
        return
    verdict = _PROBER.ask(os.path.abspath(path), PROBE_TIMEOUT_S)
    if verdict == "hang":
        raise ProductError(f"{path}: damaged HDF5 product: reading its metadata does not finish "
                           f"(given up after {PROBE_TIMEOUT_S:g} s)")
    if verdict != "ok":
        raise ProductError(f"{path}: damaged HDF5 product: reading its metadata crashes the HDF5 library"
                           f" ({verdict})")
    _probed.add(key)


def _probe_server() -> None:  # pragma: no cover - runs in the helper interpreter
    """The helper's loop: one JSON request ``[timeout_s, path]`` per line on stdin, one verdict per line
    on stdout: ``ok``, ``hang`` (the walk was killed after the timeout) or ``signal N`` / ``died``."""
    import select
    import signal
    import sys

    for line in sys.stdin:
        timeout, path = json.loads(line)
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            try:
                os.close(r)
                signal.alarm(int(timeout) + 2)  # SIGALRM's default action ends the walk even if the helper died
                with contextlib.suppress(BaseException):
                    _walk_metadata(Path(path))
                os.write(w, b"done")
            finally:
                os._exit(0)
        os.close(w)
        ready, _, _ = select.select([r], [], [], timeout)
        answer = os.read(r, 16) if ready else b""
        os.close(r)
        if not ready:
            os.kill(pid, signal.SIGKILL)
        _, status = os.waitpid(pid, 0)
        if answer == b"done":
            verdict = "ok"
        elif not ready:
            verdict = "hang"
        else:
            verdict = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else "died"
        sys.stdout.write(verdict + "\n")
        sys.stdout.flush()


class _Prober:
    """The caller's side of the helper interpreter (started on first use, restarted if it dies)."""

    def __init__(self) -> None:
        import threading

        self.proc: Any = None
        self.registered = False
        self.lock = threading.Lock()

    def _start(self) -> None:
        import subprocess
        import sys

        code = (f"import sys; sys.path[:0] = {sys.path!r}; "
                "from sarcli.io.h5common import _probe_server; _probe_server()")
        self.proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     text=True, bufsize=1)
        if not self.registered:
            import atexit

            atexit.register(self._stop)
            self.registered = True

    def _stop(self) -> None:
        """End the helper (its loop ends with its stdin; killed if it does not within a second)."""
        proc, self.proc = self.proc, None
        if proc is None:
            return
        with contextlib.suppress(OSError):
            proc.stdin.close()
        try:
            proc.wait(timeout=1.0)
        except Exception:
            proc.kill()
            proc.wait()
        with contextlib.suppress(OSError):
            proc.stdout.close()

    def start(self) -> None:
        """Start the helper unless it runs (not waiting for it to be ready)."""
        with self.lock:
            if self.proc is None or self.proc.poll() is not None:
                self._start()

    def ask(self, path: str, timeout: float) -> str:
        import select

        with self.lock:
            if self.proc is None or self.proc.poll() is not None:
                self._start()
            try:
                self.proc.stdin.write(json.dumps([timeout, path]) + "\n")
                self.proc.stdin.flush()
                ready, _, _ = select.select([self.proc.stdout], [], [], timeout + 30.0)
                line = self.proc.stdout.readline() if ready else ""
            except BaseException:  # interrupted mid-request: its answer would be read by the next one
                self._stop()
                raise
            if not line:  # the helper itself hung or died: start afresh next time
                self._stop()
                return "hang" if not ready else "helper died"
            return line.strip()


_PROBER = _Prober()


def start_probing() -> None:
    """Start :func:`probe_metadata`'s helper interpreter now without waiting for it: a command that opens
    products after its own imports overlaps the helper's start-up (an interpreter importing h5py, 0.3 s)
    with them. A no-op where ``fork`` is not available (no probe there)."""
    if hasattr(os, "fork"):
        _PROBER.start()


@contextlib.contextmanager
def open_product(path: str | os.PathLike, product_type: str | Sequence[str] | None = None,
                 mode: str = "r") -> Iterator[h5py.File]:
    """Open an existing product, refusing (one line) a missing, non-HDF5 or wrong-type file.

    The file's metadata are probed first in a child process (:func:`probe_metadata`): a damaged file
    that would hang or crash the HDF5 library is refused in one line. Inside the block, any error that
    h5py raises (a truncated or damaged file: OSError, KeyError, RuntimeError, ...) becomes one
    :class:`ProductError` line naming the file.
    """
    path = Path(path)
    if not path.exists():
        raise MissingFileError(f"{path}: no such file")
    if path.is_file():
        probe_metadata(path)
    try:
        f = h5py.File(path, mode)
    except Exception as e:  # h5py: OSError for a non-HDF5/truncated file, others for damaged superblocks
        if not (isinstance(e, OSError) or _raised_by_h5py(e)):
            raise
        raise ProductError(f"{path}: not a readable HDF5 product ({_h5_reason(e)})") from None
    try:
        ptype = f.attrs.get("product_type")
        if ptype is None:
            raise ProductError(f"{path}: not a sarcli product (no product_type attribute)")
        ptype = ck.text(str(path), "product_type", ptype)
        if product_type is not None:
            wanted = [product_type] if isinstance(product_type, str) else list(product_type)
            if ptype not in wanted:
                raise ProductError(f"{path}: is a '{ptype}' product, expected {' or '.join(wanted)}")
        yield f
    except ProductError:
        raise
    except Exception as e:
        if not _raised_by_h5py(e):
            raise
        raise ProductError(f"{path}: damaged HDF5 product, cannot read it ({_h5_reason(e)})") from None
    finally:
        with contextlib.suppress(Exception):
            f.close()


def _label(obj: h5py.HLObject) -> str:
    """``file: /group`` for messages about an object of a product."""
    name = obj.name if obj.name not in (None, "/") else ""
    return f"{obj.file.filename}{': ' + name.lstrip('/') if name else ''}"


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


def read_array(g: h5py.Group, name: str, kind: str = "f", ndim: int | None = None,
               shape: tuple[int | None, ...] | None = None, finite: bool = True, min_size: int = 0,
               required: bool = True) -> np.ndarray | None:
    """A dataset's values, checked (:func:`sarcli.model.checks.array`: dtype kind, rank or shape, size,
    finiteness); a missing optional dataset gives None, a missing required one a ProductError."""
    if name not in g:
        if required:
            raise ProductError(f"{_label(g)}: malformed product, missing '{name}'")
        return None
    ds = g[name]
    if not isinstance(ds, h5py.Dataset):
        raise ProductError(f"{_label(g)}: malformed product, '{name}' is not a dataset")
    where = _label(g)
    # dtype and rank first: no point reading a string table where numbers belong
    ck.array(where, name, np.empty((0,) * ds.ndim, ds.dtype), kind, ndim, finite=False)
    return ck.array(where, name, ds[()], kind, ndim, shape, finite, min_size)


_MISSING = object()


def attr_value(obj: h5py.HLObject, key: str, default: Any = _MISSING) -> Any:
    """An attribute's value; a missing one is ``default`` or, without a default, one ProductError line."""
    if key not in obj.attrs:
        if default is _MISSING:
            raise ProductError(f"{_label(obj)}: malformed product, attribute '{key}' missing")
        return default
    return obj.attrs[key]


def attr_number(obj: h5py.HLObject, key: str, default: Any = _MISSING, lo: float | None = None,
                hi: float | None = None, integer: bool = False, unit: str = "") -> Any:
    """A numeric scalar attribute (text, arrays, NaN, values outside [lo, hi] refused in one line)."""
    v = attr_value(obj, key, default)
    if v is default and default is not _MISSING:
        return default
    return ck.number(_label(obj), key, v, lo, hi, integer, unit)


def attr_str(obj: h5py.HLObject, key: str, default: str | None = None) -> str | None:
    """A text attribute (bytes or str, valid UTF-8; anything else is refused in one line) or ``default``."""
    v = obj.attrs.get(key, None)
    if v is None:
        return default
    return ck.text(_label(obj), key, v)


def attr_json(obj: h5py.HLObject, key: str, default: Any = _MISSING, kind: type = dict) -> Any:
    """A JSON text attribute decoded, of type ``kind`` (dict or list); bad JSON refused in one line."""
    v = attr_value(obj, key, default)
    if v is default and default is not _MISSING:
        return default
    s = ck.text(_label(obj), key, v)
    try:
        out = json.loads(s)
    except (json.JSONDecodeError, RecursionError):
        raise ProductError(f"{_label(obj)}: attribute '{key}' is not valid JSON") from None
    if not isinstance(out, kind):
        raise ProductError(f"{_label(obj)}: attribute '{key}' must be a JSON {kind.__name__}")
    return out


def provenance(f: h5py.File) -> dict[str, Any]:
    """The root provenance attributes, JSON fields decoded (text that is not JSON is kept as text)."""
    out: dict[str, Any] = {}
    for k in PROVENANCE_ATTRS:
        v = attr_str(f, k)
        if k in ("inputs", "parameters") and v is not None:
            with contextlib.suppress(json.JSONDecodeError, RecursionError):
                v = json.loads(v)
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
    """Inverse of :func:`write_mapping` (datasets as arrays, text attributes checked as UTF-8)."""
    out: dict[str, Any] = {}
    for k in g:
        if not isinstance(g[k], h5py.Dataset):
            raise ProductError(f"{_label(g)}: malformed product, '{k}' is not a dataset")
        out[k] = g[k][()]
    out.update({k: attr_str(g, k) for k in g.attrs})
    return out
