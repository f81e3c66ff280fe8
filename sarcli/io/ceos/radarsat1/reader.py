"""``read_ceos``: a Radarsat-1 CEOS RAW leader + signal data file pair -> :class:`RawProduct`.

What comes from where (see ``docs/ceos-radarsat-raw.md``):

- echo: 4-bit samples of every signal record (``samples.decode_lines``), replica bytes removed;
- PRF, sampling rate, receive window, replica flag, Rx AGC, line time: each line's aux block;
- first-sample two-way time tau_0 = DWP + N_p/PRF - 4.04 us, R_0 = c tau_0 / 2 (``aux``);
- date: the prefix year / day of year; time of day: the aux time (us resolution);
- carrier (c / wavelength), look side (clock angle), chirp rate and pulse length: the leader when the
  field is filled, else the nominal values of [A]/[I] (chirp slope by sampling rate, 42 us);
- 15 (2..64) ECI state vectors, velocities mm/s -> m/s, Greenwich hour angle kept as an attribute.

Azimuth time and missing lines. The aux clock steps are turned into whole pulse counts
g_k = round((t_k - t_{k-1}) PRF); g_k > 1 means g_k - 1 missing lines, g_k <= 0 is an error. Line k is
then put at n_k / PRF after the first line (n_k = sum of g), so the azimuth grid is exactly regular and
the clock's us quantization does not enter; the largest |t_k - t_0 - n_k/PRF| is reported
(``ceos_time_residual_max_s``). Policy for the missing lines (``missing``):

- ``"zero"`` (default): insert zero lines (no invented signal; a focuser sees a gap, not a copy),
  AGC carried from the previous line;
- ``"repeat"``: repeat the previous line (what ISCE and the CDPF processor do for short gaps);
- ``"keep"``: insert nothing; ``azimuth_time`` then has the gap (not uniform).

Gaps longer than ``max_gap`` lines (default 200, the CDPF limit [S §3.3.2]) are refused for "zero"
and "repeat". The gaps are stored as ``ceos_gaps`` ((n, 2): first line index after the gap in the
output grid, number of missing lines) and counted in ``ceos_missing_lines``.

The files are opened read-only (memory-mapped); nothing is ever written to them.
"""

from __future__ import annotations

import datetime as _dt
import os
from pathlib import Path

import numpy as np

from orbit.frames import gmst
from orbit.timeutil import format_utc
from sarcli.errors import FormatError, MissingFileError
from sarcli.io.ceos.radarsat1 import aux as A
from sarcli.io.ceos.radarsat1.datafile import ECHO_START, index_records
from sarcli.io.ceos.radarsat1.leader import parse_leader
from sarcli.io.ceos.radarsat1.samples import decode_lines, decode_reference
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import Orbit, Radar, RawProduct

MISSING_POLICIES = ("zero", "repeat", "keep")
NOMINAL_PULSE_LENGTH_S = 42e-6
_LEADER_NAMES = ("lea_01.001",)
_DATA_NAMES = ("dat_01.001",)
_MAX_LEADER_BYTES = 1 << 20


def find_scene_files(path: str | os.PathLike, data: str | os.PathLike | None = None) -> tuple[Path, Path]:
    """(leader, data) from two paths, or from a scene folder (``LEA_01.001``/``DAT_01.001``, any case,
    in the folder or its ``SCENE01`` sub-folder)."""
    path = Path(path)
    if data is not None:
        for p in (path, Path(data)):
            if not p.is_file():
                raise MissingFileError(f"{p}: no such file")
        return path, Path(data)
    if not path.is_dir():
        raise FormatError(f"{path}: give a leader and a data file, or a CEOS scene folder")
    for folder in (path, path / "SCENE01", path / "scene01"):
        if not folder.is_dir():
            continue
        files = {p.name.lower(): p for p in folder.iterdir() if p.is_file()}
        lea = next((files[n] for n in _LEADER_NAMES if n in files), None)
        dat = next((files[n] for n in _DATA_NAMES if n in files), None)
        if lea is not None and dat is not None:
            return lea, dat
    raise FormatError(f"{path}: no LEA_01.001 + DAT_01.001 pair in this folder or its SCENE01 sub-folder")


def _open_data(path: Path) -> np.ndarray:
    size = path.stat().st_size
    if size == 0:
        raise FormatError(f"{path}: empty file, not a CEOS data file")
    return np.memmap(path, dtype=np.uint8, mode="r")


def _single(values: np.ndarray, what: str, src: str) -> int:
    u = np.unique(values)
    if u.size != 1:
        k = int(np.flatnonzero(values != values[0])[0])
        raise FormatError(f"{src}: the {what} changes at line {k + 1} ({values[0]} -> {values[k]}); "
                          "a product needs one value per scene (not supported)")
    return int(u[0])


