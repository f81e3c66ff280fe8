"""User data field decoders (numba): bypass / decimation-only, BAQ 3/4/5-bit and FDBAQ [S1-ISP, §4].

The user data field holds four channel sections, IE, IO, QE, QO (I and Q of the even and odd
decimation-filter outputs), each padded to a whole 16-bit word; the field is padded to a multiple
of 4 octets [S1-ISP, §3.3.3]. Sample j of the range line is

    s[2j]   = IE[j] + i QE[j],      s[2j+1] = IO[j] + i QO[j]          (j = 0 .. NQ-1)

A code is a sign bit followed by a magnitude code MCode; the sample value is
(-1)^sign * v(MCode), with [S1-ISP, §4.2-4.4]

- format A/B (bypass, decimation only): 10-bit codes, v = MCode;
- format C (BAQ N = 3, 4, 5 bit): N-bit codes in blocks of 128 per channel, an 8-bit THIDX before
  each block of the QE section; v = MCode, or A_N[THIDX] for the largest MCode, when THIDX is in the
  simple-reconstruction range, else NRL_N[MCode] * SF[THIDX];
- format D (FDBAQ): per block, a 3-bit bit-rate code BRC before the block in IE, the 8-bit THIDX
  before the block in QE, and Huffman-coded magnitudes whose tree depends on BRC; reconstruction as
  for BAQ with the B tables and NRL_BRC.

Conventions of this implementation (the reference decode of the real packets agrees, see tests):
a zero magnitude is +0.0 whatever its sign bit; NRL * SF is the float32 product of the float32
table values (it can differ by 1 ulp from the correctly rounded product; the difference is
documented in ``docs/sentinel1.md``). Values are complex64.

Decoding is table driven: the next 10 bits of the stream index a 1024-entry table that gives the
code's length (sign included, at most 10 bits for BRC 4) and its symbol ``sign*16 + MCode``; the
symbols of the three sections before QE are kept until the block's THIDX is known, then mapped
through a (THIDX, symbol) -> value table. The plain-Python reference is
:mod:`sarcli.io.sentinel1.reference`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from sarcli.errors import FormatError
from sarcli.io.sentinel1.constants import (
    BAQ_BYPASS,
    BAQ_MODES,
    BLOCK_CODES,
    BRC_LEVELS,
    FDBAQ_MODES,
    HUFFMAN_CODES,
    NRL_BAQ,
    NRL_FDBAQ,
    SIGMA_FACTORS,
    SIMPLE_A,
    SIMPLE_B,
    TEST_MODES_BYPASS,
    TEST_MODES_OPERATIONAL,
)

# Status codes of the kernels (0 = decoded).
OK = 0
ERR_OVERRUN = 1
ERR_BRC = 2
ERR_LENGTH = 3
ERR_MODE = 4
STATUS_TEXT = {
    ERR_OVERRUN: "the channel data run past the end of the user data field",
    ERR_BRC: "a bit-rate code (BRC) is larger than 4",
    ERR_LENGTH: "the user data field length does not match the decoded sections",
    ERR_MODE: "unknown BAQ mode",
}

SYMBOLS = 32  # sign * 16 + MCode, MCode < 16


def _value_table(simple: tuple[float, ...], nrl: tuple[float, ...]) -> np.ndarray:
    """(256 THIDX, 32 symbols) float32 values of one quantiser [S1-ISP, §4.3, §4.4, §5.2]."""
    k = len(nrl)
    table = np.zeros((256, SYMBOLS), np.float32)
    nrl32 = np.asarray(nrl, np.float32)
    for thidx in range(256):
        if thidx < len(simple):
            mag = np.arange(k, dtype=np.float32)
            mag[k - 1] = np.float32(simple[thidx])
        else:
            mag = nrl32 * np.float32(SIGMA_FACTORS[thidx])
        table[thidx, :k] = mag
        table[thidx, 16:16 + k] = np.where(mag == 0, np.float32(0.0), -mag)  # zero magnitude: +0.0
    return table


def _huffman_lut(codes: tuple[str, ...]) -> np.ndarray:
    """1024-entry lookup of a sign + Huffman-magnitude code from the next 10 bits:
    entry = (code length incl. sign) << 8 | (sign*16 + MCode)."""
    lut = np.zeros(1024, np.uint16)
    for sign in (0, 1):
        for mcode, bits in enumerate(codes):
            word = f"{sign}{bits}"
            free = 10 - len(word)
            base = int(word, 2) << free
            lut[base:base + (1 << free)] = (len(word) << 8) | (sign * 16 + mcode)
    return lut


FDBAQ_VALUES = np.stack([_value_table(SIMPLE_B[brc], NRL_FDBAQ[brc]) for brc in range(5)])
BAQ_VALUES = np.stack([_value_table(SIMPLE_A[n], NRL_BAQ[n]) for n in BAQ_MODES])
HUFFMAN_LUT = np.stack([_huffman_lut(c) for c in HUFFMAN_CODES])
assert tuple(len(c) for c in HUFFMAN_CODES) == BRC_LEVELS


def decoder_kind(baq_mode: int, test_mode: int) -> int:
    """0 for formats A/B (bypass, decimation only), N for BAQ N-bit (C), 12..14 for FDBAQ (D), from the
    BAQ and test mode codes [S1-ISP, Table 3.3-2]; -1 for a combination the specification excludes."""
    if test_mode in TEST_MODES_BYPASS:
        return BAQ_BYPASS if baq_mode == BAQ_BYPASS else -1
    if test_mode in TEST_MODES_OPERATIONAL and (baq_mode == BAQ_BYPASS or baq_mode in BAQ_MODES
                                                 or baq_mode in FDBAQ_MODES):
        return int(baq_mode)
    return -1


@njit(cache=True, inline="always")
def _peek(buf, end, pos, nbits):
    """``nbits`` (<= 25) bits of ``buf`` from bit ``pos`` (msb first); octets at or past ``end`` read as 0."""
    i = pos >> 3
    w = np.uint32(0)
    for j in range(4):
        b = buf[i + j] if i + j < end else np.uint8(0)
        w = (w << np.uint32(8)) | np.uint32(b)
    return np.int64((w >> np.uint32(32 - (pos & 7) - nbits)) & np.uint32((1 << nbits) - 1))


@njit(cache=True)
def _words(nbits):
    return (nbits + 15) // 16


@njit(cache=True)
def decode_into(buf, start, end, nq, kind, out, fd_values, baq_values, huffman):
    """Decode the user data field ``buf[start:end]`` of NQ quads into ``out`` (float32, 4*NQ:
    re, im of 2*NQ complex samples). Returns a status code (0 = decoded)."""
    nb = (nq + BLOCK_CODES - 1) // BLOCK_CODES
    pos = start * 8
    limit = end * 8
    if kind == 0:  # formats A and B: 10-bit sign + magnitude
        step = _words(10 * nq) * 16
        if ((4 * step // 8 + 3) // 4) * 4 != end - start:
            return ERR_LENGTH
        for ch in range(4):
            base = pos + ch * step
            col = (0, 2, 1, 3)[ch]
            for j in range(nq):
                c = _peek(buf, end, base + 10 * j, 10)
                mag = np.float32(c & 0x1FF)
                out[4 * j + col] = -mag if (c >> 9) and mag != 0 else mag
        return OK
    codes = np.empty((4, nq), np.uint8)
    thidx = np.zeros(nb, np.int64)
    if kind == 3 or kind == 4 or kind == 5:  # format C: fixed-length BAQ codes
        n = kind
        for ch in range(4):
            chstart = pos
            for b in range(nb):
                if ch == 2:
                    thidx[b] = _peek(buf, end, pos, 8)
                    pos += 8
                for j in range(b * BLOCK_CODES, min(nq, (b + 1) * BLOCK_CODES)):
                    c = _peek(buf, end, pos, n)
                    pos += n
                    codes[ch, j] = (c >> (n - 1)) * 16 + (c & ((1 << (n - 1)) - 1))
            pos = chstart + _words(pos - chstart) * 16
        if pos > limit:
            return ERR_OVERRUN
        if ((pos - start * 8) // 8 + 3) // 4 * 4 != end - start:
            return ERR_LENGTH
        table = baq_values[kind - 3]
        for b in range(nb):
            row = table[thidx[b]]
            for j in range(b * BLOCK_CODES, min(nq, (b + 1) * BLOCK_CODES)):
                out[4 * j] = row[codes[0, j]]
                out[4 * j + 2] = row[codes[1, j]]
                out[4 * j + 1] = row[codes[2, j]]
                out[4 * j + 3] = row[codes[3, j]]
        return OK
    if kind < 12 or kind > 14:
        return ERR_MODE
    brc = np.zeros(nb, np.int64)  # format D: FDBAQ
    for ch in range(4):
        chstart = pos
        for b in range(nb):
            if ch == 0:
                brc[b] = _peek(buf, end, pos, 3)
                pos += 3
                if brc[b] > 4:
                    return ERR_BRC
            if ch == 2:
                thidx[b] = _peek(buf, end, pos, 8)
                pos += 8
            lut = huffman[brc[b]]
            for j in range(b * BLOCK_CODES, min(nq, (b + 1) * BLOCK_CODES)):
                e = lut[_peek(buf, end, pos, 10)]
                codes[ch, j] = e & 0xFF
                pos += e >> 8
        pos = chstart + _words(pos - chstart) * 16
        if pos > limit:
            return ERR_OVERRUN
    if ((pos - start * 8) // 8 + 3) // 4 * 4 != end - start:
        return ERR_LENGTH
    for b in range(nb):
        row = fd_values[brc[b], thidx[b]]
        for j in range(b * BLOCK_CODES, min(nq, (b + 1) * BLOCK_CODES)):
            out[4 * j] = row[codes[0, j]]
            out[4 * j + 2] = row[codes[1, j]]
            out[4 * j + 1] = row[codes[2, j]]
            out[4 * j + 3] = row[codes[3, j]]
    return OK


@njit(cache=True, parallel=True)
def decode_batch(data, starts, ends, nq, kind, out, fd_values, baq_values, huffman):
    """Decode many packets' user data (``data[starts[k]:ends[k]]``) into the rows of ``out``
    (float32, (n, >= 4*max NQ), zero-filled by the caller). Returns the status per packet."""
    n = starts.size
    status = np.zeros(n, np.int8)
    for k in prange(n):
        row = out[k]
        status[k] = decode_into(data, starts[k], ends[k], nq[k], kind[k], row, fd_values, baq_values, huffman)
    return status


def decode_packets(data: np.ndarray, starts: np.ndarray, ends: np.ndarray, nq: np.ndarray, kind: np.ndarray,
                   width: int | None = None, where: str = "Level-0 file") -> np.ndarray:
    """Decoded lines (complex64, (n, width)), zero-padded past each packet's 2*NQ samples; one
    :class:`FormatError` line naming the first packet that does not decode."""
    nq = np.asarray(nq, np.int64)
    width = int(2 * nq.max()) if width is None else int(width)
    out = np.zeros((starts.size, width), np.complex64)
    status = decode_batch(data, np.asarray(starts, np.int64), np.asarray(ends, np.int64), nq,
                          np.asarray(kind, np.int64), out.view(np.float32), FDBAQ_VALUES, BAQ_VALUES,
                          HUFFMAN_LUT)
    bad = np.flatnonzero(status)
    if bad.size:
        i = int(bad[0])
        raise FormatError(f"{where}: packet {i} (user data at byte {int(starts[i])}): "
                          f"{STATUS_TEXT[int(status[i])]}; the packet is corrupted or truncated")
    return out


def decode_user_data(user_data: bytes | np.ndarray, nq: int, baq_mode: int, test_mode: int = 0) -> np.ndarray:
    """The 2*NQ complex64 samples of one packet's user data field (the bytes after the 68 header octets)."""
    kind = decoder_kind(int(baq_mode), int(test_mode))
    if kind < 0:
        raise FormatError(f"BAQ mode {baq_mode} with test mode {test_mode} is not a defined data format "
                          "(S1-IF-ASD-PL-0007 Table 3.3-2)")
    buf = np.frombuffer(bytes(user_data), np.uint8)
    return decode_packets(buf, np.array([0]), np.array([buf.size]), np.array([nq]), np.array([kind]),
                          where="user data")[0]
