"""The generic CEOS layer (sarcli.io.ceos: records, signal), on files made here with no Radarsat-1 part:
record walking by the header lengths, the file descriptor check, the signal data file index."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import FormatError
from sarcli.io.ceos import fields as F
from sarcli.io.ceos.records import file_descriptor, has_file_descriptor, walk
from sarcli.io.ceos.signal import PREFIX_BYTES, build_prefix, index_signal_records


def _records(lengths: list[int], codes=(18, 10, 18, 20)) -> bytes:
    return b"".join(bytes(F.blank_record(k + 1, codes, n)) for k, n in enumerate(lengths))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(F.HEADER_BYTES, 400), min_size=1, max_size=20))
def test_walk_finds_every_record_from_the_header_lengths(lengths):
    buf = _records(lengths)
    w = walk(buf, "f")
    assert w.lengths.tolist() == lengths and not w.truncated
    assert w.offsets.tolist() == np.concatenate([[0], np.cumsum(lengths)[:-1]]).tolist()


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(F.HEADER_BYTES, 200), min_size=2, max_size=10), st.integers(1, 199))
def test_a_file_ending_inside_a_record(lengths, cut):
    buf = _records(lengths)
    end = len(buf) - min(cut, lengths[-1] - 1)  # inside the last record (or its header)
    w = walk(buf[:end], "f", partial_ok=True)
    assert w.truncated and w.lengths.tolist() == lengths[:-1]
    with pytest.raises(FormatError, match="truncated"):
        walk(buf[:end], "f")


def test_walk_messages():
    with pytest.raises(FormatError, match=r"f: record 2 at byte 100 claims 720 bytes; only 50 remain"):
        walk(_records([100, 720])[:150], "f")
    with pytest.raises(FormatError, match=r"f: record 3 at byte 42 has length 20 < 24 \(not a x record"):
        walk(_records([12, 30, 20]), "f", start=12, first_number=2, min_length=24, what="x record")


def test_file_descriptor_check():
    fd = bytes(F.file_descriptor(360, 2, "DAT_01.001", "TEST")) + b"\0" * 10
    assert has_file_descriptor(fd[:8]) and file_descriptor(fd, "d", "CEOS data file").length == 360
    with pytest.raises(FormatError, match="d: not a CEOS data file \\(no CEOS-SAR-CCT"):
        file_descriptor(_records([360]), "d", "CEOS data file")
    with pytest.raises(FormatError, match="d: file descriptor claims 360 bytes, file has 200"):
        file_descriptor(fd[:200], "d", "CEOS data file")
    with pytest.raises(FormatError, match="only 5 bytes"):
        file_descriptor(fd[:5], "d", "CEOS data file")
    assert not has_file_descriptor(_records([20])[:8])


def test_signal_file_index_of_a_non_radarsat_layout():
    """Records of 192-byte prefixes plus 40 bytes of any sensor's payload (no aux block)."""
    n = 7
    lengths = np.full(n, PREFIX_BYTES + 40)
    year, doy, ms = np.full(n, 2011), np.arange(100, 100 + n), 1000 * np.arange(n) + 17
    prefix = build_prefix(0, n, lengths, 20, year, doy, ms, 27000)
    desc = F.file_descriptor(720, 2, "IMG", "TEST")
    F.put(desc, 181, F.format_int(n, 6))
    buf = np.frombuffer(bytes(desc) + b"".join(p.tobytes() + bytes(40) for p in prefix), np.uint8)
    rec = index_signal_records(buf, "img")
    assert rec.n == n and not rec.truncated and rec.declared_records == n
    assert rec.offsets.tolist() == (720 + np.arange(n) * (PREFIX_BYTES + 40)).tolist()
    assert rec.line_number.tolist() == list(range(1, n + 1)) and rec.day_of_year.tolist() == doy.tolist()
    assert rec.year.tolist() == year.tolist() and rec.ms_of_day.tolist() == ms.tolist()
    assert rec.chirp_length_ns.tolist() == [27000] * n
    short = index_signal_records(buf[:-10], "img")
    assert short.n == n - 1 and short.truncated
    F.put(desc, 181, F.format_int(n - 2, 6))
    more = np.frombuffer(bytes(desc) + buf[720:].tobytes(), np.uint8)
    with pytest.raises(FormatError, match="7 records found, the file descriptor declares 5"):
        index_signal_records(more, "img")