def _line_times(idx, src: str) -> tuple[_dt.datetime, np.ndarray]:
    """(UTC time of the first line, seconds of every line after it) from prefix date + aux time."""
    year, doy = idx.year, idx.day_of_year
    bad = np.flatnonzero((year < 1990) | (year > 2200) | (doy < 1) | (doy > 366))
    if bad.size:
        k = int(bad[0])
        raise FormatError(f"{src}: line {k + 1} prefix date year {year[k]} day {doy[k]} is not a date")
    a = idx.aux
    bad = np.flatnonzero((a["seconds"] >= 86401) | (a["milliseconds"] > 999) | (a["microseconds"] > 999))
    if bad.size:
        k = int(bad[0])
        raise FormatError(f"{src}: line {k + 1} aux time {a['seconds'][k]} s {a['milliseconds'][k]} ms "
                          f"{a['microseconds'][k]} us is not a time of day")
    jan1 = {int(y): _dt.date(int(y), 1, 1).toordinal() for y in np.unique(year)}
    days = np.array([jan1[int(y)] for y in year], np.int64) + doy - 1
    days -= days[0]
    us_of_day = a["seconds"] * 1_000_000 + a["milliseconds"] * 1000 + a["microseconds"]
    us = days.astype(np.int64) * 86_400_000_000 + us_of_day
    first = _dt.datetime(int(year[0]), 1, 1, tzinfo=_dt.UTC) + _dt.timedelta(
        days=int(doy[0]) - 1, microseconds=int(us_of_day[0]))
    return first, (us - us[0]) * 1e-6


def _pulse_counts(t: np.ndarray, prf: float, src: str) -> np.ndarray:
    """Whole pulse index of every line from the clock times (0 for the first line)."""
    steps = np.rint(np.diff(t) * prf).astype(np.int64)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        k = int(bad[0]) + 1
        raise FormatError(f"{src}: line time does not increase at line {k + 1} "
                          f"({t[k - 1]:.6f} s -> {t[k]:.6f} s after the first line)")
    return np.concatenate([[0], np.cumsum(steps)])


def _orbit(sv, epoch: _dt.datetime, src: str) -> tuple[Orbit, float | None]:
    frame_text = sv.frame.upper()
    if "INERTIAL" in frame_text or "ECI" in frame_text:
        frame = "ECI"
    elif "EARTH" in frame_text or "ECEF" in frame_text or "FIXED" in frame_text:
        frame = "ECEF"
    else:
        raise FormatError(f"{src}: state vector reference frame {sv.frame!r} is not inertial or Earth-fixed")
    t_first = _dt.datetime.combine(sv.first_date, _dt.time(), tzinfo=_dt.UTC)
    t0 = (t_first - epoch).total_seconds() + sv.first_seconds_of_day
    n = sv.position_m.shape[0]
    times = t0 + np.arange(n) * sv.spacing_s
    return Orbit(times, sv.position_m, sv.velocity_mps, frame), sv.gha_deg


