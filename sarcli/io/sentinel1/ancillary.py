"""Orbit and attitude from the sub-commutated ancillary data, and GPS -> UTC time.

Each packet carries one 16-bit word of a 64-word ancillary data set with its index (1..64; 0 =
no data) [S1-ISP, §3.2.3]: words 1-22 are the PVT record (ECEF position, float64 m; ECEF velocity,
float32 m/s; GPS time stamp), words 23-41 the attitude record (quaternion Q0..Q3 of the body in
the ECI J2000 frame, Q0 real, float32; body angular rates, float32 rad/s; GPS time stamp; pointing
status), words 42-64 temperatures [S1-ISP, Tables 3.2-5, 3.2-6, 3.2-9]. A record is complete when
its words come in consecutive packets with consecutive indices. The same record is repeated until
the platform sends the next one (1 Hz): records are de-duplicated by time stamp.

The time stamps are 64-bit CCSDS CUC words whose last 56 bits are seconds in units of 2^-24
(32-bit integer seconds + 24-bit fraction) of GPS time [S1-ISP, Table 3.2-7].
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np

from orbit.timeutil import format_utc

#: UTC dates from which GPS - UTC grew by one second (IERS Bulletin C leap seconds since the GPS
#: epoch 1980-01-06, when GPS - UTC = 0). Valid up to the next announced leap second.
LEAP_SECOND_DATES = (
    "1981-07-01", "1982-07-01", "1983-07-01", "1985-07-01", "1988-01-01", "1990-01-01", "1991-01-01",
    "1992-07-01", "1993-07-01", "1994-07-01", "1996-01-01", "1997-07-01", "1999-01-01", "2006-01-01",
    "2009-01-01", "2012-07-01", "2015-07-01", "2017-01-01",
)
GPS_EPOCH_DT = _dt.datetime(1980, 1, 6, tzinfo=_dt.UTC)


def gps_minus_utc(gps_seconds: float) -> int:
    """GPS - UTC (s, leap seconds) at a GPS time given in seconds after the GPS epoch."""
    n = 0
    for k, day in enumerate(LEAP_SECOND_DATES):
        utc = _dt.datetime.fromisoformat(day).replace(tzinfo=_dt.UTC)
        # the k-th leap second takes effect at GPS time (utc - GPS epoch) + k + 1
        if gps_seconds >= (utc - GPS_EPOCH_DT).total_seconds() + k + 1:
            n = k + 1
    return n


def gps_to_utc_string(gps_seconds: float) -> str:
    """ISO-8601 UTC (microseconds) of a GPS time in seconds after the GPS epoch."""
    us = round((gps_seconds - gps_minus_utc(gps_seconds)) * 1e6)
    return format_utc(GPS_EPOCH_DT + _dt.timedelta(microseconds=us))


def utc_string_to_gps(epoch_utc: str) -> float:
    """Inverse of :func:`gps_to_utc_string` (seconds after the GPS epoch)."""
    from orbit.timeutil import parse_utc

    utc = (parse_utc(epoch_utc) - GPS_EPOCH_DT).total_seconds()
    leap = 0
    for _ in range(3):  # fixed point: GPS = UTC + leap(GPS)
        leap = gps_minus_utc(utc + leap)
    return utc + leap


def _words_to_bytes(words: np.ndarray) -> bytes:
    return np.asarray(words, ">u2").tobytes()


def cuc_time(words: np.ndarray) -> float:
    """GPS seconds of a 4-word (64-bit) time stamp: the last 56 bits in units of 2^-24 s."""
    value = int.from_bytes(_words_to_bytes(words), "big") & ((1 << 56) - 1)
    return value / 2.0**24


def cuc_words(seconds: float) -> np.ndarray:
    """Inverse of :func:`cuc_time` (rounded to 2^-24 s)."""
    value = round(seconds * 2.0**24)
    return np.frombuffer(value.to_bytes(8, "big"), ">u2").astype(np.uint16)


@dataclass
class Ancillary:
    """De-duplicated ancillary records, times in GPS seconds."""

    pvt_time: np.ndarray        # (n,)
    position: np.ndarray        # (n, 3) m, ECEF
    velocity: np.ndarray        # (n, 3) m/s, ECEF
    attitude_time: np.ndarray   # (m,)
    quaternion: np.ndarray      # (m, 4) Q0 (real), Q1, Q2, Q3: body in ECI J2000
    angular_rate: np.ndarray    # (m, 3) rad/s, body frame
    pointing_status: np.ndarray  # (m,) uint16 word 41


def _complete_runs(index: np.ndarray, first: int, last: int) -> np.ndarray:
    """Packet positions p where indices first..last appear in packets p..p+last-first."""
    n = last - first + 1
    if index.size < n:
        return np.zeros(0, np.int64)
    starts = np.flatnonzero(index[: index.size - n + 1] == first)
    ok = np.ones(starts.size, bool)
    for k in range(1, n):
        ok &= index[starts + k] == first + k
    return starts[ok]


def reassemble(index: np.ndarray, word: np.ndarray) -> Ancillary:
    """PVT and attitude records from the per-packet (word index, word) sequence in file order."""
    index = np.asarray(index, np.int64)
    word = np.asarray(word, np.uint16)
    pvt: dict[float, tuple] = {}
    for p in _complete_runs(index, 1, 22):
        w = word[p:p + 22]
        b = _words_to_bytes(w)
        pos = np.frombuffer(b[0:24], ">f8").astype(np.float64)
        vel = np.frombuffer(b[24:36], ">f4").astype(np.float64)
        pvt.setdefault(cuc_time(w[18:22]), (pos, vel))
    att: dict[float, tuple] = {}
    for p in _complete_runs(index, 23, 41):
        w = word[p:p + 19]
        b = _words_to_bytes(w)
        q = np.frombuffer(b[0:16], ">f4").astype(np.float64)
        rate = np.frombuffer(b[16:28], ">f4").astype(np.float64)
        if np.all(q == 0):  # no attitude in this set
            continue
        att.setdefault(cuc_time(w[14:18]), (q, rate, int(w[18])))
    tp = np.array(sorted(pvt), np.float64)
    ta = np.array(sorted(att), np.float64)
    return Ancillary(
        pvt_time=tp,
        position=np.array([pvt[t][0] for t in tp]).reshape(-1, 3),
        velocity=np.array([pvt[t][1] for t in tp]).reshape(-1, 3),
        attitude_time=ta,
        quaternion=np.array([att[t][0] for t in ta]).reshape(-1, 4),
        angular_rate=np.array([att[t][1] for t in ta]).reshape(-1, 3),
        pointing_status=np.array([att[t][2] for t in ta], np.uint16),
    )


def ancillary_words(t_gps: float, position, velocity, quaternion=(0.0, 0.0, 0.0, 0.0),
                    angular_rate=(0.0, 0.0, 0.0), t_attitude: float | None = None) -> np.ndarray:
    """The 64 words (index 1..64) of one ancillary set (inverse of :func:`reassemble`; temperatures 0)."""
    out = np.zeros(64, np.uint16)
    out[0:12] = np.frombuffer(np.asarray(position, ">f8").tobytes(), ">u2")
    out[12:18] = np.frombuffer(np.asarray(velocity, ">f4").tobytes(), ">u2")
    out[18:22] = cuc_words(t_gps)
    out[22:30] = np.frombuffer(np.asarray(quaternion, ">f4").tobytes(), ">u2")
    out[30:36] = np.frombuffer(np.asarray(angular_rate, ">f4").tobytes(), ">u2")
    out[36:40] = cuc_words(t_gps if t_attitude is None else t_attitude)
    return out
