"""Frequency-sweep data sets -> a GB-SAR scan (``sarcli gbsar import``).

A scan is one complex frequency sweep per antenna position. Many data sets are that: VNA rail scans,
stepped-frequency GPR rail scans, airborne spotlight phase histories (AFRL GOTCHA: de-ramped sweeps
per pulse with the antenna position and the range to the scene centre). This module reads them from

- MATLAB ``.mat`` files (v4-v7 with ``scipy.io.loadmat``; v7.3, which is HDF5, with h5py), NumPy
  ``.npz`` (``np.savez``: arrays by name) and ``.npy`` (a structured array: fields by name), by
  *variable*: a name, or a dotted path into MATLAB structs / structured fields (``data.fp``);
- CSV, one row per sample (long format; :func:`read_csv`), by *column* name;
- Touchstone ``.s1p``/``.s2p`` v1 or v2 (one file per antenna position, every format RI/MA/DB and
  frequency unit Hz/kHz/MHz/GHz; :func:`read_touchstone`), by S-parameter name.

What it needs (:class:`Names`): the samples (``data``: one complex variable, or ``RE,IM``), the
frequencies (Hz), the antenna positions (one variable: 1-D rail positions, an (n, 3) or (3, n)
array; or ``X,Y,Z``: three variables) and optionally a reference range per sweep (m; a scalar is
used for every sweep). Unnamed roles are looked up under common names (``DEFAULTS``), in the file's
top level and then inside its only struct. A 2-D sample matrix is frequency x position or position x
frequency: the layout is taken from the lengths of the frequency and position vectors, and a
square matrix (as many frequencies as positions) needs ``layout`` to say which. Several files are
concatenated along the positions (they must share the frequencies). Frequencies stored in float32
that are a uniform sweep to within float32 rounding (one unit in the last place off the least-squares
line; GOTCHA: 514 Hz off, float32 resolution 1024 Hz at 9.9 GHz) are replaced by that uniform sweep,
as range compression needs (said in the notes).

Every malformed input is refused in one line naming the file and what is wrong
(:class:`sarcli.errors.FormatError`; :class:`sarcli.errors.ConfigError` for an option that cannot
apply). Phase convention of the result: :mod:`sarcli.io.scan`.
"""

from __future__ import annotations

import csv
import math
import re
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, FormatError, MissingFileError
from sarcli.io.scan import POLARIZATIONS
from sarcli.model.gbsar import Antenna, Scan

LAYOUTS = ("auto", "frequency-position", "position-frequency")
MATRIX_FORMATS = {".mat": "matlab", ".npz": "numpy", ".npy": "numpy"}
FORMATS = {**MATRIX_FORMATS, ".csv": "csv", ".s1p": "touchstone", ".s2p": "touchstone"}
DEFAULTS = {
    "data": ("fp", "s21", "S21", "data", "phdata", "phase_history", "sweeps", "samples"),
    "frequency": ("freq", "frequency", "frequencies", "freqs", "f", "frequency_hz"),
    "position": ("position", "positions", "pos", "rail_position", "antenna_position", "AntPos"),
    "reference_range": ("r0", "R0", "reference_range", "r_ref"),
}
CSV_COMPLEX_PAIRS = (("s21_re", "s21_im"), ("s21_real", "s21_imag"), ("re", "im"), ("real", "imag"))


@dataclass(frozen=True)
class Names:
    """What to take from the files: each role a name (None: the defaults); ``data`` and ``position``
    may be comma lists (``RE,IM``; ``X,Y,Z``). For Touchstone files ``data`` is the S-parameter
    (S11, S21, S12, S22) and ``position`` the rail positions as ``START:STEP`` or a comma list of
    numbers (m), one per file."""

    data: str | None = None
    frequency: str | None = None
    position: str | None = None
    reference_range: str | None = None
    layout: str = "auto"


@dataclass
class Sweeps:
    """Sweeps read from one or more files: ``samples`` (n_pos, n_freq) complex128, ``frequency`` (n_freq,)
    Hz, ``position`` (n_pos,) rail positions or (n_pos, 3) m, ``reference_range`` (n_pos,) m or None;
    ``used`` maps each role to what was read; ``layout`` how a matrix was oriented; ``notes`` for people."""

    samples: np.ndarray
    frequency: np.ndarray
    position: np.ndarray
    reference_range: np.ndarray | None
    format: str
    used: dict[str, str] = field(default_factory=dict)
    layout: str = ""
    notes: list[str] = field(default_factory=list)
    frequency_float32: bool = False


