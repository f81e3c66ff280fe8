"""The CEOS signal data file: an imagery-options file descriptor, then one signal data record per
range line, each opening with the same 192-byte prefix (12-byte header + 180 bytes, big-endian
binary) before the sensor's own bytes (Radarsat-1: a 50-byte aux block, then the samples).

Prefix fields used here (1-based inclusive byte positions, [S B-18]): line number 13-16, SAR image
pixels (samples per line) 25-28, acquisition year 37-40, day of year 41-44, milliseconds of day 45-48,
SAR channel indicator 49-50 and code 51-52, chirp length (ns) 69-72. The descriptor's bytes 181-186
declare the number of signal data records.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.errors import FormatError
from sarcli.io.ceos import fields as F
from sarcli.io.ceos.records import file_descriptor, walk

PREFIX_BYTES = 192
_SIGNAL_CODES = np.array(F.CODES_SIGNAL_DATA, dtype=np.uint8)


@dataclass
class SignalRecords:
    """Where every complete signal data record sits, and its decoded prefix (one value per line)."""

    offsets: np.ndarray  # int64 (n,) byte offset of each record
    lengths: np.ndarray  # int64 (n,)
    declared_records: int
    truncated: bool  # the file ended inside a record, or before the declared number of records
    line_number: np.ndarray
    year: np.ndarray
    day_of_year: np.ndarray
    ms_of_day: np.ndarray
    chirp_length_ns: np.ndarray

    @property
    def n(self) -> int:
        return int(self.offsets.size)


def be_u32(buf: np.ndarray, offsets: np.ndarray, at: int) -> np.ndarray:
    """The big-endian unsigned 32-bit integer at 0-based byte ``at`` of every record (int64 (n,))."""
    b = buf[offsets[:, None] + at + np.arange(4)].astype(np.int64)
    return (b[:, 0] << 24) | (b[:, 1] << 16) | (b[:, 2] << 8) | b[:, 3]


def read_descriptor(buf: np.ndarray, src: str) -> tuple[int, int]:
    """Check the imagery-options file descriptor; return (its length, declared number of records)."""
    h = file_descriptor(buf, src, "CEOS data file", min_length=PREFIX_BYTES)
    head = bytes(buf[:PREFIX_BYTES])
    n = F.require_value(F.parse_int(head, 181, 186, "number of SAR data records", src),
                        "number of SAR data records", 181, 186, src)
    return h.length, n


def index_signal_records(buf: np.ndarray, src: str, min_length: int = PREFIX_BYTES) -> SignalRecords:
    """Walk all complete signal data records of a data file held in ``buf`` (uint8): descriptor, record
    walk (a record shorter than ``min_length`` is refused), count against the descriptor, type codes,
    prefix fields."""
    start, declared = read_descriptor(buf, src)
    w = walk(buf, src, start, first_number=2, min_length=min_length, what="signal data record",
             partial_ok=True)
    offsets = w.offsets
    if offsets.size > declared:
        raise FormatError(f"{src}: {offsets.size} records found, the file descriptor declares {declared}")
    if offsets.size == 0:
        raise FormatError(f"{src}: no complete signal data record (file truncated after the descriptor)")
    codes = buf[offsets[:, None] + np.arange(4, 8)]
    bad = np.flatnonzero(np.any(codes != _SIGNAL_CODES, axis=1))
    if bad.size:
        k = int(bad[0])
        raise FormatError(f"{src}: record {k + 2} at byte {offsets[k]} is not a signal data record "
                          f"(type codes {tuple(int(c) for c in codes[k])})")
    return SignalRecords(
        offsets=offsets, lengths=w.lengths, declared_records=declared,
        truncated=w.truncated or offsets.size < declared,
        line_number=be_u32(buf, offsets, 12), year=be_u32(buf, offsets, 36),
        day_of_year=be_u32(buf, offsets, 40), ms_of_day=be_u32(buf, offsets, 44),
        chirp_length_ns=be_u32(buf, offsets, 68))


def build_prefix(first_line: int, n: int, lengths: np.ndarray, n_samples: int, year: np.ndarray, doy: np.ndarray,
                 ms_of_day: np.ndarray, chirp_length_ns: int) -> np.ndarray:
    """(n, 192) uint8 prefixes of lines ``first_line .. first_line + n - 1`` (0-based): header, line
    number, pixel count, date/time, channel, chirp length."""
    p = np.zeros((n, PREFIX_BYTES), dtype=np.uint8)

    def put_u32(at: int, v) -> None:
        v = np.broadcast_to(np.asarray(v, dtype=">u4"), (n,))
        p[:, at:at + 4] = v.copy().view(np.uint8).reshape(n, 4)

    def put_u16(at: int, v) -> None:
        v = np.broadcast_to(np.asarray(v, dtype=">u2"), (n,))
        p[:, at:at + 2] = v.copy().view(np.uint8).reshape(n, 2)

    put_u32(0, np.arange(first_line + 2, first_line + n + 2))  # sequence: the descriptor is record 1
    p[:, 4:8] = _SIGNAL_CODES
    put_u32(8, lengths)
    put_u32(12, np.arange(first_line + 1, first_line + n + 1))
    put_u32(16, 1)
    put_u32(24, n_samples)
    put_u32(36, year)
    put_u32(40, doy)
    put_u32(44, ms_of_day)
    put_u16(48, 1)
    put_u16(50, 2)
    put_u32(68, chirp_length_ns)
    return p
