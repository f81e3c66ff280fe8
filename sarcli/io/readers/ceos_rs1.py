"""Reader plug-in ``ceos-rs1``: Radarsat-1 CEOS RAW (a scene folder, or a leader and a data file).

Decoding is in :mod:`sarcli.io.ceos`; this adapts it to the reader interface (:mod:`sarcli.io.readers`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.io.readers import Ingested

F3_PULSES_KNOWN = (8, 9)  # the two published readings of beam F3's pulses in flight (ISCE, ASF MapReady)


@dataclass(frozen=True)
class CeosOptions:
    """keep_partial: keep the complete lines of a truncated data file; missing: policy for missing lines
    (zero lines, repeat the previous line, keep the gap); max_gap: refuse longer gaps (lines);
    f3_pulses: pulses in flight for beam F3 (9 per ASF MapReady, 8 per ISCE)."""

    keep_partial: bool = False
    missing: Literal["zero", "repeat", "keep"] = "zero"
    max_gap: int = 200
    f3_pulses: int = 9

    def __post_init__(self) -> None:
        if self.max_gap < 0:
            raise ConfigError(f"max_gap must be a number of lines >= 0, got {self.max_gap}")
        if self.f3_pulses not in F3_PULSES_KNOWN:
            raise ConfigError(f"f3_pulses must be {' or '.join(map(str, F3_PULSES_KNOWN))} (pulses in flight of "
                              f"beam F3 per ISCE or ASF MapReady), got {self.f3_pulses}")


def _leader_signature(path: Path) -> bool:
    from sarcli.io.ceos.fields import CODES_FILE_DESCRIPTOR

    with open(path, "rb") as f:
        head = f.read(8)
    return len(head) == 8 and tuple(head[4:8]) == CODES_FILE_DESCRIPTOR


class CeosRs1Reader:
    name = "ceos-rs1"
    description = "Radarsat-1 CEOS RAW: a scene folder (LEA_01.001 + DAT_01.001) or LEADER DATA"
    Options = CeosOptions

    def sniff(self, sources: Sequence[Path]) -> bool:
        from sarcli.io.ceos import find_scene_files

        if len(sources) not in (1, 2):
            return False
        if len(sources) == 1 and not Path(sources[0]).is_dir():
            return False
        lea, _ = find_scene_files(*sources)
        return _leader_signature(lea)

    def read(self, sources: Sequence[Path], options: CeosOptions) -> Ingested:
        from sarcli.io.ceos import find_scene_files, read_ceos

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
        return Ingested({"": raw}, (lea, dat), {"format": self.name, **to_mapping(options)}, notes)


READER = CeosRs1Reader()
