"""The focuser plug-in interface and the generic block driver every focuser shares.

A focuser is an object (registered in :data:`sarcli.focus.FOCUSERS`) with

- ``name`` (str), ``Options`` (a frozen dataclass of its knobs, built with
  :func:`sarcli.config.from_mapping`: unknown keys and wrong types are refused in one line),
  ``streams`` (True: :meth:`focus_block` reads raw lines itself through ``read_lines``, the echo is
  never held in memory; False: :meth:`plan` needs the echo in ``raw``), ``needs_doppler`` (False: the
  Doppler model is not used and not estimated);
- ``plan(raw, shape, doppler, options, terrain) -> plan``: everything that does not depend on the
  echo samples (grids, filters, the model evaluated on its time grid). The plan has
  ``output_shape`` (lines, samples), ``n_blocks`` and ``block_rows(b) -> (first, stop)``, the output
  lines of block ``b`` (consecutive, covering the image once);
- ``focus_block(plan, block_index, read_lines) -> ndarray``: the block's output lines
  (complex64, ``stop - first`` x samples); ``read_lines(a, b)`` returns raw lines [a, b) of the channel.
  A block is a pure function of (plan, block index, lines read): blocks may run in any order or in
  parallel and give the same image (the plan's ``timings`` dict only accumulates diagnostics);
- ``finish(plan) -> SLC``: the metadata (empty image), built with :meth:`sarcli.model.slc.SLC.from_raw`.

Streaming, the CLI options (``--set KEY=VALUE`` reaches any focuser's Options), SLC assembly and
writing are generic (:func:`focus_lines`, ``sarcli.workflows.focus``): a new focuser implements the
three methods and registers itself; see ``docs/focusing.md`` ("A new focuser").
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np

from sarcli.config import from_mapping
from sarcli.errors import ProductError
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC
from sarcli.model.terrain import ConstantHeight, Terrain

ReadLines = Callable[[int, int], np.ndarray]


@runtime_checkable
class FocusPlan(Protocol):
    """What the driver needs of a plan (module docstring)."""

    output_shape: tuple[int, int]
    n_blocks: int

    def block_rows(self, b: int) -> tuple[int, int]: ...


@runtime_checkable
class Focuser(Protocol):
    """A focusing algorithm (module docstring)."""

    name: str
    Options: type
    streams: bool
    needs_doppler: bool

    def plan(self, raw: RawProduct, shape: tuple[int, int], doppler: Any, options: Any,
             terrain: Terrain) -> FocusPlan: ...

    def focus_block(self, plan: Any, block_index: int, read_lines: ReadLines) -> np.ndarray: ...

    def finish(self, plan: Any) -> SLC: ...


def check_focuser(name: str, obj: Any) -> None:
    """Registry check: refuse an object that is not a focuser (one line)."""
    missing = [a for a in ("Options", "streams", "needs_doppler", "plan", "focus_block", "finish")
               if not hasattr(obj, a)]
    if missing:
        raise TypeError(f"focuser {name!r} lacks {', '.join(missing)} (see sarcli.focus.base)")


def options_for(focuser: Focuser, options: Any = None) -> Any:
    """The focuser's Options from a mapping (``None``: the defaults) or as given."""
    if isinstance(options, focuser.Options):
        return options
    return from_mapping(focuser.Options, dict(options or {}), f"focus options ({focuser.name})")


def make_plan(focuser: Focuser, raw: RawProduct, shape: tuple[int, int], doppler: Any, options: Any,
              terrain: Terrain | None) -> Any:
    """The focuser's plan (options from a mapping or as given; terrain default: 0 m)."""
    return focuser.plan(raw, shape, doppler, options_for(focuser, options), terrain or ConstantHeight(0.0))


def run_blocks(focuser: Focuser, plan: Any, read_lines: ReadLines, sink: Callable[[int, np.ndarray], None],
               on_block: Callable[[int, int], None] | None = None) -> SLC:
    """Focus every block of ``plan`` in order, ``sink(first_line, lines)`` each, then finish: the SLC
    metadata (empty image)."""
    n_out = plan.output_shape[1]
    for b in range(plan.n_blocks):
        first, stop = plan.block_rows(b)
        block = np.asarray(focuser.focus_block(plan, b, read_lines))
        if block.shape != (stop - first, n_out):
            raise ProductError(f"focuser {focuser.name} returned block {b} with shape {block.shape}, expected "
                               f"{(stop - first, n_out)}")
        sink(first, block)
        if on_block is not None:
            on_block(b + 1, plan.n_blocks)
    return focuser.finish(plan)


def focus_in_memory(focuser: Focuser, raw: RawProduct, doppler: Any = None, options: Any = None,
                    terrain: Terrain | None = None, channel: int = 0) -> SLC:
    """Focus one channel of an in-memory raw product into an in-memory SLC (tests, notebooks, ATI)."""
    echo = raw.channel(channel)
    plan = make_plan(focuser, raw, echo.shape, doppler, options, terrain)
    out = np.empty(plan.output_shape, np.complex64)

    def sink(first: int, block: np.ndarray) -> None:
        out[first:first + block.shape[0]] = block

    slc = run_blocks(focuser, plan, lambda a, b: echo[a:b], sink)
    slc.image = out
    return slc