def _split(spec: str | None) -> list[str] | None:
    return None if spec is None else [p.strip() for p in spec.split(",") if p.strip()]


def _list(names: Sequence[str], limit: int = 12) -> str:
    names = list(names)
    return ", ".join(names[:limit]) + (f" (and {len(names) - limit} more)" if len(names) > limit else "") \
        if names else "none"


# --- variables of MATLAB and NumPy files ---------------------------------------------------------------

class _Variables:
    """Named arrays of one file, reached by dotted paths (``data.fp``)."""

    def __init__(self, path: Path, top: dict[str, Any]):
        self.path, self.top = path, top

    def structs(self) -> list[str]:
        return [k for k, v in self.top.items() if _fields(v) is not None]

    def names(self, prefix: str = "") -> list[str]:
        node = self.top if not prefix else self.node(prefix.rstrip("."))
        keys = list(node) if isinstance(node, dict) else (_fields(node) or [])
        return [prefix + k for k in keys]

    def node(self, dotted: str) -> Any:
        """The object at ``dotted`` or None."""
        obj: Any = self.top
        for part in dotted.split("."):
            if isinstance(obj, dict):
                obj = obj.get(part)
            elif _fields(obj) is not None and part in _fields(obj):
                obj = _field(obj, part)
            else:
                return None
            if obj is None:
                return None
        return obj

    def array(self, dotted: str) -> np.ndarray | None:
        """The numeric array at ``dotted`` (None if there is none)."""
        obj = self.node(dotted)
        if obj is None or _fields(obj) is not None:
            return None
        a = np.asarray(obj)
        return a if a.dtype.kind in "biufc" else None

    def require(self, dotted: str, role: str) -> np.ndarray:
        a = self.array(dotted)
        if a is None:
            what = "is not a numeric array" if self.node(dotted) is not None else "does not exist"
            head = dotted.rpartition(".")[0]
            known = self.names(head + ".") if head and self.node(head) is not None else self.names()
            raise FormatError(f"{self.path}: the {role} variable '{dotted}' {what} (variables: {_list(known)})")
        return a


def _fields(obj: Any) -> list[str] | None:
    """Field names of a MATLAB struct (scipy mat_struct or HDF5 group) or a structured array, else None."""
    names = getattr(obj, "_fieldnames", None)
    if names is not None:
        return list(names)
    if isinstance(obj, dict):
        return list(obj)
    if isinstance(obj, np.ndarray | np.void) and obj.dtype.names is not None:
        return list(obj.dtype.names)
    return None


def _field(obj: Any, name: str) -> Any:
    if isinstance(obj, dict | np.void):
        return obj[name]
    if isinstance(obj, np.ndarray):
        v = obj[name]
        return v[()] if v.ndim == 0 else v
    return getattr(obj, name)


def _load_matlab(path: Path) -> _Variables:
    import scipy.io

    try:
        top = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)
    except NotImplementedError:  # v7.3: an HDF5 file
        return _Variables(path, _load_matlab_hdf5(path))
    except (scipy.io.matlab.MatReadError, ValueError, TypeError, OSError, EOFError) as e:
        raise FormatError(f"{path}: not a readable MATLAB file ({e})") from None
    return _Variables(path, {k: v for k, v in top.items() if not k.startswith("__")})


def _load_matlab_hdf5(path: Path) -> dict[str, Any]:
    """A MATLAB v7.3 file as nested dicts of arrays: MATLAB writes column-major arrays (read here with
    their axes reversed) and complex numbers as (real, imag) compound elements; structs are groups."""
    import h5py

    def convert(obj: Any) -> Any:
        if isinstance(obj, h5py.Group):
            return {k: convert(v) for k, v in obj.items() if not k.startswith("#")}
        a = obj[()]
        if isinstance(a, np.ndarray) and a.dtype.names and set(a.dtype.names) >= {"real", "imag"}:
            a = a["real"] + 1j * a["imag"]
        a = np.asarray(a)
        return np.squeeze(a.T) if a.ndim else a

    try:
        with h5py.File(path, "r") as f:
            return {k: convert(v) for k, v in f.items() if not k.startswith("#")}
    except OSError as e:
        raise FormatError(f"{path}: not a readable MATLAB v7.3 (HDF5) file ({e})") from None


