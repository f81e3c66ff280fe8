"""Named plug-ins (focusers, Doppler centroid estimators, sensor readers), loaded lazily.

A :class:`Registry` maps a name to an object (a class or a module-level instance). Built-in entries
are given as ``"package.module:attribute"`` strings and imported only when first asked for, so that
looking up ``rd`` does not import the optical emulator. Third-party packages plug in through a
Python entry point group (like xarray's backends)::

    [project.entry-points."sarcli.focusers"]
    chirp_scaling = "mypkg.cs:ChirpScalingFocuser"

and code (a test, a notebook) through :meth:`Registry.register`. Entry points are scanned only when
a name is not built in, or when the full list is asked for.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator
from typing import Any, Generic, TypeVar

from sarcli.errors import ConfigError

T = TypeVar("T")


def _load(target: str) -> Any:
    module, _, attr = target.partition(":")
    obj = importlib.import_module(module)
    for part in attr.split(".") if attr else ():
        obj = getattr(obj, part)
    return obj


class Registry(Generic[T]):
    """Name -> plug-in object of one kind (``kind`` names it in error messages).

    ``builtins``: name -> ``"module:attribute"`` imported on first use. ``entry_point_group``: the
    ``importlib.metadata`` group scanned for third-party plug-ins.
    """

    def __init__(self, kind: str, entry_point_group: str, builtins: dict[str, str] | None = None,
                 check: Callable[[str, Any], None] | None = None):
        self.kind = kind
        self.group = entry_point_group
        self._targets: dict[str, str] = dict(builtins or {})
        self._loaded: dict[str, T] = {}
        self._scanned = False
        self._check = check

    def register(self, name: str, obj: T | str, *, replace: bool = False) -> None:
        """Add ``obj`` (or a ``"module:attribute"`` path to it) under ``name``."""
        if not replace and (name in self._loaded or name in self._targets):
            raise ConfigError(f"{self.kind} {name!r} is already registered")
        self._loaded.pop(name, None)
        self._targets.pop(name, None)
        if isinstance(obj, str):
            self._targets[name] = obj
        else:
            if self._check is not None:
                self._check(name, obj)
            self._loaded[name] = obj

    def unregister(self, name: str) -> None:
        """Remove ``name`` (tests that register a toy plug-in clean up with this)."""
        self._loaded.pop(name, None)
        self._targets.pop(name, None)

    def _scan_entry_points(self) -> None:
        if self._scanned:
            return
        self._scanned = True
        from importlib.metadata import entry_points

        for ep in entry_points(group=self.group):
            if ep.name not in self._loaded and ep.name not in self._targets:
                self._targets[ep.name] = ep.value

    def names(self) -> list[str]:
        """Every registered name (built-in, registered and from entry points), sorted."""
        self._scan_entry_points()
        return sorted(set(self._loaded) | set(self._targets))

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in self.names()

    def get(self, name: str) -> T:
        """The plug-in registered under ``name``; a one-line :class:`ConfigError` listing the known ones."""
        if name in self._loaded:
            return self._loaded[name]
        if name not in self._targets:
            self._scan_entry_points()
        if name not in self._targets:
            raise ConfigError(f"unknown {self.kind} {name!r}; known: {', '.join(self.names())}")
        obj = _load(self._targets[name])
        if self._check is not None:
            self._check(name, obj)
        self._loaded[name] = obj
        return obj

    def items(self) -> Iterator[tuple[str, T]]:
        """(name, plug-in) for every name, importing each one."""
        for name in self.names():
            yield name, self.get(name)
