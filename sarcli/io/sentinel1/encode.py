"""The inverse of the decoders: quantisers, encoders and packet packing (a Level-0 writer).

Used by the tests (round trips through the reader) and by the simulator (``write_level0``). The
encoders produce exactly the layout the decoders read [S1-ISP, §3.3.3, §4]: four channel sections,
each padded to a 16-bit word, the field padded to a multiple of 4 octets; BRC in front of each
block of IE, THIDX in front of each block of QE.

Quantisation (the instrument's, re-enacted for simulated echoes): per block of 128 quads, THIDX is
the sigma-factor index nearest to the block's RMS of I and Q (normal reconstruction levels are
normalised to a unit standard deviation [S1-ISP, §5.2.2.1]), and each I or Q value becomes the
nearest reconstruction level of that block. This is an encoder the decoder inverts exactly, not a
model of the on-board threshold logic.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sarcli.errors import ConfigError
from sarcli.io.sentinel1.constants import (
    BAQ_MODES,
    BLOCK_CODES,
    HEADER_BYTES,
    HUFFMAN_CODES,
    SIGMA_FACTORS,
)
from sarcli.io.sentinel1.decode import BAQ_VALUES, FDBAQ_VALUES
from sarcli.io.sentinel1.headers import FIELDS, HEADER_DTYPE

_HCODE = np.zeros((5, 32), np.int64)   # sign + magnitude code bits, right aligned
_HLEN = np.zeros((5, 32), np.int64)    # their lengths
for _b, _codes in enumerate(HUFFMAN_CODES):
    for _m, _bits in enumerate(_codes):
        for _s in (0, 1):
            _HCODE[_b, 16 * _s + _m] = int(f"{_s}{_bits}", 2)
            _HLEN[_b, 16 * _s + _m] = 1 + len(_bits)


@njit(cache=True)
def _put(buf, pos, value, nbits):
    for i in range(nbits):
        if (value >> (nbits - 1 - i)) & 1:
            buf[(pos + i) >> 3] |= np.uint8(0x80 >> ((pos + i) & 7))
    return pos + nbits


@njit(cache=True)
def _encode(sym, kind, brc, thidx, hcode, hlen):
    """User data field of one packet from symbols ``sym`` (4, NQ) (10-bit codes for bypass, else
    sign*16 + MCode) and per-block BRC and THIDX. Returns the octets (a multiple of 4)."""
    nq = sym.shape[1]
    nb = (nq + BLOCK_CODES - 1) // BLOCK_CODES
    buf = np.zeros(4 * (nq * 3 + 2 * nb + 16), np.uint8)
    pos = 0
    for ch in range(4):
        start = pos
        for b in range(nb):
            if kind >= 12 and ch == 0:
                pos = _put(buf, pos, brc[b], 3)
            if kind != 0 and ch == 2:
                pos = _put(buf, pos, thidx[b], 8)
            for j in range(b * BLOCK_CODES, min(nq, (b + 1) * BLOCK_CODES)):
                s = np.int64(sym[ch, j])
                if kind == 0:
                    pos = _put(buf, pos, s, 10)
                elif kind <= 5:
                    pos = _put(buf, pos, (s >> 4) << (kind - 1) | (s & 15), kind)
                else:
                    pos = _put(buf, pos, hcode[brc[b], s], hlen[brc[b], s])
        pos = start + (pos - start + 15) // 16 * 16
    n_bytes = (pos // 8 + 3) // 4 * 4
    return buf[:n_bytes].copy()


def _channels(line: np.ndarray) -> np.ndarray:
    """(4, NQ) float64 IE, IO, QE, QO of a line of 2*NQ complex samples [S1-ISP, §4.2]."""
    x = np.asarray(line, np.complex128)
    return np.stack([x.real[0::2], x.real[1::2], x.imag[0::2], x.imag[1::2]])


def quantise(line: np.ndarray, kind: int, brc: int | np.ndarray = 3,
             thidx: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Symbols (4, NQ) uint16, BRC (NB,) and THIDX (NB,) that encode ``line`` (2*NQ complex).

    ``kind``: 0 bypass (values rounded to integers, |v| <= 511), 3/4/5 BAQ, 12..14 FDBAQ (``brc``: one
    bit-rate code 0..4 for all blocks, or one per block). ``thidx``: imposed threshold indices
    (default: from each block's RMS)."""
    ch = _channels(line)
    nq = ch.shape[1]
    nb = -(-nq // BLOCK_CODES)
    brcs = np.broadcast_to(np.asarray(brc, np.int64), (nb,)).copy()
    if kind == 0:
        mag = np.minimum(np.rint(np.abs(ch)), 511).astype(np.int64)
        sym = ((ch < 0) & (mag > 0)).astype(np.int64) << 9 | mag
        return sym.astype(np.uint16), brcs, np.zeros(nb, np.int64)
    if kind not in BAQ_MODES and not 12 <= kind <= 14:
        raise ConfigError(f"unknown BAQ mode {kind}: use 0 (bypass), 3, 4, 5 (BAQ) or 12, 13, 14 (FDBAQ)")
    if np.any((brcs < 0) | (brcs > 4)):
        raise ConfigError(f"bit-rate codes must be 0..4, got {sorted(set(brcs.tolist()))}")
    sf = np.asarray(SIGMA_FACTORS)
    sym = np.zeros((4, nq), np.uint16)
    chosen = thidx is None
    thidx = np.zeros(nb, np.int64) if chosen else np.array(thidx, np.int64)
    for b in range(nb):
        blk = ch[:, b * BLOCK_CODES:(b + 1) * BLOCK_CODES]
        if chosen:
            thidx[b] = int(np.argmin(np.abs(sf - np.sqrt(np.mean(blk ** 2)))))
        levels = (BAQ_VALUES[kind - 3] if kind <= 5 else FDBAQ_VALUES[brcs[b]])[thidx[b]].astype(np.float64)
        k = 2 ** (kind - 1) if kind <= 5 else len(HUFFMAN_CODES[brcs[b]])
        valid = np.r_[np.arange(k), 16 + np.arange(k)]  # ties (a zero level) go to the positive code
        nearest = np.argmin(np.abs(blk[..., None] - levels[valid]), axis=-1)
        sym[:, b * BLOCK_CODES:(b + 1) * BLOCK_CODES] = valid[nearest]
    return sym, brcs, thidx


def encode_user_data(sym: np.ndarray, kind: int, brc: np.ndarray | None = None,
                     thidx: np.ndarray | None = None) -> bytes:
    """The user data field from symbols (see :func:`quantise`)."""
    nb = -(-sym.shape[1] // BLOCK_CODES)
    z = np.zeros(nb, np.int64)
    return _encode(np.asarray(sym, np.int64), int(kind), z if brc is None else np.asarray(brc, np.int64),
                   z if thidx is None else np.asarray(thidx, np.int64), _HCODE, _HLEN).tobytes()


def encode_headers(h: np.ndarray) -> np.ndarray:
    """(n, 68) uint8 headers from a :data:`~.headers.HEADER_DTYPE` array (inverse of ``decode_headers``)."""
    out = np.zeros((h.size, HEADER_BYTES), np.uint8)
    for name, _, octet, bit, width in FIELDS:
        n_bytes = (bit + width + 7) // 8
        v = h[name].astype(np.uint64) & np.uint64((1 << width) - 1)
        v = v << np.uint64(8 * n_bytes - bit - width)
        for j in range(n_bytes):
            out[:, octet + j] |= ((v >> np.uint64(8 * (n_bytes - 1 - j))) & np.uint64(0xFF)).astype(np.uint8)
    return out


def pack_packets(h: np.ndarray, user_data: list[bytes]) -> bytes:
    """Whole packets: headers (packet_data_length is set from the user data) + user data fields."""
    h = h.copy()
    h["packet_data_length"] = [HEADER_BYTES + len(u) - 7 for u in user_data]
    rows = encode_headers(h)
    return b"".join(rows[k].tobytes() + u for k, u in enumerate(user_data))


def blank_headers(n: int) -> np.ndarray:
    """n header records with the constant fields of a Sentinel-1 SAR packet set [S1-ISP, §3.1-3.2]:
    version 0, type 0, secondary header, PID 65 / PCAT 12 (as in the real packets), unsegmented,
    sync marker, BAQ block length code 31 (256 samples)."""
    from sarcli.io.sentinel1.constants import SYNC_MARKER

    h = np.zeros(n, HEADER_DTYPE)
    h["secondary_header_flag"] = 1
    h["pid"] = 65
    h["pcat"] = 12
    h["sequence_flags"] = 3
    h["packet_sequence_count"] = np.arange(n) % (1 << 14)
    h["space_packet_count"] = np.arange(n)
    h["sync_marker"] = SYNC_MARKER
    h["baq_block_length"] = 31
    return h
