"""Sensor readers: raw data in a sensor's own format -> the shared model (:class:`~sarcli.model.raw.RawProduct`).

A reader is an object (usually a module-level instance) with

- ``name`` (str), ``description`` (one line for ``sarcli ingest --help``), ``Options`` (a frozen
  dataclass of its options, parsed with :func:`sarcli.config.from_mapping`);
- ``sniff(sources) -> bool``: cheap check (a few bytes or attributes) whether the list of paths
  given on the command line is this reader's format;
- ``read(sources, options) -> Ingested``: decode it, validated (``RawProduct.validate``), with the
  paths it actually read (their hashes go into the product's provenance) and status notes.

``sarcli ingest`` and ``sarcli info`` find the reader by sniffing (:func:`find_reader`), or by name
(``--format NAME``). Built-in readers are registered in :data:`READERS`; another package adds one with
an entry point in the group ``sarcli.readers``, a test with ``READERS.register(name, reader)``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from sarcli.errors import ConfigError
from sarcli.model.raw import RawProduct
from sarcli.registry import Registry


@dataclass
class Ingested:
    """What a reader returns: one or more raw products, named when there are several (e.g. one per swath
    and polarization: ``"S3_VV"``), the input files read, the options as applied, status notes."""

    products: dict[str, RawProduct]
    inputs: tuple[Path, ...]
    parameters: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

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


READERS: Registry[SensorReader] = Registry("sensor reader", "sarcli.readers", {
    "ceos-rs1": "sarcli.io.readers.ceos_rs1:READER",
    "matlab-cw": "sarcli.io.readers.matlab_cw:READER",
    "nisar-l0b": "sarcli.io.readers.nisar_l0b:READER",
}, check=_check)


def find_reader(sources: Sequence[Path], name: str | None = None) -> SensorReader:
    """The reader ``name``, or the first whose ``sniff`` accepts ``sources``; one line when none does."""
    if name is not None:
        return READERS.get(name)
    for _, reader in READERS.items():
        try:
            if reader.sniff(sources):
                return reader
        except (OSError, ValueError):
            continue
    shown = " ".join(str(s) for s in sources)
    raise ConfigError(f"{shown}: no reader recognises this input (known formats: {', '.join(READERS.names())}); "
                      "name one with --format")