def _load_numpy(path: Path) -> _Variables:
    try:
        obj = np.load(path, allow_pickle=False)
    except ValueError as e:
        if "pickle" in str(e):
            raise FormatError(f"{path}: holds pickled Python objects, which are not read (unsafe); save named "
                              "arrays with np.savez") from None
        raise FormatError(f"{path}: not a readable NumPy file ({e})") from None
    except (OSError, EOFError, zipfile.BadZipFile) as e:  # an .npz is a zip: a damaged one is BadZipFile
        raise FormatError(f"{path}: not a readable NumPy file ({e})") from None
    if isinstance(obj, np.lib.npyio.NpzFile):
        with obj:
            return _Variables(path, {k: obj[k] for k in obj.files})
    if obj.dtype.names is None:
        raise FormatError(f"{path}: a .npy file holds one unnamed array ({obj.shape}); the samples, frequencies and "
                          "positions need names: save them with np.savez (or as fields of a structured array)")
    rec = obj.reshape(-1)[0] if obj.size == 1 else obj  # one record: its fields; a table: its columns
    return _Variables(path, {k: _field(rec, k) for k in obj.dtype.names})


def _scope(v: _Variables, names: Names) -> str:
    """Where the default names are looked up: beside the named samples, else the top level, or inside
    the file's only struct when the samples are not found at the top (GOTCHA's ``data.fp``)."""
    if names.data is not None:
        head = names.data.split(",")[0].rpartition(".")[0]
        return head + "." if head else ""
    if any(v.array(n) is not None for n in DEFAULTS["data"]):
        return ""
    structs = v.structs()
    return structs[0] + "." if len(structs) == 1 else ""


def _default(v: _Variables, scope: str, role: str) -> str | None:
    return next((scope + n for n in DEFAULTS[role] if v.array(scope + n) is not None), None)


def _matrix_file(path: Path, names: Names) -> Sweeps:
    """Samples, frequencies, positions and reference ranges of one MATLAB or NumPy file."""
    v = _load_matlab(path) if path.suffix.lower() == ".mat" else _load_numpy(path)
    scope = _scope(v, names)
    used: dict[str, str] = {}

    def pick(role: str, given: str | None, required: bool = True) -> list[str] | None:
        parts = _split(given)
        if parts is None:
            d = _default(v, scope, role)
            if d is None and role == "position":
                xyz = [scope + c for c in "xyz"]
                parts = xyz if all(v.array(n) is not None for n in xyz) else \
                    [scope + "x"] if v.array(scope + "x") is not None else None
            else:
                parts = None if d is None else [d]
        if parts is None:
            if required:
                raise FormatError(f"{path}: no {role} variable under the usual names ({', '.join(DEFAULTS[role])}"
                                  f"{', x,y,z' if role == 'position' else ''}) in {_list(v.names(scope))}: "
                                  f"give --{role.replace('_', '-')}")
            return None
        used[role] = ",".join(parts)
        return parts

    d_names = pick("data", names.data)
    if len(d_names) not in (1, 2):
        raise ConfigError(f"--data takes one complex variable or two (RE,IM), got {names.data!r}")
    if len(d_names) == 2:
        re_, im_ = (np.asarray(v.require(n, "data"), np.float64) for n in d_names)
        if re_.shape != im_.shape:
            raise FormatError(f"{path}: the real part {d_names[0]} {re_.shape} and imaginary part {d_names[1]} "
                              f"{im_.shape} differ in shape")
        data = re_ + 1j * im_
    else:
        data = v.require(d_names[0], "data")
        if data.dtype.kind != "c":
            raise FormatError(f"{path}: the data variable '{d_names[0]}' is real ({data.dtype}); a sweep is complex: "
                              "give a complex variable or the two parts as --data RE,IM")
    freq = v.require(pick("frequency", names.frequency)[0], "frequency")
    p_names = pick("position", names.position)
    if len(p_names) not in (1, 3):
        raise ConfigError(f"--position takes one variable or three (X,Y,Z), got {names.position!r}")
    pos = [v.require(n, "position") for n in p_names]
    r_names = pick("reference_range", names.reference_range, required=names.reference_range is not None)
    ref = None if r_names is None else v.require(r_names[0], "reference range")
    position = _positions(path, pos, p_names)
    if sum(n > 1 for n in freq.shape) > 1:
        raise FormatError(f"{path}: the frequency variable {used['frequency']} has shape {freq.shape}, not a vector")
    frequency = np.asarray(freq, np.float64).reshape(-1)
    samples, layout = _orient(path, data, frequency.size, position.shape[0], names.layout)
    return Sweeps(samples=samples, frequency=frequency, position=position,
                  reference_range=_reference(path, ref, position.shape[0]), format=MATRIX_FORMATS[path.suffix.lower()],
                  used=used, layout=layout, frequency_float32=freq.dtype == np.float32)


