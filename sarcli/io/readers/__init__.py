"""Sensor readers: raw data in a sensor's own format -> the shared model (:class:`~sarcli.model.raw.RawProduct`).

A reader is an object (usually a module-level instance) with

- ``name`` (str), ``description`` (one line for ``sarcli ingest --help``), ``Options`` (a frozen
  dataclass of its options, parsed with :func:`sarcli.config.from_mapping`);
- ``sniff(sources) -> bool``: cheap check (a few bytes or attributes) whether the list of paths
  given on the command line is this reader's format; it may raise a one-line
  :class:`~sarcli.errors.SarcliError` when the input is recognisably its format but incomplete
  (shown when no other reader accepts the input);
- ``read(sources, options) -> Ingested``: decode it into one or more raw products (validated again when
  written, ``sarcli.io.raw.write_raw``), with the paths it actually read (their hashes go into the
  product's provenance) and status notes.

``sarcli ingest`` and ``sarcli info`` find the reader by sniffing (:func:`find_reader`), or by name
(``--format NAME``). Built-in readers are registered in :data:`READERS`; another package adds one with
an entry point in the group ``sarcli.readers``, a test with ``READERS.register(name, reader)``. The
recipe, exercised by ``tests/io/test_toy_reader.py``: ``docs/ingest.md``, "A new sensor reader".
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from sarcli.errors import ConfigError, MissingFileError, ProductError, SarcliError
from sarcli.model.raw import RawProduct
from sarcli.registry import Registry


@dataclass
class Ingested:
    """What a reader returns: one or more raw products, named when there are several (e.g. one per swath
    and polarization: ``"S3_VV"``; a single product is named ``""``), the input files read, the options
    as applied (stored in the products' ``parameters``), status notes (one line each, shown to the user),
    and per product the reader's own summary keys for ``sarcli ingest --json`` (e.g. the CEOS beam)."""

    products: dict[str, RawProduct]
    inputs: tuple[Path, ...]
    parameters: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    summaries: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def product(self) -> RawProduct:
        """The single product (a reader that found several must be asked for one by name)."""
        if len(self.products) != 1:
            raise ConfigError(f"the input holds {len(self.products)} data sets ({', '.join(self.products)}): "
                              "choose one, or give an output folder for all of them")
        return next(iter(self.products.values()))


@runtime_checkable
class SensorReader(Protocol):
    """The reader interface (module docstring)."""

    name: str
    description: str
    Options: type

    def sniff(self, sources: Sequence[Path]) -> bool: ...

    def read(self, sources: Sequence[Path], options: Any) -> Ingested: ...


def _check(name: str, obj: Any) -> None:
    for attr in ("name", "description", "Options", "sniff", "read"):
        if not hasattr(obj, attr):
            raise ConfigError(f"reader {name!r} lacks {attr!r}: see sarcli.io.readers")


_log = logging.getLogger(__name__)

READERS: Registry[SensorReader] = Registry("sensor reader", "sarcli.readers", {
    "ceos-rs1": "sarcli.io.readers.ceos_rs1:READER",
    "matlab-cw": "sarcli.io.readers.matlab_cw:READER",
    "sentinel1-l0": "sarcli.io.readers.sentinel1:READER",
    "nisar-l0b": "sarcli.io.readers.nisar_l0b:READER",
}, check=_check)


def find_reader(sources: Sequence[Path], name: str | None = None) -> SensorReader:
    """The reader ``name``, or the one whose ``sniff`` accepts ``sources``; one line when none does.

    ``sniff`` answers True (mine), False (not mine), or raises a :class:`~sarcli.errors.SarcliError`
    when the input looks like its format but cannot be read (a scene folder without its data file, a
    leader without its signal file): that message is the answer when no reader accepts the input.
    """
    for s in sources:
        if not Path(s).exists():
            raise MissingFileError(f"{s}: no such file")
    if name is not None:
        return READERS.get(name)
    diagnoses: list[tuple[str, SarcliError]] = []
    for reader_name, reader in READERS.items():
        try:
            accepted = reader.sniff(sources)
        except SarcliError as e:
            diagnoses.append((reader_name, e))
            continue
        except (OSError, ValueError) as e:
            _log.debug("reader %s could not sniff %s: %s", reader_name, sources, e)
            continue
        if accepted:
            _log.debug("reader %s recognises %s", reader_name, [str(s) for s in sources])
            return reader
    shown = " ".join(str(s) for s in sources)
    if len(diagnoses) == 1:
        raise diagnoses[0][1]
    why = "".join(f"; {n}: {d}" for n, d in diagnoses)
    raise ProductError(f"{shown}: no reader recognises this input (known formats: {', '.join(READERS.names())}"
                       f"{why}); name one with --format")
