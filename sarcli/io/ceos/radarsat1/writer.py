"""``write_ceos``: a RawProduct -> Radarsat-1 CEOS RAW scene folder that ``read_ceos`` reads back exactly.

Files (CD layout [S §4.2.2]): ``VDF_DAT.001`` (volume descriptor, 3 file pointers, text record),
``LEA_01.001`` (file descriptor, data set summary, platform position), ``DAT_01.001`` (descriptor and
one signal record per line), ``TRA_01.001`` (file descriptor only). Each file is written to a
temporary name in the folder and renamed into place.

What must be representable (else one line and no files):

- echo: 4-bit odd levels -15..15 (the ``quantization`` effect), one channel, samples per line a
  multiple of 6 up to 24576 (receive window = 6 (code + 1) samples);
- sampling rate: one of the three ADC rates (32.317075, 18.4669, 12.9268 MHz), to 1e-9;
- PRF: 1 / (6 T_b (code + 2)) for a 13-bit code, to 1e-9 (constant over the scene);
- first-sample time tau_0 = 6 T_b (w + 5) + N_p/PRF - 4.04 us for a 12-bit code w and N_p in the beam
  table (7..11), to 1e-3 of a code step (0.19 ns at 32 MHz). The beam is the product's
  ``ceos_beam_number`` if it has one, else ST1/FN1/FN4/EX1/EH4 for N_p = 7/8/9/10/11 (never the
  disputed F3); N_p is chosen so that 0 <= DWP < 1/PRF when possible;
- azimuth times on the grid t_0 + n/PRF (to 1 us, the aux clock resolution); skipped pulses become
  missing lines in the file;
- AGC: integers 0..63 dB (absent -> 0);
- orbit: 2..64 equally spaced state vectors in ECI (ECEF is rotated to ECI by GMST, LOCAL refused).

The replica (if any) is stored on every 8th line from line 7 (as in the Vancouver scene); it is
written as is when it already holds floor(44.559 us f_s) 4-bit levels, otherwise it is scaled and
quantized to 4 bits (``samples.quantize_replica``) — the only lossy step, and reported in the product
read back as that quantized replica.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import os
import tempfile
from pathlib import Path

import numpy as np

from orbit.frames import ecef_to_eci, gmst
from orbit.timeutil import parse_utc
from sarcli import __version__
from sarcli.errors import SarcliError
from sarcli.io.ceos import fields as F
from sarcli.io.ceos.radarsat1 import aux as A
from sarcli.io.ceos.radarsat1.datafile import ECHO_START, build_descriptor
from sarcli.io.ceos.radarsat1.leader import LeaderInfo, StateVectorRecord, build_leader
from sarcli.io.ceos.radarsat1.samples import encode, is_four_bit, quantize_replica
from sarcli.io.ceos.signal import build_prefix
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import RawProduct

REPLICA_FIRST_LINE, REPLICA_PERIOD = 6, 8  # 0-based: lines 7, 15, 23, ... (1-based)
PAYLOAD_IMAGING = 0x8000  # (status >> 13) & 7 == 4: "imaging" per [A]
SOFTWARE_ID = f"SARCLI {__version__}"[:12]


class CeosExportError(SarcliError):
    """The product cannot be represented in Radarsat-1 CEOS RAW."""


SCENE_FILES = ("VDF_DAT.001", "LEA_01.001", "DAT_01.001", "TRA_01.001")  # every file write_ceos writes


def _refuse(msg: str) -> CeosExportError:
    return CeosExportError(f"cannot write CEOS RAW: {msg}")


def _adc_code(fs: float) -> int:
    for code in (0, 1, 2):
        exact = 1.0 / float(A.clock_period_s(code))
        if abs(exact - fs) <= 1e-9 * exact:
            return code
    raise _refuse(f"range sampling rate {fs} Hz is not a Radarsat-1 ADC rate (32.317075, 18.46690, "
                  "12.92683 MHz)")


def _prf_code(prf: float, adc: int) -> int:
    code = 1.0 / (6.0 * float(A.clock_period_s(adc)) * prf) - 2.0
    k = int(round(code))
    if not (0 <= k < 1 << 13 and abs(float(A.prf_from_code(k, adc)) - prf) <= 1e-9 * prf):
        raise _refuse(f"PRF {prf} Hz is not 1/(6 T_b (code+2)) for a 13-bit code (nearest code {k} gives "
                      f"{float(A.prf_from_code(k, adc)):.6f} Hz)")
    return k


def _window(tau0: float, prf_code: int, adc: int, beam_hint: int | None) -> tuple[int, int, int]:
    """(beam number, pulses in flight, window start code) reproducing tau0."""
    step = 6.0 * float(A.clock_period_s(adc))
    pri = 1.0 / float(A.prf_from_code(prf_code, adc))
    options = []
    for n_p, beam in A.WRITER_BEAM_FOR_PULSES.items():
        if beam_hint is not None and 1 <= beam_hint <= 20 and A.pulses_in_flight(beam_hint) == n_p:
            beam = beam_hint
        dwp = tau0 + A.TRANSMIT_DELAY_S - n_p * pri
        code = dwp / step - 5.0
        k = int(round(code))
        if 0 <= k < 1 << 12 and abs(code - k) <= 1e-3:
            options.append((not (0 <= dwp < pri), beam != beam_hint, beam, n_p, k))
    if not options:
        raise _refuse(f"window start {tau0 * 1e6:.4f} us (first range {C_LIGHT * tau0 / 2:.2f} m) is not "
                      "6 T_b (code+5) + N/PRF - 4.04 us for a 12-bit code and N = 7..11 pulses in flight")
    _, _, beam, n_p, k = min(options)
    return beam, n_p, k


def _pulse_grid(t: np.ndarray, prf: float) -> np.ndarray:
    n = np.rint((t - t[0]) * prf).astype(np.int64)
    if t.size > 1 and (np.any(np.diff(n) < 1) or np.max(np.abs(t - t[0] - n / prf)) > 1e-6):
        raise _refuse("azimuth times are not on the PRF grid t0 + n/PRF (to 1 us)")
    return n


def _orbit_record(raw: RawProduct) -> StateVectorRecord:
    o = raw.orbit
    if o is None:
        raise _refuse("the product has no state vectors (a CEOS leader needs them)")
    if o.frame == "LOCAL":
        raise _refuse("orbit frame LOCAL (airborne flat-Earth scene) has no CEOS RAW form")
    n = o.time.size
    if not 2 <= n <= 64:
        raise _refuse(f"{n} state vectors (the platform position record holds 2..64)")
    spacing = (o.time[-1] - o.time[0]) / (n - 1)
    if not spacing > 0 or np.max(np.abs(np.diff(o.time) - spacing)) > 1e-6:
        raise _refuse("state vectors are not equally spaced in time")
    pos, vel = np.asarray(o.position, np.float64), np.asarray(o.velocity, np.float64)
    if o.frame == "ECEF":
        pos, vel = ecef_to_eci(raw.epoch_utc, o.time, pos, vel)
    t_first = parse_utc(raw.epoch_utc) + _dt.timedelta(seconds=float(o.time[0]))
    midnight = t_first.replace(hour=0, minute=0, second=0, microsecond=0)
    return StateVectorRecord(
        first_date=t_first.date(), first_seconds_of_day=(t_first - midnight).total_seconds(),
        spacing_s=float(spacing), frame="INERTIAL", gha_deg=float(np.degrees(gmst(raw.epoch_utc, o.time[0]))),
        position_m=pos, velocity_mps=vel)


def _replica_levels(raw: RawProduct, adc: int) -> np.ndarray | None:
    if raw.replica is None:
        return None
    n = A.replica_samples(adc)
    r = np.asarray(raw.replica)
    if r.size == n and is_four_bit(r):
        return r.astype(np.complex64)
    return quantize_replica(r, n)


def _atomic_write(folder: Path, name: str, chunks) -> Path:
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            for c in chunks:
                f.write(c)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; a delivered scene is readable like any file
        os.replace(tmp, folder / name)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return folder / name


def _data_records(raw, times_us, year, doy, codes: dict, rep_levels, lines_per_chunk: int = 512):
    """Yield the data file: descriptor, then the signal records in chunks of lines."""
    n, ns = raw.echo.shape
    has_rep = np.zeros(n, bool)
    if rep_levels is not None:
        has_rep[REPLICA_FIRST_LINE::REPLICA_PERIOD] = True
    rep_bytes = encode(rep_levels) if rep_levels is not None else np.zeros(0, np.uint8)
    lengths = ECHO_START + has_rep * rep_bytes.size + 2 * ns
    yield build_descriptor(n, int(lengths.max()), ns, SOFTWARE_ID)
    us_of_day = times_us % 86_400_000_000
    agc = np.zeros(n, np.int64) if raw.agc_db is None else np.asarray(raw.agc_db).astype(np.int64)
    for a in range(0, n, lines_per_chunk):
        b = min(n, a + lines_per_chunk)
        m = b - a
        prefix = build_prefix(a, m, lengths[a:b], ns, year[a:b], doy[a:b], us_of_day[a:b] // 1000,
                              int(round(raw.radar.pulse_length_s * 1e9)))
        aux = np.zeros((m, A.AUX_BYTES), np.uint8)
        for name, v in codes.items():
            A.set_field(aux, name, v)
        A.set_field(aux, "days", doy[a:b])
        A.set_field(aux, "seconds", us_of_day[a:b] // 1_000_000)
        A.set_field(aux, "milliseconds", (us_of_day[a:b] // 1000) % 1000)
        A.set_field(aux, "microseconds", us_of_day[a:b] % 1000)
        A.set_field(aux, "replica_present", has_rep[a:b].astype(np.int64))
        A.set_field(aux, "rx_agc", agc[a:b])
        samples = encode(np.asarray(raw.echo[a:b]))
        out = bytearray()
        for k in range(m):
            out += prefix[k].tobytes() + aux[k].tobytes()
            if has_rep[a + k]:
                out += rep_bytes.tobytes()
            out += samples[k].tobytes()
        yield bytes(out)


def _volume(n_lines: int) -> bytes:
    vd = F.blank_record(1, F.CODES_VOLUME_DESCRIPTOR, 360)
    F.put(vd, 13, b"A ")
    F.put(vd, 17, F.format_text("CEOS-SAR-CCT", 12))
    F.put(vd, 45, F.format_text("SARCLI", 16))
    recs = [vd]
    for k, (name, cls) in enumerate((("LEA_01.001", "SAR LEADER FILE"), ("DAT_01.001", "SAR DATA FILE"),
                                      ("TRA_01.001", "SAR TRAILER FILE"))):
        fp = F.blank_record(2 + k, F.CODES_FILE_POINTER, 360)
        F.put(fp, 13, b"A ")
        F.put(fp, 17, F.format_int(k + 1, 4) + F.format_text(name, 16) + F.format_text(cls, 28))
        recs.append(fp)
    tx = F.blank_record(5, F.CODES_TEXT, 360)
    F.put(tx, 13, b"A ")
    F.put(tx, 17, F.format_text(f"PRODUCT:UNPROCESSED SIGNAL DATA, {n_lines} LINES, WRITTEN BY SARCLI", 40))
    recs.append(tx)
    return b"".join(bytes(r) for r in recs)


def check_representable(n_channels: int, n_samples: int, four_bit: bool, fs: float, prf: float, tau0: float,
                        beam_hint: int | None = None) -> tuple[int, int, tuple[int, int, int]]:
    """Refuse (one line, :class:`CeosExportError`) what CEOS RAW cannot hold, from the settings alone.

    Returns (ADC code, PRF code, (beam, pulses in flight, window start code)). Used by
    :func:`write_ceos` and, before any simulation, by ``sarcli simulate --format ceos``.
    """
    if n_channels != 1:
        raise _refuse(f"Radarsat-1 RAW holds one receive channel; the product has {n_channels}")
    if n_samples % 6 or n_samples > 6 * 4096:
        raise _refuse(f"{n_samples} samples per line is not 6 (code+1) for a 12-bit code (pad to a multiple of 6)")
    if not four_bit:
        raise _refuse("echo is not 4-bit quantized (odd levels -15..15); simulate with the quantization effect")
    adc = _adc_code(fs)
    prf_code = _prf_code(prf, adc)
    return adc, prf_code, _window(tau0, prf_code, adc, beam_hint)


def write_ceos(out_dir: str | os.PathLike, raw: RawProduct) -> tuple[Path, Path]:
    """Write ``raw`` as a Radarsat-1 CEOS RAW scene folder; return (leader path, data path).

    Refuses (one line, :class:`CeosExportError`) a product that CEOS RAW cannot hold exactly (module
    docstring). ``out_dir`` is created if needed (its parent must exist).
    """
    n, ns = raw.echo.shape
    r = raw.radar
    adc, prf_code, (beam, _, window_code) = check_representable(
        1 if raw.echo_channels is None else 2, ns, is_four_bit(raw.echo), r.range_sampling_rate_hz, r.prf_hz,
        r.window_start_s, raw.extra_attrs.get("ceos_beam_number"))
    if raw.prf_per_line is not None and np.ptp(raw.prf_per_line) > 0:
        raise _refuse("the PRF varies along the scene; sarcli's CEOS writer needs one PRF")
    if raw.agc_db is not None:
        agc = np.asarray(raw.agc_db, np.float64)
        if np.any(agc != np.rint(agc)) or agc.min() < 0 or agc.max() > 63:
            raise _refuse("AGC must be whole dB in 0..63 (6-bit aux field)")
    _pulse_grid(np.asarray(raw.azimuth_time, np.float64), r.prf_hz)
    sv = _orbit_record(raw)
    rep = _replica_levels(raw, adc)

    epoch = parse_utc(raw.epoch_utc)
    midnight = epoch.replace(hour=0, minute=0, second=0, microsecond=0)
    epoch_us = round((epoch - midnight).total_seconds() * 1e6)
    times_us = epoch_us + np.rint(np.asarray(raw.azimuth_time, np.float64) * 1e6).astype(np.int64)
    day_offset = times_us // 86_400_000_000
    dates = [midnight.date() + _dt.timedelta(days=int(d)) for d in np.unique(day_offset)]
    by_day = dict(zip(np.unique(day_offset).tolist(), dates, strict=True))
    year = np.array([by_day[int(d)].year for d in day_offset], np.int64)
    doy = np.array([by_day[int(d)].timetuple().tm_yday for d in day_offset], np.int64)

    mid = midnight + _dt.timedelta(microseconds=int(times_us[n // 2]))
    v_mid = sv.velocity_mps[sv.velocity_mps.shape[0] // 2]
    info = LeaderInfo(
        scene_centre_time=mid.strftime("%Y%m%d%H%M%S") + f"{mid.microsecond // 1000:03d}",
        pass_direction="ASCENDING" if v_mid[2] > 0 else "DESCENDING",
        mission="RSAT-1", sensor_id="RSAT-1-C -    -HH", orbit_number="",
        clock_angle_deg=90.0 if raw.look_side == "right" else -90.0,
        frequency_ghz=r.carrier_frequency_hz * 1e-9, wavelength_m=r.wavelength_m,
        chirp_rate_hz_per_s=r.chirp_rate_hz_per_s, range_sampling_rate_mhz=r.range_sampling_rate_hz * 1e-6,
        pulse_length_us=r.pulse_length_s * 1e6, bits_per_channel=4, state_vectors=sv)
    codes = {"sync": A.AUX_SYNC, "payload_status": PAYLOAD_IMAGING, "beam_sequence": beam,
             "n_beams_minus_1": 0, "adc_code": adc, "prf_code": prf_code, "window_start_code": window_code,
             "window_duration_code": ns // 6 - 1}

    folder = Path(out_dir)
    if not folder.parent.is_dir():
        raise _refuse(f"output folder {folder.parent} does not exist")
    folder.mkdir(exist_ok=True)
    vdf, lea_name, dat_name, tra = SCENE_FILES
    lea = _atomic_write(folder, lea_name, [build_leader(info, SOFTWARE_ID)])
    dat = _atomic_write(folder, dat_name, _data_records(raw, times_us, year, doy, codes, rep))
    _atomic_write(folder, tra, [bytes(F.file_descriptor(720, 3, tra, SOFTWARE_ID))])
    _atomic_write(folder, vdf, [_volume(n)])
    return lea, dat
