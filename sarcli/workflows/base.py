"""What every workflow shares: provenance, progress reporting, reports, and the input/output guard."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.io.provenance import Provenance, using

__all__ = ["Progress", "Provenance", "Report", "no_progress", "refuse_overwriting_inputs", "using"]

#: ``progress(label, done, total)``: called as work advances (the CLI draws a bar from it).
Progress = Callable[[str, int, int], None]


def no_progress(label: str, done: int, total: int) -> None:
    """The default progress sink: nothing."""


@dataclasses.dataclass
class Report:
    """Base of the workflows' reports: ``to_dict()`` for ``--json``, ``lines()`` for people."""

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(dataclasses.asdict(self))

    def lines(self) -> list[str]:
        return [f"{k}: {v}" for k, v in self.to_dict().items()]


def _identity(path: Path) -> tuple[str, tuple[int, int] | None]:
    p = Path(path)
    try:
        st = p.stat()
        return os.path.realpath(p), (st.st_dev, st.st_ino)
    except OSError:
        return os.path.realpath(p), None


def refuse_overwriting_inputs(inputs: Iterable[str | os.PathLike | None],
                              outputs: Iterable[str | os.PathLike | None],
                              folders: Iterable[str | os.PathLike | None] = ()) -> None:
    """Refuse, before any work, an output that is one of the inputs: the same real path (symbolic links
    resolved) or the same file under another name (a hard link: same device and inode), or an output
    given twice; and an output file that is an existing folder (``folders``: the outputs that are
    folders by design, a CEOS product, a folder of pictures). ``None`` entries are skipped. One
    :class:`ConfigError` line naming both."""
    outputs = list(outputs)
    dirs = {os.path.realpath(p) for p in folders if p is not None}
    for p in outputs:
        if p is not None and os.path.realpath(p) not in dirs and Path(p).is_dir():
            raise ConfigError(f"output {p} is an existing folder: give a file name (e.g. {Path(p) / 'out.h5'})")
    seen_in: dict[str | tuple[int, int], str | os.PathLike] = {}
    for p in inputs:
        if p is None:
            continue
        real, ident = _identity(Path(p))
        seen_in[real] = p
        if ident is not None:
            seen_in[ident] = p
    seen_out: dict[Any, Any] = {}
    for p in outputs:
        if p is None:
            continue
        real, ident = _identity(Path(p))
        for key in (real, ident):
            if key is None:
                continue
            if key in seen_in:
                raise ConfigError(f"output {p} is the input {seen_in[key]}: refusing to overwrite an input; "
                                  "choose another output name")
            if key in seen_out:
                raise ConfigError(f"outputs {seen_out[key]} and {p} are the same file: choose distinct names")
            seen_out[key] = p