def _positions(path: Path, arrays: list[np.ndarray], names: list[str]) -> np.ndarray:
    """(n,) rail positions or (n, 3) antenna positions from one or three variables."""
    if len(arrays) == 3:
        vecs = [np.asarray(a, np.float64).reshape(-1) for a in arrays]
        if len({x.size for x in vecs}) != 1:
            raise FormatError(f"{path}: the position variables {', '.join(names)} have "
                              f"{', '.join(str(x.size) for x in vecs)} values, not one per sweep each")
        p = np.stack(vecs, axis=1)
    else:
        a = np.asarray(arrays[0], np.float64)
        a = a.reshape(-1) if a.ndim == 2 and 1 in a.shape and a.shape != (1, 3) else a
        if a.ndim == 0:
            a = a.reshape(1)
        if a.ndim == 2 and a.shape[1] != 3 and a.shape[0] == 3:
            a = a.T
        if not (a.ndim == 1 or (a.ndim == 2 and a.shape[1] == 3)):
            raise FormatError(f"{path}: the position variable {names[0]} has shape {a.shape}; expected (n,) rail "
                              "positions or (n, 3) antenna positions (or three variables X,Y,Z)")
        p = a
    if not np.all(np.isfinite(p)):
        k = int(np.flatnonzero(~np.all(np.isfinite(p.reshape(p.shape[0], -1)), axis=1))[0])
        raise FormatError(f"{path}: the antenna position of sweep {k} is not finite")
    return p


def _reference(path: Path, ref: np.ndarray | None, n: int) -> np.ndarray | None:
    if ref is None:
        return None
    r = np.asarray(ref, np.float64).reshape(-1)
    if r.size == 1:
        r = np.full(n, r[0])
    if r.size != n:
        raise FormatError(f"{path}: {r.size} reference ranges for {n} sweeps")
    if not np.all(np.isfinite(r)):
        raise FormatError(f"{path}: the reference range of sweep {int(np.flatnonzero(~np.isfinite(r))[0])} is not "
                          "finite")
    return r


def _orient(path: Path, data: np.ndarray, n_f: int, n_p: int, layout: str) -> tuple[np.ndarray, str]:
    """(n_p, n_f) samples from a matrix of either orientation, and the orientation taken."""
    if layout not in LAYOUTS:
        raise ConfigError(f"unknown layout '{layout}' (use {', '.join(LAYOUTS)})")
    a = np.asarray(data)
    if a.ndim == 1 and n_p == 1:
        a = a[None, :]
    if a.ndim != 2:
        raise FormatError(f"{path}: the samples have shape {a.shape}; expected a matrix of {n_f} frequencies x "
                          f"{n_p} positions (either way round)")
    fits = {"frequency-position": a.shape == (n_f, n_p), "position-frequency": a.shape == (n_p, n_f)}
    if layout != "auto":
        if not fits[layout]:
            raise FormatError(f"{path}: the samples are {a.shape[0]} x {a.shape[1]}, not {layout.replace('-', ' x ')} "
                              f"= {n_f if layout[0] == 'f' else n_p} x {n_p if layout[0] == 'f' else n_f}")
        taken = layout
    elif fits["frequency-position"] and fits["position-frequency"] and n_f > 1:
        raise ConfigError(f"{path}: the samples are {n_f} x {n_p} with as many frequencies as positions: the layout "
                          "is ambiguous; give --layout frequency-position or position-frequency")
    elif fits["frequency-position"] or fits["position-frequency"]:
        taken = "frequency-position" if fits["frequency-position"] else "position-frequency"
    else:
        raise FormatError(f"{path}: the samples are {a.shape[0]} x {a.shape[1]} but there are {n_f} frequencies "
                          f"and {n_p} positions")
    return np.asarray(a.T if taken == "frequency-position" else a, np.complex128), taken


# --- CSV -----------------------------------------------------------------------------------------------

