"""Radarsat-1 RAW signal data file: imagery-options file descriptor (16252 B) [S B-17] and one
variable-length signal data record per range line [S B-18]:

    record = 192-byte prefix (12-byte header + 180 bytes, big-endian binary)
           + 50-byte aux block (``sarcli.io.ceos.aux``)
           + replica (2 * floor(44.559 us / T_b) bytes, only when the aux replica bit is set)
           + echo samples (2 bytes per complex sample, ``sarcli.io.ceos.samples``)

Records are found by walking the headers (bytes 9-12 = record length), never by assuming a fixed
length or a replica period (doc trap 1). ``index_records`` does the walk and every consistency
check; ``build_records`` is its inverse for the writer.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from sarcli.errors import FormatError
from sarcli.io.ceos import aux as A
from sarcli.io.ceos import fields as F

DESCRIPTOR_BYTES = 16252
PREFIX_BYTES = 192
ECHO_START = PREFIX_BYTES + A.AUX_BYTES  # 242: first byte after the aux block
_SIGNAL_CODES = np.array(F.CODES_SIGNAL_DATA, dtype=np.uint8)


@dataclass
class RecordIndex:
    """Where every complete signal record sits, and its decoded prefix and aux fields (per line)."""

    offsets: np.ndarray  # int64 (n,) byte offset of each record
    lengths: np.ndarray  # int64 (n,)
    declared_records: int
    truncated: bool  # the file ended inside a record, or before the declared number of records
    line_number: np.ndarray  # prefix line number
    year: np.ndarray
    day_of_year: np.ndarray
    ms_of_day: np.ndarray
    chirp_length_ns: np.ndarray
    aux: dict[str, np.ndarray]  # every field of aux.FIELDS, (n,) int64
    n_samples: int
    replica_bytes: int

    @property
    def n(self) -> int:
        return int(self.offsets.size)

    def echo_offsets(self) -> np.ndarray:
        """Byte offset of the first echo sample of every record (after any replica)."""
        return self.offsets + ECHO_START + self.aux["replica_present"] * self.replica_bytes


def _be_u32(buf: np.ndarray, offsets: np.ndarray, at: int) -> np.ndarray:
    b = buf[offsets[:, None] + at + np.arange(4)].astype(np.int64)
    return (b[:, 0] << 24) | (b[:, 1] << 16) | (b[:, 2] << 8) | b[:, 3]


def read_descriptor(buf: np.ndarray, src: str) -> tuple[int, int]:
    """Check the imagery-options file descriptor; return (its length, declared number of records)."""
    if buf.size < F.HEADER_BYTES:
        raise FormatError(f"{src}: not a CEOS data file (only {buf.size} bytes)")
    head = bytes(buf[:min(buf.size, 192)])
    h = F.parse_header(head)
    if h.codes != F.CODES_FILE_DESCRIPTOR or F.ascii_field(head, 17, 28) != "CEOS-SAR-CCT":
        raise FormatError(f"{src}: not a CEOS data file (no CEOS-SAR-CCT file descriptor record)")
    if h.length < 192 or h.length > buf.size:
        raise FormatError(f"{src}: file descriptor claims {h.length} bytes, file has {buf.size}")
    n = F.require_value(F.parse_int(head, 181, 186, "number of SAR data records", src),
                        "number of SAR data records", 181, 186, src)
    return h.length, n


def _walk(buf: np.ndarray, start: int, src: str) -> tuple[np.ndarray, np.ndarray, bool]:
    mv = memoryview(buf)
    size = buf.size
    offs: list[int] = []
    lens: list[int] = []
    off = start
    truncated = False
    while off < size:
        if size - off < F.HEADER_BYTES:
            truncated = True
            break
        (length,) = struct.unpack_from(">I", mv, off + 8)
        if length < ECHO_START:
            raise FormatError(f"{src}: record {len(offs) + 2} at byte {off} has length {length} < "
                              f"{ECHO_START} (not a signal data record; corrupt file?)")
        if off + length > size:
            truncated = True
            break
        offs.append(off)
        lens.append(length)
        off += length
    return np.asarray(offs, np.int64), np.asarray(lens, np.int64), truncated


def index_records(buf: np.ndarray, src: str) -> RecordIndex:
    """Walk and validate all complete signal records of a data file held in ``buf`` (uint8)."""
    start, declared = read_descriptor(buf, src)
    offsets, lengths, truncated = _walk(buf, start, src)
    if offsets.size > declared:
        raise FormatError(f"{src}: {offsets.size} records found, the file descriptor declares {declared}")
    truncated = truncated or offsets.size < declared
    if offsets.size == 0:
        raise FormatError(f"{src}: no complete signal data record (file truncated after the descriptor)")
    codes = buf[offsets[:, None] + np.arange(4, 8)]
    bad = np.flatnonzero(np.any(codes != _SIGNAL_CODES, axis=1))
    if bad.size:
        k = int(bad[0])
        raise FormatError(f"{src}: record {k + 2} at byte {offsets[k]} is not a signal data record "
                          f"(type codes {tuple(int(c) for c in codes[k])})")
    aux_bytes = buf[offsets[:, None] + PREFIX_BYTES + np.arange(A.AUX_BYTES)]
    aux = {name: A.get_field(aux_bytes, name) for name in A.FIELDS}
    if not np.any(aux["sync"] == A.AUX_SYNC):
        raise FormatError(f"{src}: no aux block carries the Radarsat-1 sync marker 0x352EF853 "
                          "(not Radarsat-1 RAW signal data)")
    adc = np.unique(aux["adc_code"])
    if adc.size != 1 or int(adc[0]) > 2:
        raise FormatError(f"{src}: ADC rate codes {adc.tolist()} (need one of 0, 1, 2 for the whole file)")
    dur = np.unique(aux["window_duration_code"])
    if dur.size != 1:
        k = int(np.flatnonzero(aux["window_duration_code"] != aux["window_duration_code"][0])[0])
        raise FormatError(f"{src}: the number of samples per line changes at line {k + 1} "
                          "(receive-window duration code); not supported")
    n_samples = int(A.samples_from_code(dur[0]))
    rep_bytes = 2 * A.replica_samples(int(adc[0]))
    expected = ECHO_START + aux["replica_present"] * rep_bytes + 2 * n_samples
    bad = np.flatnonzero(lengths != expected)
    if bad.size:
        k = int(bad[0])
        raise FormatError(
            f"{src}: inconsistent record length at line {k + 1} (byte {offsets[k]}): header says "
            f"{lengths[k]} bytes, the aux block implies {expected[k]} ({n_samples} samples, replica "
            f"flag {aux['replica_present'][k]})")
    return RecordIndex(
        offsets=offsets, lengths=lengths, declared_records=declared, truncated=truncated,
        line_number=_be_u32(buf, offsets, 12), year=_be_u32(buf, offsets, 36),
        day_of_year=_be_u32(buf, offsets, 40), ms_of_day=_be_u32(buf, offsets, 44),
        chirp_length_ns=_be_u32(buf, offsets, 68), aux=aux, n_samples=n_samples,
        replica_bytes=rep_bytes)


def build_descriptor(n_records: int, max_length: int, n_samples: int, software_id: str) -> bytes:
    """The 16252-byte imagery-options file descriptor of a RAW data file."""
    d = F.file_descriptor(DESCRIPTOR_BYTES, 2, "DAT_01.001", software_id)
    F.put(d, 181, F.format_int(n_records, 6) + F.format_int(max_length, 6))
    F.put(d, 217, F.format_int(8, 4) + F.format_int(2, 4) + F.format_int(2, 4))
    F.put(d, 237, F.format_int(n_records, 8) + F.format_int(0, 4) + F.format_int(n_samples, 8))
    F.put(d, 277, F.format_int(PREFIX_BYTES - F.HEADER_BYTES, 4) + F.format_int(2 * n_samples, 8)
          + F.format_int(0, 4))
    F.put(d, 297, b"  13 4PB  49 2PB  45 4PB  21 4PB  29 4PB")
    F.put(d, 401, F.format_text("COMPLEX INTEGER*2", 28) + F.format_text("CI*2", 4))
    F.put(d, 433, F.format_int(4, 4) + F.format_int(0, 4) + F.format_int(15, 8))
    return bytes(d)


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
