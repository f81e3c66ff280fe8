"""Radarsat-1 RAW leader values: the leader file's file descriptor (720 B), data set summary (4096 B), platform position
(8960 B) [S Table 4, B-6, B-7, B-13]. Decoding and encoding of the fields sarcli uses.

A RAW leader has no PRF, sampling rate, range gate or Doppler (those come from each line's aux block).
Fields blank in a real RAW leader decode to ``None``. The sarcli writer additionally fills the range
sampling rate (711-726, MHz), the range pulse phase coefficient 3 (647-662, the chirp rate in Hz/s,
as ASF MapReady reads it: ``chirp_rate = phas_coef[2]``) and the radar frequency (493-500, GHz), so that a
simulated product's chirp rate survives the round trip; the reader uses them only when present.

State vectors: positions in m, velocities in **mm/s** in the file (trap 5), m/s in sarcli; inertial
frame with a Greenwich mean hour angle (deg) at the first vector.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np

from sarcli.errors import FormatError
from sarcli.io.ceos import fields as F
from sarcli.io.ceos.records import file_descriptor, walk

FILE_DESCRIPTOR_BYTES = 720
DSS_BYTES = 4096
PLATFORM_BYTES = 8960
MAX_STATE_VECTORS = 64
_SV_FIRST = 387  # first byte of state vector 0; 132 bytes (6 x D22.15) per vector


@dataclass
class StateVectorRecord:
    """Platform position record contents: times as date + seconds of day, SI units."""

    first_date: _dt.date
    first_seconds_of_day: float
    spacing_s: float
    frame: str
    gha_deg: float | None
    position_m: np.ndarray  # (n, 3)
    velocity_mps: np.ndarray  # (n, 3)


@dataclass
class LeaderInfo:
    """Leader fields sarcli uses; ``None`` where the field is blank."""

    scene_centre_time: str
    pass_direction: str
    mission: str
    sensor_id: str
    orbit_number: str
    clock_angle_deg: float | None
    frequency_ghz: float | None
    wavelength_m: float
    chirp_rate_hz_per_s: float | None
    range_sampling_rate_mhz: float | None
    pulse_length_us: float | None
    bits_per_channel: int | None
    state_vectors: StateVectorRecord


def _parse_dss(rec: bytes, src: str) -> dict:
    return {
        "scene_centre_time": F.ascii_field(rec, 69, 100),
        "pass_direction": F.ascii_field(rec, 101, 116),
        "mission": F.ascii_field(rec, 397, 412),
        "sensor_id": F.ascii_field(rec, 413, 444),
        "orbit_number": F.ascii_field(rec, 445, 452),
        "clock_angle_deg": F.parse_real(rec, 477, 484, "sensor clock angle", src),
        "frequency_ghz": F.parse_real(rec, 493, 500, "radar frequency", src),
        "wavelength_m": F.require_value(F.parse_real(rec, 501, 516, "wavelength", src),
                                        "wavelength", 501, 516, src),
        "chirp_rate_hz_per_s": F.parse_real(rec, 647, 662, "range pulse phase coefficient 3", src),
        "range_sampling_rate_mhz": F.parse_real(rec, 711, 726, "range sampling rate", src),
        "pulse_length_us": F.parse_real(rec, 743, 758, "range pulse length", src),
        "bits_per_channel": F.parse_int(rec, 799, 806, "bits per channel", src),
    }


def _parse_platform(rec: bytes, src: str) -> StateVectorRecord:
    def need(v, name, a, b):
        return F.require_value(v, name, a, b, src)

    n = need(F.parse_int(rec, 141, 144, "number of state vectors", src), "number of state vectors", 141, 144)
    if not 2 <= n <= MAX_STATE_VECTORS:
        raise FormatError(f"{src}: {n} state vectors in the platform position record (need 2..64)")
    year = need(F.parse_int(rec, 145, 148, "year", src), "year", 145, 148)
    month = need(F.parse_int(rec, 149, 152, "month", src), "month", 149, 152)
    day = need(F.parse_int(rec, 153, 156, "day", src), "day", 153, 156)
    try:
        date = _dt.date(year, month, day)
    except ValueError:
        raise FormatError(f"{src}: state vector date {year}-{month}-{day} is not a date") from None
    sod = need(F.parse_real(rec, 161, 182, "seconds of day", src), "seconds of day", 161, 182)
    spacing = need(F.parse_real(rec, 183, 204, "state vector interval", src), "state vector interval", 183, 204)
    if not spacing > 0:
        raise FormatError(f"{src}: state vector interval {spacing} s is not positive")
    pv = np.empty((n, 6))
    for k in range(n):
        for j in range(6):
            a = _SV_FIRST + 132 * k + 22 * j
            pv[k, j] = need(F.parse_real(rec, a, a + 21, f"state vector {k + 1} component {j + 1}", src),
                            f"state vector {k + 1} component {j + 1}", a, a + 21)
    return StateVectorRecord(
        first_date=date, first_seconds_of_day=sod, spacing_s=spacing,
        frame=F.ascii_field(rec, 205, 268),
        gha_deg=F.parse_real(rec, 269, 290, "Greenwich mean hour angle", src),
        position_m=pv[:, :3].copy(), velocity_mps=pv[:, 3:] * 1e-3,
    )


def parse_leader(buf: bytes, src: str) -> LeaderInfo:
    """Walk the leader's records (``sarcli.io.ceos.records.walk``) and decode the data set summary and
    the state vectors."""
    if len(buf) >= F.HEADER_BYTES:
        first = F.parse_header(buf, 0)
        if first.codes == F.CODES_FILE_DESCRIPTOR and first.length != FILE_DESCRIPTOR_BYTES:
            raise FormatError(f"{src}: not a CEOS leader file (its file descriptor is {first.length} bytes, a "
                              f"leader's is {FILE_DESCRIPTOR_BYTES}; leader and data swapped?)")
    file_descriptor(buf, src, "CEOS leader file", min_length=FILE_DESCRIPTOR_BYTES)
    dss = platform = None
    w = walk(buf, src)
    for off, length in zip(w.offsets.tolist(), w.lengths.tolist(), strict=True):
        h = F.parse_header(buf, off)
        rec = bytes(buf[off:off + length])
        if h.codes == F.CODES_DATA_SET_SUMMARY:
            dss = _parse_dss(rec, src)
        elif h.codes == F.CODES_PLATFORM_POSITION:
            platform = _parse_platform(rec, src)
    if dss is None:
        raise FormatError(f"{src}: no data set summary record in the leader")
    if platform is None:
        raise FormatError(f"{src}: missing state vectors (no platform position record in the leader)")
    return LeaderInfo(state_vectors=platform, **dss)


def build_leader(info: LeaderInfo, software_id: str) -> bytes:
    """The three leader records (file descriptor, data set summary, platform position) as bytes."""
    fd = F.file_descriptor(FILE_DESCRIPTOR_BYTES, 1, "LEA_01.001", software_id)
    F.put(fd, 181, F.format_int(1, 6) + F.format_int(DSS_BYTES, 6) + F.format_int(0, 6) * 2)
    F.put(fd, 205, F.format_int(1, 6) + F.format_int(PLATFORM_BYTES, 6))
    for first in range(217, 361, 12):  # attitude .. remaining record pairs: none in RAW
        F.put(fd, first, F.format_int(0, 6) * 2)

    d = F.blank_record(2, F.CODES_DATA_SET_SUMMARY, DSS_BYTES)
    F.put(d, 13, F.format_int(1, 4) + F.format_int(1, 4))
    F.put(d, 69, F.format_text(info.scene_centre_time, 32))
    F.put(d, 101, F.format_text(info.pass_direction, 16))
    F.put(d, 165, F.format_text("INTERNATIONAL", 16))
    F.put(d, 181, F.format_real(6378.140, 16) + F.format_real(6356.755, 16))
    F.put(d, 397, F.format_text(info.mission, 16) + F.format_text(info.sensor_id, 32))
    F.put(d, 445, F.format_text(info.orbit_number, 8))
    if info.clock_angle_deg is not None:
        F.put(d, 477, F.format_real(info.clock_angle_deg, 8))
    if info.frequency_ghz is not None:
        F.put(d, 493, F.format_real(info.frequency_ghz, 8))
    F.put(d, 501, F.format_real(info.wavelength_m, 16))
    F.put(d, 519, F.format_text("LINEAR FM CHIRP", 16))
    if info.chirp_rate_hz_per_s is not None:
        for k in range(5):
            v = info.chirp_rate_hz_per_s if k == 2 else 0.0
            F.put(d, 615 + 16 * k, F.format_real(v, 16, "E"))
    if info.range_sampling_rate_mhz is not None:
        F.put(d, 711, F.format_real(info.range_sampling_rate_mhz, 16))
    if info.pulse_length_us is not None:
        F.put(d, 743, F.format_real(info.pulse_length_us, 16))
    if info.bits_per_channel is not None:
        F.put(d, 799, F.format_int(info.bits_per_channel, 8) + F.format_text("UNIFORM I,Q", 12))
    F.put(d, 1047, F.format_text("CDPF-RSAT", 16) + F.format_text("SARCLI", 8) + F.format_text("", 8))
    F.put(d, 1111, F.format_text("UNPROCESSED SIGNAL DATA", 32))
    F.put(d, 1527, F.format_text("INCREASE", 8) * 2)

    sv = info.state_vectors
    n = sv.position_m.shape[0]
    p = F.blank_record(3, F.CODES_PLATFORM_POSITION, PLATFORM_BYTES)
    F.put(p, 141, F.format_int(n, 4))
    date = sv.first_date
    F.put(p, 145, b"".join(F.format_int(v, 4) for v in
                          (date.year, date.month, date.day, date.timetuple().tm_yday)))
    F.put(p, 161, F.format_real(sv.first_seconds_of_day, 22, "D") + F.format_real(sv.spacing_s, 22, "D"))
    F.put(p, 205, F.format_text(sv.frame, 64))
    if sv.gha_deg is not None:
        F.put(p, 269, F.format_real(sv.gha_deg, 22, "D"))
    for k in range(n):
        vals = np.concatenate([sv.position_m[k], sv.velocity_mps[k] * 1e3])
        F.put(p, _SV_FIRST + 132 * k, b"".join(F.format_real(v, 22, "D") for v in vals))
    return bytes(fd) + bytes(d) + bytes(p)
