"""Typed, frozen configurations: built from a mapping (a TOML table, CLI options), checked in one place.

Every workflow, reader, focuser and estimator declares its options as a frozen dataclass. This module
turns a plain mapping into one, refusing in one line (:class:`~sarcli.errors.ConfigError`) an
unknown key (the message lists the known ones), a value of the wrong type or outside a ``Literal``'s
choices; a dataclass's own ``__post_init__`` adds the checks that need several fields. The inverse,
:func:`to_mapping`, gives the JSON/TOML-able form that products store as their ``parameters``, so
that ``sarcli run`` can re-run a product's configuration.

Supported field types: ``bool``, ``int``, ``float`` (an int is accepted), ``str``, ``Path``,
``Literal[...]``, ``X | None``, ``tuple[T, ...]``, ``tuple[A, B]``, ``list[T]``, ``dict[str, T]``,
nested dataclasses (from a sub-table) and ``Any``.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

from sarcli.errors import ConfigError

T = TypeVar("T")


def load_toml(path: str | Path) -> dict[str, Any]:
    """Parse a TOML file; a missing, non-UTF-8 or malformed file is one :class:`ConfigError` line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{p}: no such file") from None
    except UnicodeDecodeError:
        raise ConfigError(f"{p}: not UTF-8 text") from None
    except OSError as e:
        raise ConfigError(f"{p}: cannot read ({e.strerror})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{p}: not valid TOML ({e})") from None


def _type_name(tp: Any) -> str:
    if isinstance(tp, type):
        return tp.__name__
    return str(tp).replace("typing.", "").replace("pathlib.", "")


def _coerce(value: Any, tp: Any, where: str) -> Any:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if tp is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        errors = []
        for a in args:
            if a is type(None):
                continue
            try:
                return _coerce(value, a, where)
            except ConfigError as e:
                errors.append(str(e))
        raise ConfigError(errors[0] if len(errors) == 1 else
                          f"{where}: expected {_type_name(tp)}, got {value!r}")
    if origin is typing.Literal:
        if value not in args:
            raise ConfigError(f"{where}: {value!r} is not one of {', '.join(map(repr, args))}")
        return value
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        if isinstance(value, tp):
            return value
        if not isinstance(value, Mapping):
            raise ConfigError(f"{where}: expected a table of {tp.__name__} options, got {value!r}")
        return from_mapping(tp, value, where)
    if origin in (tuple, list):
        if isinstance(value, str | bytes) or not isinstance(value, list | tuple):
            raise ConfigError(f"{where}: expected a list, got {value!r}")
        if origin is tuple and args and not (len(args) == 2 and args[1] is Ellipsis):
            if len(value) != len(args):
                raise ConfigError(f"{where}: expected {len(args)} values, got {len(value)}")
            return tuple(_coerce(v, a, f"{where}[{i}]") for i, (v, a) in enumerate(zip(value, args, strict=True)))
        item = args[0] if args else Any
        out = [_coerce(v, item, f"{where}[{i}]") for i, v in enumerate(value)]
        return tuple(out) if origin is tuple else out
    if origin is dict:
        if not isinstance(value, Mapping):
            raise ConfigError(f"{where}: expected a table, got {value!r}")
        vt = args[1] if len(args) == 2 else Any
        return {str(k): _coerce(v, vt, f"{where}.{k}") for k, v in value.items()}
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{where}: expected true or false, got {value!r}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int | float) or (
                isinstance(value, float) and not (math.isfinite(value) and value.is_integer())):
            raise ConfigError(f"{where}: expected an integer, got {value!r}")
        if not -(2**63) <= int(value) < 2**63:  # seeds, counts: stored as int64 (numpy, HDF5)
            raise ConfigError(f"{where}: {int(value)} does not fit a 64-bit integer")
        return int(value)
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"{where}: expected a number, got {value!r}")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where}: expected a string, got {value!r}")
        return value
    if tp is Path:
        if not isinstance(value, str | Path):
            raise ConfigError(f"{where}: expected a path, got {value!r}")
        return Path(value)
    if isinstance(tp, type) and isinstance(value, tp):
        return value
    raise ConfigError(f"{where}: expected {_type_name(tp)}, got {value!r}")


def from_mapping(cls: type[T], data: Mapping[str, Any], where: str = "config") -> T:
    """An instance of the dataclass ``cls`` from ``data`` (module docstring); ``where`` names the source
    in messages (e.g. ``focus.toml [focus]``)."""
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where}: expected a table of options, got {data!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}  # type: ignore[arg-type]
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ConfigError(f"{where}: unknown option(s) {', '.join(unknown)}; known: {', '.join(sorted(fields))}")
    kwargs = {}
    for name, value in data.items():
        kwargs[name] = _coerce(value, hints[name], f"{where}.{name}" if where else name)
    missing = [n for n, f in fields.items() if n not in kwargs and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if missing:
        raise ConfigError(f"{where}: missing required option(s) {', '.join(missing)}")
    return cls(**kwargs)


def replace(obj: T, where: str = "config", **changes: Any) -> T:
    """``dataclasses.replace`` with the same checks as :func:`from_mapping` (``None`` values are kept)."""
    return from_mapping(type(obj), {**to_mapping(obj, keep_none=True), **changes}, where)


def to_mapping(obj: Any, keep_none: bool = False) -> Any:
    """The plain form of a configuration (dataclasses as dicts, paths as strings, tuples as lists);
    ``None`` fields are dropped unless ``keep_none`` (TOML has no null)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out = {}
        for f in dataclasses.fields(obj):
            v = getattr(obj, f.name)
            if v is None and not keep_none:
                continue
            out[f.name] = to_mapping(v, keep_none)
        return out
    if isinstance(obj, Mapping):
        return {str(k): to_mapping(v, keep_none) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_mapping(v, keep_none) for v in obj]
    if isinstance(obj, Path):
        return str(obj)
    return obj


def positive(where: str, value: float | int | None, allow_zero: bool = False) -> None:
    """Refuse a non-finite or non-positive number (``None`` passes: "not given")."""
    if value is None:
        return
    ok = math.isfinite(value) and (value >= 0 if allow_zero else value > 0)
    if not ok:
        raise ConfigError(f"{where} must be {'>= 0' if allow_zero else 'positive'} and finite, got {value}")
