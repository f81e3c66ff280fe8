"""Effect registry. Every module in this package is one effect; nothing else needs to change to add one.

An effect module defines:

- ``NAME`` (the name used in ``scene.effects``) and ``DOC`` (one line),
- ``parse(table, platform) -> params`` validating its optional top-level scene table ``[NAME]``
  (``table`` is ``None`` when absent); raise ``FormatError`` for bad values or an unsuitable platform,
- optionally ``configure(ctx, params)``: switch physics on in the :class:`SimContext` before echoes,
- optionally ``apply(ctx, params, product)`` with an integer ``ORDER``: post-process the product
  (lower ORDER first: replica 10, noise 20, quantization 30).

A parameter table of an effect that is not listed is ignored (the effect list is the only switch).
"""

from __future__ import annotations

import importlib
import pkgutil
from functools import lru_cache
from types import ModuleType
from typing import Any

from sarcli.errors import FormatError


@lru_cache(maxsize=1)
def registry() -> dict[str, ModuleType]:
    """name -> effect module, discovered in this package."""
    out = {}
    for m in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        mod = importlib.import_module(f"{__name__}.{m.name}")
        out[mod.NAME] = mod
    return out


def no_parameters(table: Any, platform: Any) -> None:
    """``parse`` of an effect without parameters (its table, if any, must be empty)."""
    return None


def switch(attribute: str):
    """``configure`` of an effect that only switches one physics flag of the SimContext on."""
    def configure(ctx: Any, params: Any) -> None:
        setattr(ctx, attribute, True)
    return configure


def known_effects() -> list[str]:
    return sorted(registry())


def parse_effects(names: list[str], root: Any, platform: Any) -> dict[str, Any]:
    """Validate the listed effect names and parse each one's parameter table."""
    reg = registry()
    params: dict[str, Any] = {}
    for name in reg:
        if name in root.data:
            root.used.add(name)
    for name in names:
        if name not in reg:
            raise FormatError(f"{root.src}: unknown effect {name!r}; known effects: {', '.join(known_effects())}")
        table = root.sub(name) if name in root.data else None
        try:
            params[name] = reg[name].parse(table, platform)
        except FormatError as e:
            raise e if str(e).startswith(root.src) else FormatError(f"{root.src}: {e}") from None
        if table is not None:
            table.finish()
    return params


def configure_all(ctx: Any) -> None:
    reg = registry()
    for name in ctx.scene.effects:
        fn = getattr(reg[name], "configure", None)
        if fn is not None:
            fn(ctx, ctx.scene.effect_params[name])


def apply_all(ctx: Any, product: Any) -> None:
    reg = registry()
    post = [n for n in ctx.scene.effects if hasattr(reg[n], "apply")]
    for name in sorted(post, key=lambda n: reg[n].ORDER):
        reg[name].apply(ctx, ctx.scene.effect_params[name], product)
