"""Walking a CEOS file record by record, and the file descriptor record that opens every CEOS file.

A CEOS file is a sequence of records, each starting with the 12-byte header of
:mod:`sarcli.io.ceos.fields` whose bytes 9-12 give the record's whole length. Records are found by
walking those lengths from the first one, never by assuming a fixed record length (replica lines
of a Radarsat-1 signal file, for instance, are longer than the others).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from sarcli.errors import FormatError
from sarcli.io.ceos import fields as F


@dataclass
class RecordWalk:
    """Where the complete records of a walk sit: byte offsets and lengths (int64), and whether the
    file ended inside a record (only possible when the walk was asked to tolerate it)."""

    offsets: np.ndarray
    lengths: np.ndarray
    truncated: bool


def walk(buf: bytes | memoryview | np.ndarray, src: str, start: int = 0, first_number: int = 1,
         min_length: int = F.HEADER_BYTES, what: str = "CEOS record", partial_ok: bool = False) -> RecordWalk:
    """Walk the records of ``buf`` from byte ``start`` (record number ``first_number``) to its end.

    A record shorter than ``min_length`` is refused (``what`` names the record kind expected). A file
    that ends inside a header or a record is refused in one line, or, with ``partial_ok``, gives the
    complete records before it and ``truncated = True``.
    """
    mv = memoryview(buf)
    size = len(mv)
    offs: list[int] = []
    lens: list[int] = []
    off = start
    truncated = False
    while off < size:
        number = first_number + len(offs)
        if size - off < F.HEADER_BYTES:
            if partial_ok:
                truncated = True
                break
            raise FormatError(f"{src}: truncated record header at byte {off}")
        (length,) = struct.unpack_from(">I", mv, off + 8)
        if length < min_length:
            raise FormatError(f"{src}: record {number} at byte {off} has length {length} < {min_length} "
                              f"(not a {what}; corrupt file?)")
        if off + length > size:
            if partial_ok:
                truncated = True
                break
            raise FormatError(f"{src}: record {number} at byte {off} claims {length} bytes; only {size - off} "
                              "remain (truncated or corrupt)")
        offs.append(off)
        lens.append(length)
        off += length
    return RecordWalk(np.asarray(offs, np.int64), np.asarray(lens, np.int64), truncated)


def file_descriptor(buf: bytes | memoryview | np.ndarray, src: str, what: str,
                    min_length: int = F.HEADER_BYTES) -> F.RecordHeader:
    """The header of the file descriptor record that opens ``buf`` (record 1: type codes
    ``CODES_FILE_DESCRIPTOR`` and ``CEOS-SAR-CCT`` at bytes 17-28), checked to be at least
    ``min_length`` bytes long (the fields the caller reads) and to fit in the file. ``what`` names the
    file kind in messages ("CEOS data file")."""
    size = len(buf)
    if size < F.HEADER_BYTES:
        raise FormatError(f"{src}: not a {what} (only {size} bytes)")
    head = bytes(buf[:min(size, 192)])
    h = F.parse_header(head)
    if h.codes != F.CODES_FILE_DESCRIPTOR or F.ascii_field(head, 17, 28) != "CEOS-SAR-CCT":
        raise FormatError(f"{src}: not a {what} (no CEOS-SAR-CCT file descriptor record)")
    if h.length < min_length or h.length > size:
        raise FormatError(f"{src}: file descriptor claims {h.length} bytes, file has {size}")
    return h


def has_file_descriptor(head: bytes) -> bool:
    """Cheap signature check (for sniffing): ``head`` (the first 8 bytes or more of a file) starts with
    a record whose type codes are those of a CEOS file descriptor."""
    return len(head) >= 8 and tuple(head[4:8]) == F.CODES_FILE_DESCRIPTOR
