"""The Radarsat-1 50-byte auxiliary block of each signal record, and the timing it encodes.

Bit fields (byte index within the block, bits numbered MSB first; ASF MapReady ``aux_RSAT.c`` [A],
ISCE ``Radarsat1.py`` [I], UBC MATLAB readers [M]; see ``docs/ceos-radarsat-raw.md`` §3):

    bytes 0-3    sync marker 0x352EF853            byte 22 b7-6  number of beams - 1
    byte 10 b7-2 replica AGC (6 bit)               byte 22 b5-4  ADC rate code
    bytes 18-19  beam sequence (beam = low 5 bits) byte 25 + 26 b7-3  PRF code (13 bit)
    byte 27 + 28 b7-4  Rx window start code (12)   byte 29 + 30 b7-4  Rx window duration code (12)
    bytes 43-48  time: days 11, seconds 17, ms 10, us 10 bits
    byte 49      b6 replica present, b5-0 Rx AGC (dB)

Timing (``T_b`` = ADC clock period, ``f_s = 1/T_b``):

    T_b   = (4 + 3*adc) / 129.2683 MHz                f_s = 32.317075, 18.4669, 12.9268 MHz
    PRF   = 1 / (6 T_b (prf_code + 2))
    DWP   = 6 T_b (window_code + 5)                    (receive-window start after a transmit)
    N_s   = 6 (duration_code + 1)                      samples per line
    tau_0 = DWP + N_p / PRF - 4.04 us                  two-way time of the first sample
    R_0   = c/2 * tau_0                                slant range of the first sample

``N_p`` is the number of pulses in flight, from the beam number ([A] ``CONF_RSAT_pulsesInAirList``).
The fine beam F3 (beam 18) is 9 in [A] and 8 in [I]; sarcli follows [A] by default and lets the
caller choose (``f3_pulses_in_flight``); it is the only entry where the sources disagree.
The 4.04 us transmission delay is [A]'s corner-reflector calibration.

Line time of day = seconds + ms 1e-3 + us 1e-6 ([I]; [A] reads the last field as 1/1024 ms, at most
23 us apart; sarcli follows [I]).
"""

from __future__ import annotations

import numpy as np

AUX_BYTES = 50
AUX_SYNC = 0x352EF853
SMO_HZ = 129.2683e6  # satellite master oscillator [A]
TRANSMIT_DELAY_S = 4.04e-6  # [A], calibrated on corner reflectors
REPLICA_DURATION_S = 44.559e-6  # [A], [M]

# (bit offset from the start of the block, width) — MSB-first numbering.
FIELDS: dict[str, tuple[int, int]] = {
    "sync": (0, 32),
    "payload_status": (64, 16),
    "replica_agc": (80, 6),
    "beam_sequence": (144, 16),
    "n_beams_minus_1": (176, 2),
    "adc_code": (178, 2),
    "prf_code": (200, 13),
    "window_start_code": (216, 12),
    "window_duration_code": (232, 12),
    "days": (344, 11),
    "seconds": (355, 17),
    "milliseconds": (372, 10),
    "microseconds": (382, 10),
    "replica_present": (393, 1),
    "rx_agc": (394, 6),
}

BEAM_NAMES = ("", "ST1", "ST2", "ST3", "ST4", "ST5", "ST6", "ST7", "WD1", "WD2", "WD3", "WD2R",
              "EX1", "EX2", "EH4", "EX4", "FN1", "FN2", "FN3", "FN4", "FN5")
_PULSES_IN_FLIGHT_A = (0, 7, 7, 8, 8, 8, 9, 9, 7, 8, 9, 8, 10, 10, 11, 11, 8, 8, 9, 9, 9)
F3_BEAM = 18
# Beam the writer uses for a given number of pulses in flight (F3 avoided: the sources disagree).
WRITER_BEAM_FOR_PULSES = {7: 1, 8: 16, 9: 19, 10: 12, 11: 14}

# Range chirp slope by sampling rate ([A] config.h, [I]); the RAW product itself carries none.
CHIRP_SLOPE_FAST, CHIRP_SLOPE_MED, CHIRP_SLOPE_SLOW = -7.214e11, -4.1619e11, -2.7931e11


