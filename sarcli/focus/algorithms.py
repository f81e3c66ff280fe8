"""Focusing algorithm registry: name -> callable ``(raw, doppler, channel=0, **knobs) -> SLC``.

``sarcli focus --algorithm NAME`` looks the name up here. Built in: ``rd`` (Range-Doppler,
:func:`sarcli.focus.rda.focus_rd`) and ``backprojection`` (:func:`sarcli.focus.bp_product.focus_bp`).
Another package plugs in without editing the focus command by providing a module
``sarcli/<package>/focus_plugin.py`` that calls :func:`register` at import; :func:`get` and
:func:`names` import every such module once.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable

import sarcli
from sarcli.errors import SarcliError

ALGORITHMS: dict[str, Callable] = {}
_plugins_loaded = False


def register(name: str, fn: Callable) -> None:
    """Make ``fn`` available as ``sarcli focus --algorithm name``."""
    ALGORITHMS[name] = fn


def _load_plugins() -> None:
    global _plugins_loaded
    if _plugins_loaded:
        return
    _plugins_loaded = True
    from sarcli.focus.bp_product import focus_bp
    from sarcli.focus.rda import focus_rd

    register("rd", focus_rd)
    register("backprojection", focus_bp)
    for mod in pkgutil.iter_modules(sarcli.__path__):
        if mod.ispkg and importlib.util.find_spec(f"sarcli.{mod.name}.focus_plugin") is not None:
            importlib.import_module(f"sarcli.{mod.name}.focus_plugin")


def names() -> list[str]:
    """Registered algorithm names."""
    _load_plugins()
    return sorted(ALGORITHMS)


def get(name: str) -> Callable:
    """The callable registered under ``name``; one-line error listing the known names otherwise."""
    _load_plugins()
    if name not in ALGORITHMS:
        raise SarcliError(f"unknown focusing algorithm {name!r}; known: {', '.join(sorted(ALGORITHMS))}")
    return ALGORITHMS[name]
