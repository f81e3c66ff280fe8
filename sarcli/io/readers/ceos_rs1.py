"""Reader plug-in ``ceos-rs1``: Radarsat-1 CEOS RAW (a scene folder, or a leader and a data file).

Decoding is in :mod:`sarcli.io.ceos.radarsat1` (on the generic CEOS layer :mod:`sarcli.io.ceos`); this
adapts it to the reader interface (:mod:`sarcli.io.readers`).

Sniffing: two files of which one opens with a CEOS file descriptor record, or a folder holding a
``LEA_01.001``/``DAT_01.001`` file (directly or in ``SCENE01``). A CEOS pair of another sensor is
claimed too and then refused by the Radarsat-1 checks in one line (no other CEOS reader exists yet).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.io.readers import Ingested

_log = logging.getLogger(__name__)

F3_PULSES_KNOWN = (8, 9)  # the two published readings of beam F3's pulses in flight (ISCE, ASF MapReady)


@dataclass(frozen=True)
class CeosOptions:
    """keep_partial: keep the complete lines of a truncated data file; missing: policy for missing lines
    (zero lines, repeat the previous line, keep the gap); max_gap: refuse longer gaps (lines);
    f3_pulses: pulses in flight for beam F3 (9 per ASF MapReady, 8 per ISCE)."""

    keep_partial: bool = False
    missing: str = "zero"
    max_gap: int = 200
    f3_pulses: int = 9

    def __post_init__(self) -> None:
        from sarcli.io.ceos.radarsat1.reader import MISSING_POLICIES

        if self.missing not in MISSING_POLICIES:
            raise ConfigError(f"missing-line policy {self.missing!r} is not one of {', '.join(MISSING_POLICIES)}")
        if self.max_gap < 0:
            raise ConfigError(f"max_gap must be a number of lines >= 0, got {self.max_gap}")
        if self.f3_pulses not in F3_PULSES_KNOWN:
            raise ConfigError(f"f3_pulses must be {' or '.join(map(str, F3_PULSES_KNOWN))} (pulses in flight of "
                              f"beam F3 per ISCE or ASF MapReady), got {self.f3_pulses}")


def _starts_with_file_descriptor(path: Path) -> bool:
    from sarcli.io.ceos.records import has_file_descriptor

    with open(path, "rb") as f:
        return has_file_descriptor(f.read(8))


def _scene_folder_names(folder: Path) -> bool:
    """A CEOS scene folder: it (or its SCENE01) holds a file named like a RAW leader or data file."""
    names = {"lea_01.001", "dat_01.001"}
    for sub in (folder, folder / "SCENE01", folder / "scene01"):
        if sub.is_dir() and any(p.name.lower() in names for p in sub.iterdir()):
            return True
    return False


class CeosRs1Reader:
    name = "ceos-rs1"
    description = "Radarsat-1 CEOS RAW: a scene folder (LEA_01.001 + DAT_01.001) or LEADER DATA"
    Options = CeosOptions

    def sniff(self, sources: Sequence[Path]) -> bool:
        from sarcli.io.ceos.radarsat1 import find_scene_files

        paths = [Path(s) for s in sources]
        if len(paths) == 2 and all(p.is_file() for p in paths):
            return any(_starts_with_file_descriptor(p) for p in paths)
        if len(paths) == 1 and paths[0].is_dir() and _scene_folder_names(paths[0]):
            find_scene_files(paths[0])  # an incomplete scene folder: the one-line reason
            return True
        return False

    def read(self, sources: Sequence[Path], options: CeosOptions) -> Ingested:
        from sarcli.io.ceos.radarsat1 import find_scene_files, read_ceos

        if len(sources) not in (1, 2):
            raise ConfigError("give a CEOS scene folder, or its leader and data files")
        lea, dat = find_scene_files(*sources)
        raw = read_ceos(lea, dat, keep_partial=options.keep_partial, missing=options.missing,
                        max_gap=options.max_gap, f3_pulses_in_flight=options.f3_pulses)
        x = raw.extra_attrs
        notes = []
        if x["ceos_truncated"]:
            notes.append(f"data file truncated: kept the {x['ceos_records_read']} complete lines of "
                         f"{x['ceos_records_declared']} declared")
        if x["ceos_missing_lines"]:
            notes.append(f"{x['ceos_missing_lines']} missing lines in {len(x['ceos_gaps'])} gap(s): "
                         f"policy {options.missing}")
        _log.debug("%s: beam %s, %d lines x %d samples, %d records of %d declared", dat, x["ceos_beam_name"],
                   *raw.shape, x["ceos_records_read"], x["ceos_records_declared"])
        summary = {"beam": x["ceos_beam_name"], "missing_lines": x["ceos_missing_lines"],
                   "missing_policy": x["ceos_missing_policy"], "truncated": x["ceos_truncated"],
                   "replica_lines": len(x["ceos_replica_lines"])}
        return Ingested({"": raw}, (lea, dat), {"format": self.name, **to_mapping(options)}, notes, {"": summary})


READER = CeosRs1Reader()
