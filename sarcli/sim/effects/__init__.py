"""Effect registry. Every module in this package is one effect; nothing else needs to change to add one.

An effect module defines:

- ``NAME`` (the name used in ``scene.effects``) and ``DOC`` (one line),
- optionally ``Options``: a frozen dataclass of the keys of its top-level scene table ``[NAME]``, parsed
  with :func:`sarcli.config.from_mapping` (unknown keys, wrong types and non-finite numbers are refused
  there); an effect without ``Options`` takes no table,
- ``parse(options, platform) -> params``: the checks that need several keys or the platform (``options``
  is ``None`` when the table is absent); raise ``ConfigError("NAME.key: ...")`` (the file name is added),
- optionally ``configure(ctx, params)``: switch physics on in the :class:`SimContext` before echoes,
- optionally ``apply(ctx, params, product)`` with an integer ``ORDER``: post-process the product
  (lower ORDER first: replica 10, noise 20, quantization 30).

A parameter table of an effect that is not listed is ignored (the effect list is the only switch).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Mapping
from functools import lru_cache
from types import ModuleType
from typing import Any

from sarcli.errors import ConfigError


@lru_cache(maxsize=1)
def registry() -> dict[str, ModuleType]:
    """name -> effect module, discovered in this package."""
    out = {}
    for m in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        mod = importlib.import_module(f"{__name__}.{m.name}")
        out[mod.NAME] = mod
    return out


def no_parameters(options: Any, platform: Any) -> None:
    """``parse`` of an effect without parameters."""
    return None


def switch(attribute: str):
    """``configure`` of an effect that only switches one physics flag of the SimContext on."""
    def configure(ctx: Any, params: Any) -> None:
        setattr(ctx, attribute, True)
    return configure


def known_effects() -> list[str]:
    return sorted(registry())


def parse_effects(names: list[str], doc: Mapping[str, Any], platform: Any, src: str) -> dict[str, Any]:
    """Validate the listed effect names and parse each one's parameter table (``doc``: the scene file's
    TOML, ``src`` its name for messages)."""
    from sarcli.sim.scene import table as parse_table

    reg = registry()
    params: dict[str, Any] = {}
    for name in names:
        if name not in reg:
            raise ConfigError(f"{src}: unknown effect {name!r}; known effects: {', '.join(known_effects())}")
        mod = reg[name]
        options_cls = getattr(mod, "Options", None)
        data = doc.get(name)
        options = None
        if data is not None:
            if options_cls is None:
                keys = ", ".join(data) if isinstance(data, Mapping) else repr(data)
                if not isinstance(data, Mapping) or data:
                    raise ConfigError(f"{src}: {name}: effect {name} takes no options, got {keys}")
            else:
                options = parse_table(options_cls, data, f"{src}: {name}")
        try:
            params[name] = mod.parse(options, platform)
        except ConfigError as e:
            raise e if str(e).startswith(src) else ConfigError(f"{src}: {e}") from None
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
