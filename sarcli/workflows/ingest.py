"""Workflow ``ingest``: raw data in a sensor's own format -> raw product(s) (HDF5).

The sensor reader is found by sniffing the sources (:func:`sarcli.io.readers.find_reader`) or named
(``format``); ``options`` are the reader's own (its ``Options`` dataclass, e.g. ``missing = "repeat"`` for
CEOS). A reader that finds several data sets in one input (swaths, polarizations) returns them by name;
each becomes its own product:

- ``output`` ending in ``.h5``/``.hdf5``: ``STEM_NAME.h5`` next to it (``raw.h5`` -> ``raw_S3_VV.h5``);
- any other ``output``: a folder (created; its parent must exist) holding ``NAME.h5``.

A single data set is written to ``output`` itself. Nothing is ever written to the inputs: an output that
is one of them (or a file inside a source folder) is refused before any work.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from sarcli.config import from_mapping, to_mapping
from sarcli.errors import ConfigError
from sarcli.workflows import base

_log = logging.getLogger(__name__)

H5_SUFFIXES = (".h5", ".hdf5")


@dataclass(frozen=True)
class Config:
    """sources: the input paths (a scene folder, LEADER DATA, DATA.mat PARAMS.mat, ...); output: the raw
    product (or, for several data sets, see the module docstring); format: a reader name (default: found
    by sniffing); options: the reader's options; compression: HDF5 compression of the echo."""

    sources: tuple[Path, ...]
    output: Path
    format: str | None = None
    options: dict[str, Any] = field(default_factory=dict)
    compression: Literal["auto", "gzip", "lzf", "none"] | None = "auto"

    def __post_init__(self) -> None:
        if not self.sources:
            raise ConfigError("give LEADER DATA, a CEOS scene folder, DATA.mat PARAMS.mat, or any input a "
                              "reader recognises (sarcli ingest --help lists the formats)")


@dataclass
class Report(base.Report):
    """format: the reader used; products: one summary per product written (output, shape, PRF, ...);
    notes: what the reader reported (truncation, missing lines)."""

    format: str
    products: list[dict[str, Any]]
    notes: list[str]

    def to_dict(self) -> dict[str, Any]:
        """One product: its summary (plus format and notes); several: ``{format, notes, outputs, products}``."""
        d = super().to_dict()
        if len(d["products"]) == 1:
            return {**d["products"][0], "format": d["format"], "notes": d["notes"]}
        return {"format": d["format"], "notes": d["notes"], "outputs": [p["output"] for p in d["products"]],
                "products": d["products"]}

    def lines(self) -> list[str]:
        return [f"wrote {p['output']}: {p['shape'][0]} lines x {p['shape'][1]} samples ({p['source']}), "
                f"PRF {p['prf_hz']:.3f} Hz, first range {p['first_range_m']:.2f} m" for p in self.products]


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "product"


def output_paths(output: Path, names: list[str]) -> dict[str, Path]:
    """Where each named data set goes (module docstring)."""
    if len(names) == 1:
        return {names[0]: output}
    if output.suffix.lower() in H5_SUFFIXES:
        return {n: output.with_name(f"{output.stem}_{_safe(n)}{output.suffix}") for n in names}
    return {n: output / f"{_safe(n)}.h5" for n in names}


def _input_files(sources: tuple[Path, ...]) -> list[Path]:
    """The sources, and every file inside a source folder (an output there would overwrite an input)."""
    out: list[Path] = []
    for s in sources:
        out.append(s)
        if s.is_dir():
            out.extend(p for p in s.rglob("*") if p.is_file())
    return out


def reader_options(reader: Any, options: dict[str, Any]) -> Any:
    """The reader's ``Options`` from a mapping (unknown options are refused, naming the reader's)."""
    return from_mapping(reader.Options, options, where=f"{reader.name} options")


def summary(raw: Any, output: Path | None, extra: dict[str, Any]) -> dict[str, Any]:
    """What ``sarcli ingest --json`` prints for one product."""
    n_lines, n_samples = raw.shape
    return {"output": None if output is None else str(output), "source": raw.source, "shape": [n_lines, n_samples],
            "prf_hz": raw.radar.prf_hz, "first_range_m": raw.radar.first_range_m,
            "azimuth_start_utc": raw.epoch_utc,
            "n_state_vectors": 0 if raw.orbit is None else int(raw.orbit.time.size), **extra}


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Read the sources with their reader and write the raw product(s) (module docstring)."""
    from sarcli.io.raw import write_raw
    from sarcli.io.readers import find_reader

    with base.using(provenance):
        sources = tuple(Path(s) for s in config.sources)
        output = Path(config.output)
        base.refuse_overwriting_inputs(_input_files(sources), [output], folders=[output])  # several products: a folder
        folder = output.resolve().parent
        if not folder.is_dir():
            raise ConfigError(f"output folder {folder} does not exist: create it first")
        reader = find_reader(sources, config.format)
        options = reader_options(reader, config.options)
        _log.info("reading %s with reader %s", " ".join(map(str, sources)), reader.name)
        ingested = reader.read(sources, options)
        targets = output_paths(output, list(ingested.products))
        base.refuse_overwriting_inputs(_input_files(sources) + list(ingested.inputs), targets.values())
        if len(targets) == 1 and output.is_dir():
            raise ConfigError(f"{output} is a folder: give a file name for the raw product")
        if len(targets) > 1 and output.suffix.lower() not in H5_SUFFIXES:
            if output.exists() and not output.is_dir():
                raise ConfigError(f"{output} is a file: the input holds {len(targets)} data sets; give a folder "
                                  "(or a name ending in .h5 for STEM_NAME.h5 files)")
            output.mkdir(exist_ok=True)
        products = []
        for i, (name, raw) in enumerate(ingested.products.items()):
            params = {**ingested.parameters, **({"product": name} if name else {}), "workflow": "ingest",
                      "config": {k: v for k, v in to_mapping(config).items() if k != "output"}}
            write_raw(targets[name], raw, parameters=params, inputs=ingested.inputs, compression=config.compression)
            _log.info("wrote %s (%s)", targets[name], name or "the only data set")
            products.append(summary(raw, targets[name], {**({"name": name} if name else {}),
                                                         **ingested.summaries.get(name, {})}))
            if progress is not None:
                progress("writing", i + 1, len(targets))
        return Report(format=reader.name, products=products, notes=list(ingested.notes))
