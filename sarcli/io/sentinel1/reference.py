"""Plain-Python reference decoders of the user data field (for the tests of :mod:`.decode`).

Written for clarity, not speed, and deliberately in another way than the numba kernels: the user
data become a string of '0'/'1' characters, Huffman codes are matched by walking the code strings
of the specification symbol by symbol, and every sample value is computed from the law of
[S1-ISP, §4.2-4.4] with the tables of :mod:`.constants` (no precomputed value tables).
"""

from __future__ import annotations

import numpy as np

from sarcli.io.sentinel1.constants import (
    BLOCK_CODES,
    HUFFMAN_CODES,
    NRL_BAQ,
    NRL_FDBAQ,
    SIGMA_FACTORS,
    SIMPLE_A,
    SIMPLE_B,
)


def _bits(user_data: bytes) -> str:
    return "".join(f"{b:08b}" for b in user_data)


def _value(sign: int, mcode: int, simple: tuple[float, ...], nrl: tuple[float, ...], thidx: int) -> np.float32:
    """(-1)^sign times the simple or normal reconstruction of MCode [S1-ISP, §4.3/§4.4]; +0.0 for 0."""
    if thidx <= len(simple) - 1:
        mag = np.float32(simple[thidx]) if mcode == len(nrl) - 1 else np.float32(mcode)
    else:
        mag = np.float32(nrl[mcode]) * np.float32(SIGMA_FACTORS[thidx])
    if mag == 0:
        return np.float32(0.0)
    return -mag if sign else mag


def _align(ie, io, qe, qo) -> np.ndarray:
    nq = len(ie)
    out = np.empty(2 * nq, np.complex64)
    for j in range(nq):
        out[2 * j] = complex(ie[j], qe[j])
        out[2 * j + 1] = complex(io[j], qo[j])
    return out


def _word_aligned(pos: int, start: int) -> int:
    used = pos - start
    return start + -(-used // 16) * 16


def reference_bypass(user_data: bytes, nq: int) -> np.ndarray:
    """Formats A/B: 10-bit sign + magnitude codes, four sections of ceil(10 NQ / 16) words [S1-ISP, §4.2]."""
    bits = _bits(user_data)
    section = -(-10 * nq // 16) * 16
    chans = []
    for ch in range(4):
        vals = []
        for j in range(nq):
            code = bits[ch * section + 10 * j: ch * section + 10 * j + 10]
            mag = int(code[1:], 2)
            vals.append(np.float32(0.0) if mag == 0 else np.float32(-mag if code[0] == "1" else mag))
        chans.append(vals)
    return _align(*chans)


def reference_baq(user_data: bytes, nq: int, n_bits: int) -> np.ndarray:
    """Format C: N-bit BAQ, THIDX in front of each block of the QE section [S1-ISP, §4.3]."""
    bits = _bits(user_data)
    nb = -(-nq // BLOCK_CODES)
    pos = 0
    codes: list[list[tuple[int, int]]] = []
    thidx: list[int] = []
    for ch in range(4):
        start = pos
        vals = []
        for b in range(nb):
            if ch == 2:
                thidx.append(int(bits[pos:pos + 8], 2))
                pos += 8
            for _ in range(min(BLOCK_CODES, nq - b * BLOCK_CODES)):
                code = bits[pos:pos + n_bits]
                pos += n_bits
                vals.append((int(code[0]), int(code[1:], 2)))
        codes.append(vals)
        pos = _word_aligned(pos, start)
    chans = [[_value(s, m, SIMPLE_A[n_bits], NRL_BAQ[n_bits], thidx[j // BLOCK_CODES])
              for j, (s, m) in enumerate(vals)] for vals in codes]
    return _align(*chans)


def reference_fdbaq(user_data: bytes, nq: int) -> tuple[np.ndarray, list[int], list[int]]:
    """Format D: FDBAQ [S1-ISP, §4.4]. Returns the samples, the BRC and the THIDX of each block."""
    bits = _bits(user_data)
    nb = -(-nq // BLOCK_CODES)
    pos = 0
    brc: list[int] = []
    thidx: list[int] = []
    codes: list[list[tuple[int, int]]] = []
    for ch in range(4):
        start = pos
        vals = []
        for b in range(nb):
            if ch == 0:
                brc.append(int(bits[pos:pos + 3], 2))
                pos += 3
            if ch == 2:
                thidx.append(int(bits[pos:pos + 8], 2))
                pos += 8
            tree = HUFFMAN_CODES[brc[b]]
            for _ in range(min(BLOCK_CODES, nq - b * BLOCK_CODES)):
                sign = int(bits[pos])
                pos += 1
                word = ""
                while word not in tree:
                    word += bits[pos]
                    pos += 1
                vals.append((sign, tree.index(word)))
        codes.append(vals)
        pos = _word_aligned(pos, start)
    chans = [[_value(s, m, SIMPLE_B[brc[j // BLOCK_CODES]], NRL_FDBAQ[brc[j // BLOCK_CODES]],
                     thidx[j // BLOCK_CODES]) for j, (s, m) in enumerate(vals)] for vals in codes]
    return _align(*chans), brc, thidx
