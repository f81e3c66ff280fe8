"""Reader plug-in ``sentinel1-l0``: Sentinel-1 Level-0 instrument source packets.

Sources: one measurement file (a stream of packets, ``s1?-*-raw-*.dat``), or a ``.SAFE`` folder
(every ``measurement``-level ``.dat`` that is not an ``-index.dat`` or ``-annot.dat``: one file
per polarisation; the index and annotation files are not needed and not read), or a folder of packet
files. In a folder, a file with no echo packets (noise or calibration only) is skipped with a note. Decoding is in
:mod:`sarcli.io.sentinel1`; this adapts it to the reader interface (:mod:`sarcli.io.readers`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, FormatError
from sarcli.io.readers import Ingested

SYNC = bytes.fromhex("352EF853")


@dataclass(frozen=True)
class Sentinel1Options:
    """keep_partial: drop a trailing partial packet instead of refusing a truncated file."""

    keep_partial: bool = False


def _measurement_files(source: Path) -> list[Path]:
    if source.is_dir():
        files = sorted(p for p in source.rglob("*.dat")
                       if not p.name.endswith(("-index.dat", "-annot.dat")))
        if not files:
            raise ConfigError(f"{source}: no Level-0 measurement .dat file in this folder")
        return files
    return [source]


def looks_like_packets(path: Path) -> bool:
    """Header plausibility of the first packet [S1-ISP, §3.1-3.2]: CCSDS version 0 with a secondary
    header, a length that holds the 68 header octets and is a multiple of 4, the sync marker."""
    with open(path, "rb") as f:
        head = f.read(68)
    if len(head) < 68:
        return False
    length = int.from_bytes(head[4:6], "big") + 7
    return head[0] >> 5 == 0 and (head[0] >> 3) & 1 == 1 and length >= 68 and length % 4 == 0 \
        and head[12:16] == SYNC


class Sentinel1Reader:
    name = "sentinel1-l0"
    description = "Sentinel-1 Level-0 packets: a measurement .dat file or a .SAFE folder"
    Options = Sentinel1Options

    def sniff(self, sources: Sequence[Path]) -> bool:
        if len(sources) != 1:
            return False
        source = Path(sources[0])
        if source.is_dir() and not source.name.upper().endswith(".SAFE") and not any(source.rglob("*.dat")):
            return False  # a folder of another format (a .SAFE folder without measurement files: the reason)
        files = _measurement_files(source) if source.is_dir() else [source]
        return all(p.is_file() and looks_like_packets(p) for p in files)

    def read(self, sources: Sequence[Path], options: Sentinel1Options) -> Ingested:
        from sarcli.io.sentinel1.product import NoEchoPackets, read_level0

        if len(sources) != 1:
            raise ConfigError("give one Level-0 measurement .dat file or one .SAFE folder")
        files = _measurement_files(Path(sources[0]))
        products, notes, skipped = {}, [], []
        for path in files:
            try:
                l0 = read_level0(path, allow_truncated=options.keep_partial)
            except NoEchoPackets as e:
                if len(files) == 1:
                    raise
                skipped.append(path)
                notes.append(f"{path.name}: skipped ({str(e).split(': ', 1)[1]})")
                continue
            for name, raw in l0.products.items():
                if name in products:
                    raise FormatError(f"{path}: data set {name} also comes from another file of {sources[0]}")
                products[name] = raw
            notes += [f"{path.name}: {n}" for n in l0.notes]
        if not products:
            raise FormatError(f"{sources[0]}: no echo packets in any of its {len(files)} measurement files")
        used = tuple(p for p in files if p not in skipped)
        return Ingested(products, used, {"format": self.name, **to_mapping(options)}, notes)


READER = Sentinel1Reader()