def get_field(aux: np.ndarray, name: str) -> np.ndarray:
    """Unsigned value of one bit field for every row of ``aux`` ((n, 50) uint8) -> (n,) int64.

    The bytes spanned by the field are assembled big-endian into one integer, then shifted and masked.
    """
    off, width = FIELDS[name]
    b0, b1 = off // 8, (off + width - 1) // 8
    acc = np.zeros(aux.shape[0], dtype=np.uint64)
    for b in range(b0, b1 + 1):
        acc = (acc << np.uint64(8)) | aux[:, b].astype(np.uint64)
    shift = (b1 + 1) * 8 - (off + width)
    return ((acc >> np.uint64(shift)) & np.uint64((1 << width) - 1)).astype(np.int64)


def set_field(aux: np.ndarray, name: str, value: np.ndarray | int) -> None:
    """Write ``value`` into one bit field of every row of ``aux`` ((n, 50) uint8), in place."""
    off, width = FIELDS[name]
    value = np.broadcast_to(np.asarray(value, dtype=np.int64), (aux.shape[0],))
    if np.any(value < 0) or np.any(value >= (1 << width)):
        raise ValueError(f"aux field {name} ({width} bit) cannot hold {value.min()}..{value.max()}")
    b0, b1 = off // 8, (off + width - 1) // 8
    shift = (b1 + 1) * 8 - (off + width)
    acc = np.zeros(aux.shape[0], dtype=np.uint64)
    for b in range(b0, b1 + 1):
        acc = (acc << np.uint64(8)) | aux[:, b].astype(np.uint64)
    mask = np.uint64(((1 << width) - 1) << shift)
    acc = (acc & ~mask) | ((value.astype(np.uint64) << np.uint64(shift)) & mask)
    for b in range(b1, b0 - 1, -1):
        aux[:, b] = (acc & np.uint64(0xFF)).astype(np.uint8)
        acc = acc >> np.uint64(8)


def clock_period_s(adc_code: np.ndarray | int) -> np.ndarray:
    """ADC clock period T_b (s) for ADC rate codes 0, 1, 2."""
    return (4.0 + 3.0 * np.asarray(adc_code, dtype=np.float64)) / SMO_HZ


def prf_from_code(prf_code, adc_code) -> np.ndarray:
    """PRF (Hz) = 1 / (6 T_b (code + 2))."""
    return 1.0 / (6.0 * clock_period_s(adc_code) * (np.asarray(prf_code, np.float64) + 2.0))


def dwp_from_code(window_code, adc_code) -> np.ndarray:
    """Receive-window start after the transmit, DWP (s) = 6 T_b (code + 5)."""
    return 6.0 * clock_period_s(adc_code) * (np.asarray(window_code, np.float64) + 5.0)


def samples_from_code(duration_code) -> np.ndarray:
    """Complex samples per echo line = 6 (code + 1)."""
    return 6 * (np.asarray(duration_code, np.int64) + 1)


def replica_samples(adc_code: int) -> int:
    """Complex samples of a chirp replica: floor(44.559 us / T_b) (1440 at 32.3 MHz)."""
    return int(np.floor(REPLICA_DURATION_S / float(clock_period_s(adc_code)) + 1e-9))


def pulses_in_flight(beam: int, f3_pulses_in_flight: int = 9) -> int:
    """Pulses in flight between transmit and the receive window for a beam number (1..20)."""
    if not 1 <= beam < len(_PULSES_IN_FLIGHT_A):
        raise ValueError(f"unknown Radarsat-1 beam number {beam}")
    return f3_pulses_in_flight if beam == F3_BEAM else _PULSES_IN_FLIGHT_A[beam]


def first_sample_time(window_code, prf_code, adc_code, n_pulses: int) -> np.ndarray:
    """Two-way time of the first sample: tau_0 = DWP + N_p / PRF - 4.04 us (s)."""
    return (dwp_from_code(window_code, adc_code) + n_pulses / prf_from_code(prf_code, adc_code)
            - TRANSMIT_DELAY_S)


def chirp_slope(fs_hz: float) -> float:
    """Nominal range chirp rate (Hz/s, down-chirp) by sampling rate ([A], [I])."""
    if fs_hz > 30e6:
        return CHIRP_SLOPE_FAST
    if fs_hz > 15e6:
        return CHIRP_SLOPE_MED
    return CHIRP_SLOPE_SLOW

