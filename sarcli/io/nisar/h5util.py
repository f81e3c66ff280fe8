"""Conventions shared by the NISAR L0B and RSLC layouts, and one-line errors for bad files.

- Band root: ``/science/LSAR`` (L-band) or ``/science/SSAR`` (S-band); a file holds one of them.
- Times: float64 seconds after an epoch given in the dataset's ``units`` attribute, written
  ``seconds since YYYY-MM-DD HH:MM:SS`` or ``seconds since YYYY-MM-DDTHH:MM:SS[.fraction]``
  (ISCE3 writes both spellings, and up to nine fraction digits: the NISAR writers require a whole-
  second epoch). :func:`time_axis` returns the times relative to the whole-second epoch, the
  fraction added to the values, so nanoseconds are not lost to Python's microsecond datetimes.
- Strings: fixed-length byte strings, scalars or 1-D lists (``listOfPolarizations``).
- Complex images: ``complex64`` or NISAR's ``complex32`` (a compound of two float16, fields ``r`` and
  ``i``), decoded to complex64.

Every malformed item is reported as :class:`~sarcli.errors.FormatError` in one line naming the file
and the HDF5 path.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import os
import re
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np

from sarcli.errors import FormatError, MissingFileError, ProductError

BANDS = ("LSAR", "SSAR")
_UNITS = re.compile(r"^\s*seconds?\s+since\s+(\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2}):(\d{2})(\.\d+)?\s*(Z|UTC)?\s*$",
                    re.IGNORECASE)
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def is_hdf5(path: str | os.PathLike) -> bool:
    """True when ``path`` is a file starting with the HDF5 signature (at offset 0: h5py's default)."""
    p = Path(path)
    if not p.is_file():
        return False
    with open(p, "rb") as fh:
        return fh.read(8) == HDF5_SIGNATURE


@contextlib.contextmanager
def open_h5(path: str | os.PathLike) -> Iterator[h5py.File]:
    """Open an existing HDF5 file read-only; a missing, unreadable or truncated file is one line."""
    p = Path(path)
    if not p.exists():
        raise MissingFileError(f"{p}: no such file")
    try:
        f = h5py.File(p, "r")
    except OSError as e:
        raise FormatError(f"{p}: not a readable HDF5 file ({_short(e)})") from None
    try:
        yield f
    except (OSError, RuntimeError, KeyError, ValueError) as e:
        # h5py raises these when a damaged file cannot be read (truncated chunks, bad object headers,
        # corrupt symbol tables, failing filters): the file, not the caller, is at fault. Only errors
        # raised inside h5py are converted; a sarcli error (a ValueError) passes unchanged.
        if isinstance(e, ProductError) or not _raised_in_h5py(e):
            raise
        raise FormatError(f"{p}: damaged HDF5 file ({_short(e)})") from None
    finally:
        f.close()


def _raised_in_h5py(e: BaseException) -> bool:
    tb = e.__traceback__
    last = None
    while tb is not None:
        last = tb.tb_frame.f_code.co_filename
        tb = tb.tb_next
    return last is not None and "h5py" in Path(last).parts  # .../site-packages/h5py/... or h5py/h5g.pyx


def _short(e: BaseException) -> str:
    return " ".join(str(e).split())[:160] or type(e).__name__


def band_root(f: h5py.File, path: str | os.PathLike, product: str | tuple[str, ...]) -> tuple[str, h5py.Group, str]:
    """(band ``"L"``/``"S"``, the ``/science/XSAR`` group, the product group name found).

    ``product``: accepted product group names (``"RRSD"``, or ``("RSLC", "SLC")`` - early RSLCs used
    ``SLC``). Refuses, in one line, a file that is not a NISAR product of that kind."""
    names = (product,) if isinstance(product, str) else tuple(product)
    sci = f.get("science")
    if not isinstance(sci, h5py.Group):
        raise FormatError(f"{path}: not a NISAR product (no /science group)")
    found = [b for b in BANDS if isinstance(sci.get(b), h5py.Group)]
    if not found:
        raise FormatError(f"{path}: not a NISAR product (no /science/LSAR or /science/SSAR)")
    for b in found:
        g = sci[b]
        for name in names:
            if isinstance(g.get(name), h5py.Group):
                return b[0], g, name
    raise FormatError(f"{path}: not a NISAR {names[0]} product (/science/{found[0]} holds "
                      f"{', '.join(sorted(sci[found[0]].keys())) or 'nothing'})")


def need(group: h5py.Group, name: str, path: str | os.PathLike, kind: str = "dataset") -> h5py.Dataset | h5py.Group:
    """``group[name]`` or a one-line :class:`FormatError` naming the missing HDF5 path."""
    obj = group.get(name)
    want = h5py.Dataset if kind == "dataset" else h5py.Group
    if not isinstance(obj, want):
        what = "missing" if obj is None else f"not a {kind}"
        raise FormatError(f"{path}: incomplete NISAR product: {group.name}/{name} {what}")
    return obj


def number(group: h5py.Group, name: str, path: str | os.PathLike, positive: bool = False) -> float:
    """A finite scalar dataset as float (``positive``: also > 0)."""
    ds = need(group, name, path)
    try:
        v = float(np.asarray(ds[()]).reshape(-1)[0])
    except (TypeError, ValueError, IndexError):
        raise FormatError(f"{path}: {ds.name} is not a number") from None
    if not np.isfinite(v) or (positive and v <= 0):
        raise FormatError(f"{path}: {ds.name} = {v} is not a {'positive ' if positive else ''}finite number")
    return v


def member_names(group: h5py.Group) -> list[str]:
    """The names of a group's members, sorted; a name that is not UTF-8 (h5py gives it as bytes) names no
    member of the layout, so it is left out (sorting bytes with str would fail)."""
    return sorted(n for n in group if isinstance(n, str))


def text(obj: h5py.Dataset | bytes | str | np.ndarray) -> str:
    """A string dataset/attribute value (scalar, or the first element of a list), stripped."""
    v = obj[()] if isinstance(obj, h5py.Dataset) else obj
    if isinstance(v, np.ndarray):
        v = v.reshape(-1)[0] if v.size else b""
    if isinstance(v, bytes | np.bytes_):
        v = bytes(v).decode("utf-8", errors="replace")
    return str(v).strip().rstrip("\x00")


def text_list(ds: h5py.Dataset) -> list[str]:
    """A list-of-strings dataset (or a scalar string) as a list of str."""
    v = np.atleast_1d(ds[()])
    return [text(x) for x in v.reshape(-1)]


def optional_text(group: h5py.Group, name: str, default: str = "") -> str:
    obj = group.get(name)
    return text(obj) if isinstance(obj, h5py.Dataset) else default


def parse_epoch(units: str, where: str) -> tuple[str, float]:
    """(whole-second epoch as ISO-8601 UTC ``...Z``, fraction of a second) from a ``units`` string."""
    m = _UNITS.match(units or "")
    if m is None:
        raise FormatError(f"{where}: time units {units!r} are not 'seconds since YYYY-MM-DD HH:MM:SS'")
    y, mo, d, hh, mm, ss = (int(x) for x in m.groups()[:6])
    try:
        t = _dt.datetime(y, mo, d, hh, mm, ss, tzinfo=_dt.UTC)
    except ValueError:
        raise FormatError(f"{where}: time units {units!r} hold an impossible date") from None
    frac = float(m.group(7)) if m.group(7) else 0.0
    return t.strftime("%Y-%m-%dT%H:%M:%S.%fZ"), frac


def time_axis(ds: h5py.Dataset, path: str | os.PathLike) -> tuple[str, np.ndarray]:
    """(epoch, float64 times after it) of a 1-D time dataset with a ``units`` epoch; refuses NaN/inf."""
    if ds.ndim != 1:
        raise FormatError(f"{path}: {ds.name} must be 1-D, has shape {ds.shape}")
    epoch, frac = parse_epoch(text(ds.attrs.get("units", b"")), f"{path}: {ds.name}")
    t = np.asarray(ds[()], np.float64) + frac
    if not np.all(np.isfinite(t)):
        raise FormatError(f"{path}: {ds.name} holds NaN or inf times")
    return epoch, t


def seconds_between(later: str, earlier: str) -> float:
    """``later - earlier`` in seconds (ISO-8601 UTC strings, microsecond resolution)."""
    from orbit.timeutil import parse_utc

    d = parse_utc(later) - parse_utc(earlier)
    return d.days * 86400.0 + d.seconds + d.microseconds * 1e-6


def whole_second_epoch(epoch: str) -> tuple[str, float]:
    """(the epoch truncated to whole seconds, the seconds removed): NISAR epochs are whole seconds."""
    from orbit.timeutil import format_utc, parse_utc

    t = parse_utc(epoch)
    base = t.replace(microsecond=0)
    return format_utc(base), t.microsecond * 1e-6


def units_since(epoch: str) -> str:
    """``seconds since YYYY-MM-DDTHH:MM:SS`` for a whole-second epoch (ISCE3's writer spelling)."""
    from orbit.timeutil import parse_utc

    t = parse_utc(epoch)
    if t.microsecond:
        raise ValueError(f"NISAR time units need a whole-second epoch, got {epoch}")
    return "seconds since " + t.strftime("%Y-%m-%dT%H:%M:%S")


def complex_rows(ds: h5py.Dataset, start: int, stop: int) -> np.ndarray:
    """Rows ``start:stop`` of a complex image dataset as complex64 (complex64/128 or complex32 pairs)."""
    dt = ds.dtype
    block = ds[start:stop]
    if dt.kind == "c":
        return block.astype(np.complex64, copy=False)
    names = dt.names or ()
    if set(names) >= {"r", "i"} and dt["r"].kind == "f" and dt["i"].kind == "f":
        out = np.empty(block.shape, np.complex64)
        out.real = block["r"]
        out.imag = block["i"]
        return out
    raise FormatError(f"{ds.file.filename}: {ds.name} has dtype {dt}, not complex (complex64 or float16 pairs r, i)")
