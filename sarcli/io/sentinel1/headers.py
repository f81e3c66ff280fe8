"""Packet walking and header decoding of Sentinel-1 instrument source packets (ISP).

A Level-0 measurement file is a plain concatenation of space packets: a 6-octet primary header
(CCSDS), a 62-octet secondary header and the user data field [S1-ISP, §3]. The packet length is
``packet_data_length + 7`` octets [S1-ISP, §3.1, §3.3.1]. :func:`walk_packets` finds every packet's
offset; :func:`decode_headers` decodes all headers at once (vectorised over packets) into a numpy
structured array, one record per packet, with the raw codes of every field (names below) -- the
physical values are derived by :func:`physical`.

Bit positions: the specification numbers octets from the start of the packet and bits from the
most significant (bit 0); the offsets below are octets of the packet.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sarcli.errors import FormatError
from sarcli.io.sentinel1.constants import (
    DELTA_T_SUPPR_S,
    F_REF_HZ,
    HEADER_BYTES,
    RANGE_DECIMATION,
    SYNC_MARKER,
)

#: (name, numpy type, octet offset, bit offset from the msb of that octet, width in bits).
FIELDS: tuple[tuple[str, str, int, int, int], ...] = (
    # primary header [S1-ISP, Table 3.1-1]
    ("packet_version_number", "u1", 0, 0, 3),
    ("packet_type", "u1", 0, 3, 1),
    ("secondary_header_flag", "u1", 0, 4, 1),
    ("pid", "u1", 0, 5, 7),
    ("pcat", "u1", 1, 4, 4),
    ("sequence_flags", "u1", 2, 0, 2),
    ("packet_sequence_count", "u2", 2, 2, 14),
    ("packet_data_length", "u2", 4, 0, 16),
    # datation [S1-ISP, §3.2.1]
    ("coarse_time", "u4", 6, 0, 32),
    ("fine_time", "u2", 10, 0, 16),
    # fixed ancillary data [S1-ISP, §3.2.2]
    ("sync_marker", "u4", 12, 0, 32),
    ("data_take_id", "u4", 16, 0, 32),
    ("ecc_number", "u1", 20, 0, 8),
    ("test_mode", "u1", 21, 1, 3),
    ("rx_channel_id", "u1", 21, 4, 4),
    ("instrument_configuration_id", "u4", 22, 0, 32),
    # sub-commutated ancillary data [S1-ISP, §3.2.3]
    ("subcom_word_index", "u1", 26, 0, 8),
    ("subcom_word", "u2", 27, 0, 16),
    # counters [S1-ISP, §3.2.4]
    ("space_packet_count", "u4", 29, 0, 32),
    ("pri_count", "u4", 33, 0, 32),
    # radar configuration support [S1-ISP, §3.2.5]
    ("error_flag", "u1", 37, 0, 1),
    ("baq_mode", "u1", 37, 3, 5),
    ("baq_block_length", "u1", 38, 0, 8),
    ("range_decimation", "u1", 40, 0, 8),
    ("rx_gain", "u1", 41, 0, 8),
    ("tx_ramp_rate", "u2", 42, 0, 16),
    ("tx_pulse_start_frequency", "u2", 44, 0, 16),
    ("tx_pulse_length", "u4", 46, 0, 24),
    ("rank", "u1", 49, 3, 5),
    ("pri", "u4", 50, 0, 24),
    ("swst", "u4", 53, 0, 24),
    ("swl", "u4", 56, 0, 24),
    # SAS SSB data [S1-ISP, §3.2.5.13]: octet 60 bits 0-3 are the elevation beam address for
    # imaging/noise, or SAS test flag + cal type for calibration (ssb_flag = 1).
    ("ssb_flag", "u1", 59, 0, 1),
    ("polarisation", "u1", 59, 1, 3),
    ("temperature_compensation", "u1", 59, 4, 2),
    ("sas_beam_or_cal", "u1", 60, 0, 4),
    ("beam_address", "u2", 60, 6, 10),
    # SES SSB data [S1-ISP, §3.2.5.14]
    ("cal_mode", "u1", 62, 0, 2),
    ("tx_pulse_number", "u1", 62, 3, 5),
    ("signal_type", "u1", 63, 0, 4),
    ("swap", "u1", 63, 7, 1),
    ("swath_number", "u1", 64, 0, 8),
    # radar sample count [S1-ISP, §3.2.6]
    ("number_of_quads", "u2", 65, 0, 16),
)

#: The record of one packet: the fields above plus its byte offset in the file.
HEADER_DTYPE = np.dtype([("offset", "u8")] + [(name, typ) for name, typ, *_ in FIELDS])


@njit(cache=True)
def _walk(data: np.ndarray, start: int) -> tuple[np.ndarray, int]:
    """Offsets of consecutive packets from ``start``; returns (offsets, end of the last whole packet)."""
    n = data.size
    cap = max(16, n // 4096 + 16)
    out = np.empty(cap, np.int64)
    k = 0
    pos = start
    while pos + 6 <= n:
        length = ((np.int64(data[pos + 4]) << 8) | np.int64(data[pos + 5])) + 7
        if pos + length > n:
            break
        if k == out.size:
            grown = np.empty(out.size * 2, np.int64)
            grown[:k] = out[:k]
            out = grown
        out[k] = pos
        k += 1
        pos += length
    return out[:k], pos


def walk_packets(data: np.ndarray, where: str = "Level-0 file", allow_truncated: bool = False) -> np.ndarray:
    """Byte offsets of every packet in ``data`` (uint8). A trailing partial packet is refused with
    one line (or dropped with ``allow_truncated``); a packet too short for the headers is refused."""
    offsets, end = _walk(data, 0)
    if offsets.size == 0:
        raise FormatError(f"{where}: no complete space packet (file of {data.size} bytes)")
    if end != data.size and not allow_truncated:
        raise FormatError(f"{where}: truncated: {data.size - end} bytes after the last complete packet "
                          f"(packet {offsets.size} at byte {end} is incomplete)")
    lengths = np.diff(np.append(offsets, end))
    short = np.flatnonzero(lengths < HEADER_BYTES)
    if short.size:
        i = int(short[0])
        raise FormatError(f"{where}: packet {i} at byte {int(offsets[i])} is {int(lengths[i])} bytes long, "
                          f"shorter than its {HEADER_BYTES} header bytes")
    return offsets


def decode_headers(data: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """All packet headers as a structured array (:data:`HEADER_DTYPE`), raw codes."""
    rows = data[offsets[:, None] + np.arange(HEADER_BYTES)[None, :]]
    out = np.zeros(offsets.size, HEADER_DTYPE)
    out["offset"] = offsets
    for name, typ, octet, bit, width in FIELDS:
        n_bytes = (bit + width + 7) // 8
        word = np.zeros(offsets.size, np.uint64)
        for j in range(n_bytes):
            word = (word << np.uint64(8)) | rows[:, octet + j].astype(np.uint64)
        shift = np.uint64(8 * n_bytes - bit - width)
        out[name] = ((word >> shift) & np.uint64((1 << width) - 1)).astype(typ)
    return out


def check_headers(h: np.ndarray, where: str = "Level-0 file") -> None:
    """Refuse, in one line naming the first bad packet, what is not a Sentinel-1 SAR packet."""
    bad = np.flatnonzero(h["sync_marker"] != SYNC_MARKER)
    if bad.size:
        i = int(bad[0])
        raise FormatError(f"{where}: packet {i} at byte {int(h['offset'][i])}: sync marker "
                          f"{int(h['sync_marker'][i]):#010x}, expected {SYNC_MARKER:#010x} "
                          "(not a Sentinel-1 SAR packet, or a corrupted header)")
    bad = np.flatnonzero(h["secondary_header_flag"] != 1)
    if bad.size:
        i = int(bad[0])
        raise FormatError(f"{where}: packet {i} at byte {int(h['offset'][i])} has no secondary header")
    ud_len = h["packet_data_length"].astype(np.int64) + 7 - HEADER_BYTES
    bad = np.flatnonzero(ud_len % 4 != 0)
    if bad.size:
        i = int(bad[0])
        raise FormatError(f"{where}: packet {i} at byte {int(h['offset'][i])}: user data length {int(ud_len[i])} is "
                          "not a multiple of 4 octets (S1-IF-ASD-PL-0007 §3.3.1)")


def packet_time(h: np.ndarray) -> np.ndarray:
    """Datation of each packet, float64 seconds of GPS time: coarse + (fine + 0.5) 2^-16 [S1-ISP, §3.2.1]."""
    return h["coarse_time"].astype(np.float64) + (h["fine_time"].astype(np.float64) + 0.5) / 65536.0


def signed_code(code: np.ndarray) -> np.ndarray:
    """A 16-bit sign-and-magnitude code (bit 0 = polarity, 1 positive) as a signed integer
    [S1-ISP, §3.2.5.6, §3.2.5.7]."""
    c = np.asarray(code, np.int64)
    mag = c & 0x7FFF
    return np.where(c >> 15 == 1, mag, -mag)


def tx_ramp_rate_hz_per_s(code: np.ndarray) -> np.ndarray:
    """TXPRR = (-1)^(1-P) |code| f_ref^2 / 2^21 [MHz/us] [S1-ISP, §3.2.5.6], in Hz/s (1 MHz/us = 1e12 Hz/s).
    Positive for an up-chirp."""
    f_mhz = F_REF_HZ * 1e-6
    return signed_code(code) * (f_mhz * f_mhz / 2.0**21) * 1e12


def tx_start_frequency_hz(ramp_code: np.ndarray, start_code: np.ndarray) -> np.ndarray:
    """TXPSF = TXPRR / (4 f_ref) + (-1)^(1-P) |code| f_ref / 2^14 [MHz] [S1-ISP, §3.2.5.7], in Hz."""
    f_mhz = F_REF_HZ * 1e-6
    ramp_mhz_per_us = tx_ramp_rate_hz_per_s(ramp_code) * 1e-12
    return (ramp_mhz_per_us / (4.0 * f_mhz) + signed_code(start_code) * f_mhz / 2.0**14) * 1e6


def range_sampling_rate_hz(rgdec: int) -> float:
    """Sampling rate after decimation f_dec = (L/M) 4 f_ref [S1-ISP, §3.2.5.4]; one line for a bad code."""
    if int(rgdec) not in RANGE_DECIMATION:
        raise FormatError(f"range decimation code {int(rgdec)} is not defined (S1-IF-ASD-PL-0007 §3.2.5.4)")
    num, den, _, _ = RANGE_DECIMATION[int(rgdec)]
    return num / den * 4.0 * F_REF_HZ


def physical(h: np.ndarray) -> dict[str, np.ndarray]:
    """Physical values of the radar configuration (SI), per packet [S1-ISP, §3.2.5]."""
    return {
        "time_gps_s": packet_time(h),
        "rx_gain_db": -0.5 * h["rx_gain"].astype(np.float64),
        "tx_ramp_rate_hz_per_s": tx_ramp_rate_hz_per_s(h["tx_ramp_rate"]),
        "tx_start_frequency_hz": tx_start_frequency_hz(h["tx_ramp_rate"], h["tx_pulse_start_frequency"]),
        "tx_pulse_length_s": h["tx_pulse_length"].astype(np.float64) / F_REF_HZ,
        "pri_s": h["pri"].astype(np.float64) / F_REF_HZ,
        "swst_s": h["swst"].astype(np.float64) / F_REF_HZ,
        "swl_s": h["swl"].astype(np.float64) / F_REF_HZ,
        "delta_t_suppr_s": np.full(h.size, DELTA_T_SUPPR_S),
    }