def _parse_complex(text: str) -> complex:
    return complex(text.strip().replace(" ", "").replace("i", "j").strip("()"))


def read_csv(path: Path, names: Names) -> Sweeps:
    """One row per sample, a header row of column names (lines starting with '#' before it are
    comments; delimiter ``,`` ``;`` or tab). Columns: the frequency (Hz), the position (one column of
    rail positions, or three X,Y,Z), the sample (one complex column, ``1+2j`` or ``1+2i``, or two RE,IM
    columns) and optionally the reference range. Sweeps are the rows of one position (in order of
    first appearance), each with the same set of frequencies, sorted; a reference range must be the
    same on every row of a position."""
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise FormatError(f"{path}: not a readable CSV text file ({e})") from None
    body = [(i + 1, ln) for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")]
    if len(body) < 2:
        raise FormatError(f"{path}: a CSV of sweeps needs a header row and at least one data row")
    delim = max(",;\t", key=body[0][1].count)
    rows = list(csv.reader([ln for _, ln in body], delimiter=delim))
    header = [h.strip() for h in rows[0]]
    index = {h: k for k, h in enumerate(header)}
    lower = {h.lower(): k for k, h in enumerate(header)}

    def col(name: str) -> int | None:
        return index.get(name, lower.get(name.lower()))

    used: dict[str, str] = {}

    def pick(role: str, given: str | None, defaults: Sequence[Sequence[str]], required: bool = True) -> list[int]:
        parts = _split(given)
        if parts is None:
            parts = next((list(c) for c in defaults if all(col(n) is not None for n in c)), None)
            if parts is None:
                if required:
                    raise FormatError(f"{path}: no {role} column under the usual names "
                                      f"({', '.join('/'.join(c) for c in defaults)}) in {_list(header)}: give "
                                      f"--{role.replace('_', '-')}")
                return []
        missing = [n for n in parts if col(n) is None]
        if missing:
            raise FormatError(f"{path}: no column {', '.join(missing)} (columns: {_list(header)})")
        used[role] = ",".join(parts)
        return [col(n) for n in parts]

    d_cols = pick("data", names.data, [("s21",), *CSV_COMPLEX_PAIRS, ("data",)])
    f_cols = pick("frequency", names.frequency, [(n,) for n in DEFAULTS["frequency"]])
    p_cols = pick("position", names.position, [(n,) for n in DEFAULTS["position"]] + [("x", "y", "z"), ("x",)])
    r_cols = pick("reference_range", names.reference_range, [(n,) for n in DEFAULTS["reference_range"]],
                  required=names.reference_range is not None)
    if len(d_cols) not in (1, 2) or len(p_cols) not in (1, 3):
        raise ConfigError("for a CSV, --data names one complex column or two (RE,IM) and --position one column or "
                          "three (X,Y,Z)")
    sweeps: dict[tuple[float, ...], dict[float, complex]] = {}
    refs: dict[tuple[float, ...], float] = {}
    for (lineno, _), row in zip(body[1:], rows[1:], strict=True):
        try:
            cells = [row[k] for k in (*f_cols, *p_cols, *r_cols, *d_cols)]
            freq = float(row[f_cols[0]])
            key = tuple(float(row[k]) for k in p_cols)
            value = _parse_complex(row[d_cols[0]]) if len(d_cols) == 1 else complex(float(row[d_cols[0]]),
                                                                                   float(row[d_cols[1]]))
            ref = float(row[r_cols[0]]) if r_cols else None
        except IndexError:
            raise FormatError(f"{path}, line {lineno}: {len(row)} fields, fewer than the {len(header)} columns of the "
                              "header") from None
        except ValueError:
            raise FormatError(f"{path}, line {lineno}: not a number in {', '.join(c.strip() for c in cells)}") from None
        sweep = sweeps.setdefault(key, {})
        if freq in sweep:
            raise FormatError(f"{path}, line {lineno}: position {_fmt(key)} has frequency {freq:g} Hz twice")
        sweep[freq] = value
        if ref is not None and refs.setdefault(key, ref) != ref:
            raise FormatError(f"{path}, line {lineno}: position {_fmt(key)} has two reference ranges "
                              f"({refs[key]:g} and {ref:g} m)")
    keys = list(sweeps)
    frequency = np.array(sorted(sweeps[keys[0]]))
    for key in keys[1:]:
        if sorted(sweeps[key]) != frequency.tolist():
            raise FormatError(f"{path}: position {_fmt(key)} was measured at {len(sweeps[key])} frequencies, "
                              f"position {_fmt(keys[0])} at {frequency.size}: every position needs the same sweep")
    samples = np.array([[sweeps[k][f] for f in frequency] for k in keys], np.complex128)
    position = np.array(keys, np.float64)
    position = position[:, 0] if position.shape[1] == 1 else position
    return Sweeps(samples=samples, frequency=frequency, position=_positions(path, [position], [used["position"]]),
                  reference_range=np.array([refs[k] for k in keys]) if r_cols else None, format="csv", used=used,
                  layout="rows")


def _fmt(key: tuple[float, ...]) -> str:
    return "(" + ", ".join(f"{v:g}" for v in key) + ")" if len(key) > 1 else f"{key[0]:g} m"


# --- Touchstone ----------------------------------------------------------------------------------------

_UNITS = {"hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}
_PAIR: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
    "ri": lambda a, b: a + 1j * b,
    "ma": lambda a, b: a * np.exp(1j * np.deg2rad(b)),
    "db": lambda a, b: 10.0 ** (a / 20.0) * np.exp(1j * np.deg2rad(b)),
}


def read_touchstone(path: Path, parameter: str | None = None) -> tuple[np.ndarray, np.ndarray, str]:
    """``(frequency Hz, complex values, parameter)`` of one S-parameter of a Touchstone file [Touchstone2009].

    Ports from the extension (.s1p: S11; .s2p: S11 S21 S12 S22 in that order, the v1 convention, or the
    order of a v2 ``[Two-Port Data Order]``). Option line ``# <unit> S <format> R <ohms>`` (defaults GHz,
    MA); comments after ``!``; v2 keywords in brackets; data may wrap over lines; a 2-port v1 file's
    noise parameters (after the network data, where the frequency stops increasing) are ignored.
    Default parameter: S21 (transmission, the GB-SAR measurement) for .s2p, S11 for .s1p."""
    ports = 1 if path.suffix.lower() == ".s1p" else 2
    names = ["S11"] if ports == 1 else ["S11", "S21", "S12", "S22"]
    param = (parameter or ("S11" if ports == 1 else "S21")).upper()
    try:
        text = path.read_text(encoding="latin-1")
    except OSError as e:
        raise FormatError(f"{path}: not a readable Touchstone file ({e})") from None
    unit, fmt, seen_option = "ghz", "ma", False
    values: list[float] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("!", 1)[0].strip()
        if not line:
            continue
        if line.startswith("#"):
            if seen_option:
                continue  # the specification: only the first option line counts
            seen_option = True
            words = line[1:].lower().split()
            for k, w in enumerate(words):
                if w in _UNITS:
                    unit = w
                elif w in _PAIR:
                    fmt = w
                elif w in ("y", "z", "h", "g"):
                    raise FormatError(f"{path}, line {lineno}: {w.upper()}-parameters; only S-parameters are read")
                elif w == "r" or (k and words[k - 1] == "r") or w == "s":
                    continue
                else:
                    raise FormatError(f"{path}, line {lineno}: unknown option '{w}' in the option line {raw.strip()!r}")
            continue
        if line.startswith("["):
            key = line.lower()
            if key.startswith("[two-port data order]") and "12_21" in key:
                names = ["S11", "S12", "S21", "S22"]
            if key.startswith(("[end]", "[noise data]")):
                break
            continue
        try:
            values.extend(float(t) for t in line.split())
        except ValueError:
            raise FormatError(f"{path}, line {lineno}: not a number in {raw.strip()!r}") from None
    if param not in names:
        raise ConfigError(f"{path}: a {ports}-port file holds {', '.join(names)}, not {param}")
    group = 1 + 2 * ports * ports
    n = len(values) // group
    table = np.asarray(values[:n * group], np.float64).reshape(n, group)
    stop = np.flatnonzero(np.diff(table[:, 0]) <= 0)  # v1 noise data follow with restarting frequencies
    if stop.size:
        table = table[:stop[0] + 1]
    elif len(values) % group:
        raise FormatError(f"{path}: {len(values)} numbers do not make whole lines of {group} (frequency and "
                          f"{ports * ports} complex S-parameters)")
    if table.shape[0] < 1:
        raise FormatError(f"{path}: no network data")
    k = names.index(param)
    return table[:, 0] * _UNITS[unit], _PAIR[fmt](table[:, 1 + 2 * k], table[:, 2 + 2 * k]), param


def _rail_positions(spec: str | None, n: int) -> np.ndarray:
    """Touchstone positions: ``START:STEP`` or a comma list of n numbers (m)."""
    if spec is None:
        raise ConfigError("Touchstone files carry no antenna position: give --position START:STEP (m, one stop per "
                          "file in the order given) or a comma list of the positions")
    try:
        if ":" in spec:
            start, step = (float(t) for t in spec.split(":"))
            return start + step * np.arange(n)
        pos = np.array([float(t) for t in spec.split(",")])
    except ValueError:
        raise ConfigError(f"--position for Touchstone files is START:STEP or a comma list of numbers (m), not "
                          f"{spec!r}") from None
    if pos.size != n:
        raise ConfigError(f"--position lists {pos.size} positions for {n} Touchstone files")
    return pos


def _touchstone_files(paths: Sequence[Path], names: Names) -> Sweeps:
    if names.reference_range is not None or names.frequency is not None or names.layout != "auto":
        raise ConfigError("Touchstone files hold their frequencies and one sweep per file: --frequency, "
                          "--reference-range and --layout do not apply")
    rows, freq0, param = [], None, ""
    for p in paths:
        f, s, param = read_touchstone(p, names.data)
        if freq0 is None:
            freq0 = f
        elif f.shape != freq0.shape or not np.allclose(f, freq0, rtol=1e-9, atol=0):
            raise FormatError(f"{p}: its {f.size} frequencies differ from the {freq0.size} of {paths[0]}")
        rows.append(s)
    position = _rail_positions(names.position, len(paths))
    if not np.all(np.isfinite(position)):
        raise ConfigError("--position gives a non-finite position")
    return Sweeps(samples=np.array(rows), frequency=freq0, position=position, reference_range=None,
                  format="touchstone", used={"data": param, "position": names.position or ""},
                  layout="one file per position")


# --- several files -> one set of sweeps -> a scan ------------------------------------------------------

def read_sweeps(paths: Sequence[str | Path], names: Names = Names()) -> Sweeps:
    """Read and concatenate (along positions) the sweeps of ``paths``, all of one format (module docstring)."""
    paths = [Path(p) for p in paths]
    if not paths:
        raise ConfigError("no input file")
    kinds = set()
    for p in paths:
        if p.suffix.lower() not in FORMATS:
            raise FormatError(f"{p}: unknown sweep format '{p.suffix}' (use .mat, .npz, .npy, .csv, .s1p or .s2p)")
        if not p.is_file():
            raise MissingFileError(f"{p}: no such file")
        kinds.add(FORMATS[p.suffix.lower()])
    if len(kinds) > 1:
        raise ConfigError(f"the inputs mix formats ({', '.join(sorted(kinds))}): import one format at a time")
    kind = kinds.pop()
    if kind == "touchstone":
        sw = _touchstone_files(paths, names)
    else:
        if kind == "csv" and names.layout != "auto":
            raise ConfigError("a CSV has one row per sample: --layout does not apply")
        parts = [read_csv(p, names) if kind == "csv" else _matrix_file(p, names) for p in paths]
        sw = _concatenate(paths, parts)
    return _finish(sw)


def _concatenate(paths: list[Path], parts: list[Sweeps]) -> Sweeps:
    first = parts[0]
    for p, s in zip(paths[1:], parts[1:], strict=True):
        if s.frequency.shape != first.frequency.shape or not np.array_equal(s.frequency, first.frequency):
            raise FormatError(f"{p}: its {s.frequency.size} frequencies differ from the {first.frequency.size} of "
                              f"{paths[0]}")
        if s.position.ndim != first.position.ndim:
            raise FormatError(f"{p}: {'3-D' if s.position.ndim == 2 else 'rail'} positions, but "
                              f"{'3-D' if first.position.ndim == 2 else 'rail'} ones in {paths[0]}")
        if (s.reference_range is None) != (first.reference_range is None):
            raise FormatError(f"{p}: {'no ' if s.reference_range is None else ''}reference ranges, unlike {paths[0]}")
        if s.used != first.used:
            raise FormatError(f"{p}: took {s.used}, but {first.used} in {paths[0]}: name the variables")
    layouts = sorted({s.layout for s in parts})
    if len(layouts) > 1:
        raise FormatError(f"the files' sample matrices are laid out differently ({', '.join(layouts)}): give --layout")
    refs = None if first.reference_range is None else np.concatenate([s.reference_range for s in parts])
    return Sweeps(samples=np.concatenate([s.samples for s in parts]), frequency=first.frequency,
                  position=np.concatenate([s.position for s in parts]), reference_range=refs, format=first.format,
                  used=first.used, layout=layouts[0], frequency_float32=first.frequency_float32)


def _finish(sw: Sweeps) -> Sweeps:
    """Frequencies finite and increasing (a decreasing sweep is reversed); a float32 uniform sweep made
    exactly uniform (module docstring)."""
    f = sw.frequency
    if not np.all(np.isfinite(f)):
        raise FormatError("a frequency is not finite")
    if f.size > 1 and np.all(np.diff(f) < 0):
        sw.frequency, sw.samples = f[::-1].copy(), sw.samples[:, ::-1].copy()
        sw.notes.append("frequencies decreasing in the file: reversed to increasing")
    elif f.size > 1 and not np.all(np.diff(f) > 0):
        k = int(np.flatnonzero(np.diff(f) <= 0)[0])
        raise FormatError(f"the frequencies are not strictly monotonic ({f[k]:.9g} Hz then {f[k + 1]:.9g} Hz)")
    f = sw.frequency
    if sw.frequency_float32 and f.size > 2:
        k = np.arange(f.size)
        fit = np.polyval(np.polyfit(k, f, 1), k)
        resolution = float(np.spacing(np.float32(np.abs(f).max())))
        if np.abs(f - fit).max() <= resolution:  # 1/2 ulp of rounding, plus the fit's own error
            sw.frequency = fit
            sw.notes.append(f"frequencies stored in float32, {np.abs(f - fit).max():.0f} Hz at most off a uniform "
                            f"sweep (float32 resolution {resolution:.0f} Hz): taken as the uniform sweep "
                            f"{fit[0]:.6g} Hz + k {(fit[-1] - fit[0]) / (f.size - 1):.6g} Hz")
    return sw


_POL_TOKEN = re.compile(r"(?<![a-z])(hh|hv|vh|vv)(?![a-z])", re.IGNORECASE)


def polarization_from_names(paths: Sequence[str | Path]) -> str | None:
    """The polarization every file name carries as a token (``..._HH.mat``), or None."""
    found = [_POL_TOKEN.findall(Path(p).stem) for p in paths]
    pols = {m[0].upper() for m in found if len(m) == 1}
    return pols.pop() if len(pols) == 1 and all(len(m) == 1 for m in found) else None


def to_scan(sw: Sweeps, pol: str, height_m: float = 0.0, antenna: Antenna | None = None,
            epoch_utc: str = "2000-01-01T00:00:00Z", instrument: dict[str, Any] | None = None) -> Scan:
    """The scan of ``sw``: rail positions at antenna height ``height_m``, or a 3-D track (then
    ``rail_position`` is the distance along it and ``rail_height`` its z); sweeps holding a NaN or inf
    sample are flagged (focusing skips them)."""
    if pol not in POLARIZATIONS:
        raise ConfigError(f"unknown polarization '{pol}' (use {', '.join(POLARIZATIONS)})")
    if not math.isfinite(height_m):
        raise ConfigError(f"the antenna height must be finite, got {height_m:g}")
    n = sw.samples.shape[0]
    track = sw.position.ndim == 2
    if track:
        steps = np.linalg.norm(np.diff(sw.position, axis=0), axis=1)
        rail, heights = np.r_[0.0, np.cumsum(steps)], sw.position[:, 2].copy()
    else:
        rail, heights = sw.position.copy(), np.full(n, float(height_m))
    flags = (~np.all(np.isfinite(sw.samples), axis=1)).astype(np.uint8)
    if n and flags.all():
        raise FormatError(f"every one of the {n} sweeps holds a NaN or inf sample: nothing to focus")
    return Scan(s21=sw.samples.astype(np.complex64)[None], frequency=sw.frequency, rail_position=rail,
                rail_height=heights, polarizations=(pol,), epoch_utc=epoch_utc, stop_time=np.zeros(n),
                stop_flags=flags, antenna=antenna or Antenna(), instrument=dict(instrument or {}),
                source="imported", status="complete", n_planned=n,
                antenna_position=sw.position if track else None, reference_range=sw.reference_range)
