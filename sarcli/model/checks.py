"""The checks every product model applies to what it holds: one :class:`ProductError` line per defect.

``where`` names the product (its file name when it was read from one); ``name`` the field. Each check
returns the value it validated, converted to the type it promises (``float``, ``int``, ``str``,
``numpy.ndarray``), so a reader can build its model from the returned values. The plausibility bounds
themselves live with the models (``sarcli.model.raw``, ``sarcli.model.gbsar``); docs/products.md,
section "What sarcli refuses", lists them.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable
from typing import Any

import numpy as np

from orbit.timeutil import parse_utc
from sarcli.errors import ProductError


def number(where: str, name: str, value: Any, lo: float | None = None, hi: float | None = None,
           integer: bool = False, unit: str = "") -> float | int:
    """A finite real scalar (a bool, string or array is refused), optionally within [lo, hi]."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise ProductError(f"{where}: {name} must be a number, got {_show(value)}")
    if not np.isfinite(float(value)):
        raise ProductError(f"{where}: {name} must be finite, got {value}")
    if integer and not float(value).is_integer():
        raise ProductError(f"{where}: {name} must be an integer, got {value}")
    out: float | int = float(value)
    if integer:  # an Integral exactly (even beyond 2**53); any other Real is integer-valued here
        out = int(value) if isinstance(value, numbers.Integral) else int(out)
    if (lo is not None and out < lo) or (hi is not None and out > hi):
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        raise ProductError(f"{where}: {name} = {out:g}{' ' + unit if unit else ''} is implausible "
                           f"(expected {lo_s} .. {hi_s}{' ' + unit if unit else ''})")
    return out


def text(where: str, name: str, value: Any, choices: Iterable[str] | None = None) -> str:
    """A string (valid UTF-8), optionally one of ``choices``."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, bytes | np.bytes_):
        try:
            value = bytes(value).decode("utf-8")
        except UnicodeDecodeError:
            raise ProductError(f"{where}: {name} is not valid UTF-8 text") from None
    if not isinstance(value, str):
        raise ProductError(f"{where}: {name} must be text, got {_show(value)}")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:  # h5py hands invalid UTF-8 over as lone surrogates
        raise ProductError(f"{where}: {name} is not valid UTF-8 text") from None
    if choices is not None:
        allowed = tuple(choices)
        if value not in allowed:
            raise ProductError(f"{where}: {name} must be one of {', '.join(allowed)}, got {value!r}")
    return value


def utc(where: str, name: str, value: Any) -> str:
    """An ISO-8601 UTC time string ('2002-06-16T15:41:00Z')."""
    s = text(where, name, value)
    try:
        parse_utc(s)
    except (ValueError, OverflowError):
        raise ProductError(f"{where}: {name} = {s!r} is not an ISO-8601 UTC time") from None
    return s


def array(where: str, name: str, value: Any, kind: str = "f", ndim: int | None = None,
          shape: tuple[int | None, ...] | None = None, finite: bool = True, min_size: int = 0) -> np.ndarray:
    """A numpy array of dtype kind in ``kind`` ('f' float, 'c' complex, 'i'/'u' integer; integers are
    accepted where floats are asked), of rank ``ndim`` / ``shape`` (None = any length on that axis),
    with at least ``min_size`` elements, all finite if ``finite``."""
    a = np.asarray(value) if not isinstance(value, np.ndarray) else value
    kinds = kind + ("iu" if "f" in kind else "")
    if a.dtype.kind not in kinds:
        raise ProductError(f"{where}: {name} has dtype {a.dtype}, expected {_kind_name(kind)}")
    if ndim is not None and a.ndim != ndim:
        raise ProductError(f"{where}: {name} has {a.ndim} dimension(s), expected {ndim}")
    if shape is not None:
        if a.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, a.shape, strict=True)):
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
            raise ProductError(f"{where}: {name} has shape {a.shape}, expected {want}")
    if a.size < min_size:
        raise ProductError(f"{where}: {name} has {a.size} value(s), at least {min_size} needed")
    if finite and a.dtype.kind in "fc" and a.size and not _all_finite(a):
        raise ProductError(f"{where}: {name} contains NaN or inf ({int(np.sum(~np.isfinite(a)))} value(s))")
    return a


#: elements per slice of :func:`_all_finite` (8 MB of float32 flags at most)
FINITE_SLICE = 1 << 21


def _all_finite(a: np.ndarray, slice_elements: int = FINITE_SLICE) -> bool:
    """Whether every value of the float or complex ``a`` is finite, tested in slices of about
    ``slice_elements`` along the first axis (a full scene's echo would otherwise need a flag array of
    290 MB, written page by page: 2-4x slower)."""
    if a.dtype == np.complex64 and a.ndim and a.strides[-1] == a.itemsize:
        a = a.view(np.float32)  # the float32 test is vectorized, the complex one is not (3x)
    if a.ndim < 2:
        return bool(np.isfinite(a).all())
    rows = max(1, slice_elements // max(1, a[0].size))
    return all(bool(np.isfinite(a[i:i + rows]).all()) for i in range(0, a.shape[0], rows))


def increasing(where: str, name: str, a: np.ndarray, strict: bool = True) -> np.ndarray:
    """A 1-D array that increases (strictly, or never decreases)."""
    if a.size > 1:
        d = np.diff(a)
        ok = d > 0 if strict else d >= 0
        if not np.all(ok):
            k = int(np.argmin(ok))
            raise ProductError(f"{where}: {name} must {'increase' if strict else 'never decrease'} "
                               f"(element {k + 1} = {a[k + 1]:g} after {a[k]:g})")
    return a


def uniform(where: str, name: str, a: np.ndarray, step: float | np.ndarray, rtol: float,
            gaps: bool = False) -> np.ndarray:
    """A 1-D array whose consecutive differences equal ``step`` (scalar or one per difference) to ``rtol``.

    ``gaps``: a difference may also be a whole number k >= 2 of steps (missing samples kept as a gap),
    within ``rtol`` of one step, as long as the median difference is one step (so a step mislabelled
    by a factor of two or more is still refused)."""
    if a.size > 1:
        ratio = np.diff(a) / step
        k = np.maximum(np.round(ratio), 1.0) if gaps else np.ones_like(ratio)
        bad = ~(np.abs(ratio - k) <= rtol)
        if bad.any():
            i = int(np.argmax(bad))
            s = float(np.broadcast_to(step, ratio.shape)[i])
            raise ProductError(f"{where}: {name} is not uniform: step {i} is {ratio[i] * s:.6g}, expected "
                               f"{'a whole multiple of ' if gaps else ''}{s:.6g} within {100 * rtol:g} %")
        if gaps and not abs(float(np.median(ratio)) - 1.0) <= rtol:
            raise ProductError(f"{where}: {name} steps are {float(np.median(ratio)):.6g} times the expected "
                               f"{float(np.median(np.broadcast_to(step, ratio.shape))):.6g} (median)")
    return a


def _kind_name(kind: str) -> str:
    names = {"f": "float", "c": "complex", "i": "integer", "u": "unsigned integer", "b": "boolean"}
    return " or ".join(names.get(k, k) for k in kind)


def _show(value: Any) -> str:
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, str | bytes):
        s = repr(value)
        return f"text {s[:40]}{'...' if len(s) > 40 else ''}"
    return f"{type(value).__name__}"