def read_ceos(leader: str | os.PathLike, data: str | os.PathLike | None = None, keep_partial: bool = False,
              missing: str = "zero", max_gap: int = 200, f3_pulses_in_flight: int = 9) -> RawProduct:
    """Read a Radarsat-1 CEOS RAW scene (leader + data file, or a scene folder) into a RawProduct.

    ``keep_partial``: keep the complete lines of a truncated data file instead of refusing it.
    ``missing``: policy for missing lines, one of ``MISSING_POLICIES`` (module docstring).
    ``f3_pulses_in_flight``: pulses in flight for beam F3 (9 per ASF, 8 per ISCE).
    Any undecodable input raises :class:`FormatError` with one line.
    """
    if missing not in MISSING_POLICIES:
        raise FormatError(f"missing-line policy {missing!r} is not one of {', '.join(MISSING_POLICIES)}")
    lea_path, dat_path = find_scene_files(leader, data)
    if lea_path.stat().st_size > _MAX_LEADER_BYTES:
        raise FormatError(f"{lea_path}: {lea_path.stat().st_size} bytes is too large for a RAW leader file "
                          "(leader and data swapped?)")
    info = parse_leader(lea_path.read_bytes(), str(lea_path))
    src = str(dat_path)
    buf = _open_data(dat_path)
    idx = index_records(buf, src)
    if idx.truncated and not keep_partial:
        raise FormatError(f"{src}: data file truncated: {idx.n} of {idx.declared_records} lines complete; "
                          "use --keep-partial to ingest them")
    a = idx.aux
    adc = int(a["adc_code"][0])
    prf_code = _single(a["prf_code"], "PRF code", src)
    window_code = _single(a["window_start_code"], "receive-window start code", src)
    if np.any(a["n_beams_minus_1"] != 0):
        raise FormatError(f"{src}: ScanSAR (multi-beam) aux blocks; only single-beam stripmap RAW is supported")
    beam = _single(a["beam_sequence"] & 0x1F, "beam number", src)
    try:
        n_pulses = A.pulses_in_flight(beam, f3_pulses_in_flight)
    except ValueError as e:
        raise FormatError(f"{src}: {e}") from None
    fs = 1.0 / float(A.clock_period_s(adc))
    prf = float(A.prf_from_code(prf_code, adc))
    tau0 = float(A.first_sample_time(window_code, prf_code, adc, n_pulses))

    first_time, t_clock = _line_times(idx, src)
    counts = _pulse_counts(t_clock, prf, src)
    gap_after = np.flatnonzero(np.diff(counts) > 1)
    gaps = np.stack([counts[gap_after] + 1, np.diff(counts)[gap_after] - 1], axis=1) if gap_after.size \
        else np.zeros((0, 2), np.int64)
    if missing != "keep" and gaps.size and gaps[:, 1].max() > max_gap:
        k = int(np.argmax(gaps[:, 1]))
        raise FormatError(f"{src}: {gaps[k, 1]} lines missing after line {gap_after[k] + 1} (more than "
                          f"{max_gap}); split the scene or use --missing keep")
    rows = np.arange(idx.n) if missing == "keep" else counts
    n_out = idx.n if missing == "keep" else int(counts[-1]) + 1
    echo = np.zeros((n_out, idx.n_samples), dtype=np.complex64)
    bad = decode_lines(np.asarray(buf), idx.echo_offsets(), rows.astype(np.int64), idx.n_samples, echo)
    if bad:
        raise FormatError(f"{src}: {bad} sample bytes have a non-zero high nibble: not Radarsat-1 4-bit "
                          "RAW samples (packed level-0 data?)")
    agc = a["rx_agc"].astype(np.float32)
    if missing != "keep":
        rec_of_row = np.searchsorted(rows, np.arange(n_out), side="right") - 1  # last line read so far
        agc = agc[rec_of_row]
        filled = rows[rec_of_row] != np.arange(n_out)
        if missing == "repeat" and filled.any():
            echo[filled] = echo[rows[rec_of_row[filled]]]
    azimuth_time = (np.arange(n_out) if missing != "keep" else counts) / prf
    residual = t_clock - counts / prf

    rep_lines = np.flatnonzero(a["replica_present"] == 1)
    replica = None
    if rep_lines.size:
        o = int(idx.offsets[rep_lines[0]]) + ECHO_START
        replica = decode_reference(np.asarray(buf[o:o + idx.replica_bytes]))

    orbit, gha = _orbit(info.state_vectors, first_time, str(lea_path))
    wavelength = info.wavelength_m
    chirp = info.chirp_rate_hz_per_s if info.chirp_rate_hz_per_s else A.chirp_slope(fs)
    if info.pulse_length_us:
        pulse = info.pulse_length_us * 1e-6
    elif idx.chirp_length_ns[0] > 0:
        pulse = float(idx.chirp_length_ns[0]) * 1e-9
    else:
        pulse = NOMINAL_PULSE_LENGTH_S
    radar = Radar(
        carrier_frequency_hz=C_LIGHT / wavelength, wavelength_m=wavelength, prf_hz=prf,
        range_sampling_rate_hz=fs, chirp_rate_hz_per_s=chirp, pulse_length_s=pulse,
        window_start_s=tau0, first_range_m=C_LIGHT * tau0 / 2.0,
        quantization_bits=int(info.bits_per_channel or 4),
    )
    extra = {
        "ceos_leader_file": lea_path.name, "ceos_data_file": dat_path.name,
        "ceos_mission": info.mission, "ceos_sensor_id": info.sensor_id,
        "ceos_pass_direction": info.pass_direction, "ceos_scene_centre_time": info.scene_centre_time,
        "ceos_beam_number": beam, "ceos_beam_name": A.BEAM_NAMES[beam],
        "ceos_pulses_in_flight": n_pulses, "ceos_adc_code": adc, "ceos_prf_code": prf_code,
        "ceos_window_start_code": window_code,
        "ceos_window_duration_code": int(a["window_duration_code"][0]),
        "ceos_records_read": idx.n, "ceos_records_declared": idx.declared_records,
        "ceos_truncated": bool(idx.truncated),
        "ceos_replica_lines": rep_lines.astype(np.int64),
        "ceos_replica_effective_samples": int(round(pulse * fs)),
        "ceos_missing_policy": missing, "ceos_missing_lines": int(gaps[:, 1].sum()) if gaps.size else 0,
        "ceos_gaps": gaps.astype(np.int64),
        "ceos_time_residual_max_s": float(np.max(np.abs(residual))),
        "ceos_chirp_rate_source": "leader" if info.chirp_rate_hz_per_s else "nominal table by sampling rate",
        "ceos_bad_sync_lines": int(np.sum(a["sync"] != A.AUX_SYNC)),
    }
    if gha is not None:
        # The format does not say which equinox its "inertial" frame uses; the difference between the
        # delivered hour angle and sarcli's GMST at the first vector shows it (0 for sarcli's writer).
        gmst_deg = float(np.degrees(gmst(format_utc(first_time), orbit.time[0])))
        extra["ceos_gha_deg"] = gha
        extra["ceos_gha_minus_gmst_deg"] = (gha - gmst_deg + 180.0) % 360.0 - 180.0
    look = "left" if (info.clock_angle_deg is not None and info.clock_angle_deg < 0) else "right"
    return RawProduct(
        echo=echo, azimuth_time=azimuth_time.astype(np.float64), epoch_utc=format_utc(first_time),
        radar=radar, look_side=look, source="ceos", agc_db=agc, replica=replica, orbit=orbit,
        extra_attrs=extra,
    )
