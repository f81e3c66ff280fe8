"""CEOS field primitives: the 12-byte record header, ASCII fields, big-endian binary fields.

Byte positions in this package are given as in the specification (RSI-GS-026 Rev 2/0, "[S]"):
**1-based and inclusive**. ``ascii_field(rec, 69, 100)`` is the 32 bytes at 0-based offsets 68..99.

ASCII numbers (``In``, ``Fw.d``, ``Ew.d``, ``Dw.d``) are right-justified and blank padded. A blank
field means "missing" (RAW products leave many fields blank) and decodes to ``None``, never to 0;
anything else that is not a number is a :class:`FormatError` naming the field.

Writing: reals are written with as many digits as fit in the field width (``format_real``), not
just the ``d`` decimals of the descriptor. A Fortran ``Fw.d``/``Ew.d`` read honours an explicit
decimal point, so the field stays readable as specified while a round trip keeps ~13 significant
digits instead of 7 decimals (e.g. a wavelength of 0.05656461251 m keeps its last digits).
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass

from sarcli.errors import FormatError

HEADER_BYTES = 12

# (first sub-type, record type, second sub-type, third sub-type) codes [S], see docs/ceos-radarsat-raw.md
CODES_VOLUME_DESCRIPTOR = (192, 192, 18, 18)
CODES_FILE_POINTER = (219, 192, 18, 18)
CODES_TEXT = (18, 63, 18, 18)
CODES_FILE_DESCRIPTOR = (63, 192, 18, 18)
CODES_DATA_SET_SUMMARY = (18, 10, 18, 20)
CODES_PLATFORM_POSITION = (18, 30, 18, 20)
CODES_SIGNAL_DATA = (50, 10, 18, 20)

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([EeDd][+-]?\d+)?$")
_INTEGER = re.compile(r"^[+-]?\d+$")


@dataclass(frozen=True)
class RecordHeader:
    """The 12 bytes that start every CEOS record; ``length`` counts the whole record."""

    sequence: int
    codes: tuple[int, int, int, int]
    length: int


def parse_header(buf: bytes | memoryview, offset: int = 0) -> RecordHeader:
    """Decode the record header at ``offset``: B4 sequence, 4 x B1 type codes, B4 length (big-endian)."""
    seq, c1, c2, c3, c4, length = struct.unpack_from(">I4BI", buf, offset)
    return RecordHeader(seq, (c1, c2, c3, c4), length)


def pack_header(sequence: int, codes: tuple[int, int, int, int], length: int) -> bytes:
    """The 12-byte header of a record with the given sequence number, type codes and total length."""
    return struct.pack(">I4BI", sequence, *codes, length)


def ascii_field(rec: bytes | memoryview, first: int, last: int) -> str:
    """The text of bytes ``first..last`` (1-based, inclusive), stripped of blanks."""
    raw = bytes(rec[first - 1:last])
    return raw.decode("ascii", errors="replace").strip()


def _where(name: str, first: int, last: int, source: str) -> str:
    return f"{source}: field '{name}' (bytes {first}-{last})"


def _parse_number(rec, first: int, last: int, name: str, source: str, pattern: re.Pattern, what: str,
                  convert):
    s = ascii_field(rec, first, last)
    if not s:
        return None
    if not pattern.match(s):
        raise FormatError(f"{_where(name, first, last, source)} holds {s!r}, not {what}")
    return convert(s)


def parse_int(rec: bytes | memoryview, first: int, last: int, name: str, source: str = "CEOS") -> int | None:
    """Decode an ``In`` field; blank -> ``None``; garbage -> :class:`FormatError`."""
    return _parse_number(rec, first, last, name, source, _INTEGER, "an integer", int)


def parse_real(rec: bytes | memoryview, first: int, last: int, name: str, source: str = "CEOS") -> float | None:
    """Decode an ``F``/``E``/``D`` field (Fortran ``D`` exponents accepted); blank -> ``None``."""
    return _parse_number(rec, first, last, name, source, _NUMBER, "a number",
                         lambda s: float(s.replace("D", "E").replace("d", "e")))


def require_value(value: float | int | None, name: str, first: int, last: int, source: str = "CEOS"):
    """``value`` unless it is ``None`` (a blank field), in which case a one-line :class:`FormatError`."""
    if value is None:
        raise FormatError(f"{_where(name, first, last, source)} is blank; the file is incomplete")
    return value


def format_int(v: int, width: int) -> bytes:
    """An ``In`` field: right-justified decimal integer."""
    s = str(int(v))
    if len(s) > width:
        raise FormatError(f"integer {v} does not fit a {width}-character CEOS field")
    return s.rjust(width).encode("ascii")


def format_text(s: str, width: int) -> bytes:
    """An ``An`` field: left-justified, blank padded (truncated to ``width``)."""
    return s[:width].ljust(width).encode("ascii")


def format_real(v: float, width: int, style: str = "F") -> bytes:
    """An ``F``, ``E`` or ``D`` field with as many digits as fit in ``width`` (see module docstring)."""
    for digits in range(width - 2, -1, -1):
        if style == "F":
            s = f"{v:.{digits}f}"
        else:
            s = f"{v:.{digits}E}"
            if style == "D":
                s = s.replace("E", "D")
        if len(s) <= width:
            return s.rjust(width).encode("ascii")
    raise FormatError(f"value {v} does not fit a {width}-character CEOS field")


def put(rec: bytearray, first: int, field: bytes) -> None:
    """Write ``field`` at 1-based byte ``first`` of ``rec`` (its length sets the last byte)."""
    rec[first - 1:first - 1 + len(field)] = field


def blank_record(sequence: int, codes: tuple[int, int, int, int], length: int) -> bytearray:
    """A record of ``length`` bytes: its header, then blanks (the CEOS 'missing' value for ASCII)."""
    rec = bytearray(b" " * length)
    rec[:HEADER_BYTES] = pack_header(sequence, codes, length)
    return rec


def file_descriptor(length: int, file_number: int, file_name: str, software_id: str) -> bytearray:
    """The common head of a file descriptor record (record 1 of every CEOS file): ASCII flag,
    ``CEOS-SAR-CCT``, software id, file number (45-48), file name (49-64), ``FSEQ`` (65-68)."""
    rec = blank_record(1, CODES_FILE_DESCRIPTOR, length)
    put(rec, 13, b"A ")
    put(rec, 17, format_text("CEOS-SAR-CCT", 12))
    put(rec, 33, format_text(software_id, 12))
    put(rec, 45, format_int(file_number, 4) + format_text(file_name, 16) + format_text("FSEQ", 4))
    return rec
