"""CEOS field decoding against plain reference decoders (hypothesis property tests)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import FormatError
from sarcli.io.ceos import fields as F
from sarcli.io.ceos.radarsat1 import aux as A
from sarcli.io.ceos.radarsat1.samples import decode_lines, decode_reference, encode

blocks = st.binary(min_size=50, max_size=50)


def ref_field(block: bytes, off: int, width: int) -> int:
    """Reference: the whole block as one big-endian integer, MSB-first bit offsets."""
    big = int.from_bytes(block, "big")
    return (big >> (400 - off - width)) & ((1 << width) - 1)


@settings(max_examples=200, deadline=None)
@given(st.lists(blocks, min_size=1, max_size=8))
def test_aux_fields_match_bitwise_reference(bl):
    arr = np.frombuffer(b"".join(bl), np.uint8).reshape(len(bl), 50)
    for name, (off, width) in A.FIELDS.items():
        got = A.get_field(arr, name)
        assert got.tolist() == [ref_field(b, off, width) for b in bl], name


@settings(max_examples=200, deadline=None)
@given(blocks, st.sampled_from(sorted(A.FIELDS)), st.integers(0, 2**32 - 1))
def test_set_field_changes_only_its_bits(block, name, value):
    off, width = A.FIELDS[name]
    value %= 1 << width
    arr = np.frombuffer(block, np.uint8).reshape(1, 50).copy()
    A.set_field(arr, name, value)
    mask = ((1 << width) - 1) << (400 - off - width)
    expect = (int.from_bytes(block, "big") & ~mask) | (value << (400 - off - width))
    assert int.from_bytes(arr.tobytes(), "big") == expect


def test_aux_time_fields_follow_asf_layout():
    # ASF aux_RSAT.c: days = b43<<3 | b44>>5; seconds = (b44&0x1f)<<12 | b45<<4 | b46>>4;
    # ms = (b46&0xf)<<6 | b47>>2; us = (b47&3)<<8 | b48; PRF = b25<<5 | b26>>3; AGC = b49 & 0x3f.
    rng = np.random.default_rng(3)
    b = rng.integers(0, 256, (20, 50)).astype(np.uint8)
    i = b.astype(np.int64)
    assert np.array_equal(A.get_field(b, "days"), (i[:, 43] << 3) | (i[:, 44] >> 5))
    assert np.array_equal(A.get_field(b, "seconds"), ((i[:, 44] & 31) << 12) | (i[:, 45] << 4) | (i[:, 46] >> 4))
    assert np.array_equal(A.get_field(b, "milliseconds"), ((i[:, 46] & 15) << 6) | (i[:, 47] >> 2))
    assert np.array_equal(A.get_field(b, "microseconds"), ((i[:, 47] & 3) << 8) | i[:, 48])
    assert np.array_equal(A.get_field(b, "prf_code"), (i[:, 25] << 5) | (i[:, 26] >> 3))
    assert np.array_equal(A.get_field(b, "window_start_code"), (i[:, 27] << 4) | (i[:, 28] >> 4))
    assert np.array_equal(A.get_field(b, "rx_agc"), i[:, 49] & 63)
    assert np.array_equal(A.get_field(b, "replica_present"), (i[:, 49] >> 6) & 1)
    assert np.array_equal(A.get_field(b, "adc_code"), (i[:, 22] >> 4) & 3)


def test_timing_codes_reproduce_the_vancouver_numbers():
    # Format notes §4: PRF code 4283 -> 1256.985 Hz; 9288 = 6*1548; replica 1440 samples at 32.317 MHz;
    # t0 = 6.5956 ms with N = 8 and a window code near 1262 (within one code step, 6 T_b = 0.186 us).
    assert A.prf_from_code(4283, 0) == pytest.approx(1256.985, abs=5e-4)
    assert 1 / A.clock_period_s(np.arange(3)) == pytest.approx([32.317075e6, 18.4669e6, 12.92683e6], rel=1e-6)
    assert A.samples_from_code(1547) == 9288
    assert A.replica_samples(0) == 1440
    t0 = A.first_sample_time(1262, 4283, 0, 8)
    assert abs(t0 - 6.5956e-3) < 6 * A.clock_period_s(0)
    assert A.pulses_in_flight(18) == 9 and A.pulses_in_flight(18, f3_pulses_in_flight=8) == 8
    assert A.chirp_slope(32.3e6) == -7.214e11


def ref_nibble(b: int) -> int:
    s = b & 15
    return 2 * (s - 16 if s >= 8 else s) + 1


@settings(max_examples=100, deadline=None)
@given(st.lists(st.integers(0, 15), min_size=2, max_size=64).filter(lambda v: len(v) % 2 == 0))
def test_sample_decoding_matches_scalar_reference(nibbles):
    raw = np.array(nibbles, np.uint8)
    expect = np.array([ref_nibble(i) + 1j * ref_nibble(q) for i, q in zip(nibbles[0::2], nibbles[1::2],
                                                                        strict=True)])
    ref = decode_reference(raw)
    assert np.array_equal(ref, expect)
    out = np.zeros((1, raw.size // 2), np.complex64)
    bad = decode_lines(raw, np.array([0], np.int64), np.array([0], np.int64), raw.size // 2, out)
    assert bad == 0 and np.array_equal(out[0], expect)
    assert np.array_equal(encode(ref), raw)


def test_kernel_counts_high_nibbles_and_places_rows():
    buf = np.arange(40, dtype=np.uint8)  # bytes 16..39 have a non-zero high nibble
    out = np.zeros((3, 4), np.complex64)
    bad = decode_lines(buf, np.array([0, 16], np.int64), np.array([2, 0], np.int64), 4, out)
    assert bad == 8  # the 8 bytes 16..23 of the second line
    assert np.array_equal(out[2], decode_reference(buf[0:8])) and np.array_equal(out[0], decode_reference(buf[16:24]))
    assert np.all(out[1] == 0)


@settings(max_examples=200, deadline=None)
@given(st.integers(-(10**6), 10**7), st.integers(8, 12))
def test_ascii_int_roundtrip(v, width):
    rec = b"  " + F.format_int(v, width)
    assert F.parse_int(rec, 3, 2 + width, "x") == int(v)


@settings(max_examples=300, deadline=None)
@given(st.floats(-1e12, 1e12, allow_nan=False), st.sampled_from([(16, "F"), (16, "E"), (22, "D"), (8, "F")]))
def test_ascii_real_roundtrip_keeps_the_digits_that_fit(v, spec):
    width, style = spec
    try:
        field = F.format_real(v, width, style)
    except FormatError:
        assert style == "F" and abs(v) >= 10 ** (width - 1)
        return
    assert len(field) == width
    back = F.parse_real(field, 1, width, "x")
    # reference: what the field's text itself means (plain float of the text, D -> E)
    assert back == float(field.decode().replace("D", "E"))
    if style != "F":
        assert back == pytest.approx(v, rel=10.0 ** -(width - 8), abs=0)
    elif width == 16 and abs(v) > 1e-3:
        assert back == pytest.approx(v, rel=1e-9)


@given(st.text(alphabet="abcXYZ#*,;", min_size=1, max_size=6))
def test_garbage_ascii_numbers_are_one_line_errors(s):
    rec = s.rjust(16).encode()
    with pytest.raises(FormatError, match="not a number"):
        F.parse_real(rec, 1, 16, "wavelength", "LEA")
    with pytest.raises(FormatError, match="not an integer"):
        F.parse_int(rec, 1, 16, "count", "LEA")


def test_blank_fields_are_missing_not_zero():
    rec = b" " * 32
    assert F.parse_real(rec, 1, 16, "x") is None and F.parse_int(rec, 17, 32, "y") is None
    with pytest.raises(FormatError, match="blank"):
        F.require_value(None, "wavelength", 501, 516, "LEA")
    assert F.parse_real(b"  0.123456789012345D+07", 2, 23, "d") == 1234567.89012345


def test_record_header_roundtrip():
    h = F.parse_header(F.pack_header(7, F.CODES_SIGNAL_DATA, 18818))
    assert (h.sequence, h.codes, h.length) == (7, (50, 10, 18, 20), 18818)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from([-15.0, -3.0, -1.0, 1.0, 7.0, 15.0, 0.0, 2.0, 17.0, -17.0, 1.5, np.nan, np.inf]),
                min_size=2, max_size=12).filter(lambda v: len(v) % 2 == 0),
       st.sampled_from([np.complex64, np.complex128]))
def test_four_bit_check_matches_reference(vals, dtype):
    from sarcli.io.ceos.radarsat1.samples import is_four_bit, is_four_bit_reference

    x = np.empty(len(vals) // 2, dtype)
    x.real, x.imag = vals[0::2], vals[1::2]
    assert is_four_bit(x) == is_four_bit_reference(x)
    assert not is_four_bit(np.ones(4))  # real arrays are not I/Q levels
