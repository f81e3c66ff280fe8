"""NISAR L0B ("RRSD") reader: raw echoes of every frequency and polarization -> sarcli raw products.

Layout read (``/science/{LSAR|SSAR}/``; ISCE3 ``nisar.products.readers.Raw``, [NISAR-L0B])::

    identification/lookDirection ("Right"/"Left"), orbitPassDirection, missionId, ...
    RRSD/swaths/frequency{A,B}/tx{H,V,L,R}/
        UTCtime            (n_lines,) transmit time of each pulse, epoch in its units attribute
        calType            (n_lines,) uint8: 0 = HPA (an echo), 1 = LNA, 2 = BYPASS (calibration lines)
        rangeLineIndex     (n_lines,) hardware line counter (a jump = lines lost)
        slantRange, slantRangeSpacing, centerFrequency, chirpSlope (signed), chirpDuration,
        rangeBandwidth, nominalAcquisitionPRF, numberOfSubSwaths, validSamplesSubSwath{k} (n_lines, 2)
        rx{H,V}/{TxRx}     (n_lines, n_samples): uint16 codes (r, i) into rx{H,V}/BFPQLUT (float32), or
                           complex32 (float16 pairs) / complex64 samples; _FillValue marks missing samples
    RRSD/lowRateTelemetry/orbit/{time, position, velocity}   ECEF (WGS-84) state vectors
    RRSD/lowRateTelemetry/attitude/{time, quaternions, eulerAngles}  RCS -> ECEF (see .attitude)

Conversions to sarcli's raw model (``sarcli.model.raw``):

- Samples: ``LUT[r] + j LUT[i]`` (complex64); a fill-value code gives 0; samples outside the valid-sample
  windows ``[start, stop)`` (transmit gaps) are set to 0.
- Timing: in the L0B, ``slantRange[k]`` is the range whose echo STARTS at sample k (ISCE3 compresses with
  the ``full`` correlation and moves the start range by ``first_valid_sample = n_chirp - 1`` samples: the
  peak of a point at range R lands at the slant range R), and ``UTCtime`` is the start of the pulse.
  sarcli measures both from the pulse CENTRE (``sarcli.focus.rangecomp``: the echo of range R is centred
  on 2R/c). Hence ``azimuth_time = UTCtime + T/2`` and ``window_start_s = 2 slantRange[0]/c - T/2``,
  ``first_range_m = slantRange[0] - c T/4`` (T = chirpDuration); the receive time of every sample is
  unchanged.
- Chirp: ``range_sampling_rate_hz = c / (2 slantRangeSpacing)`` (as ISCE3), ``chirp_rate_hz_per_s =
  chirpSlope`` (same sign convention: transmitted phase +pi K t^2), the replica ``exp(j pi K t^2)``,
  |t| <= T/2 at that rate (the baseband chirp; ``centerFrequency`` is the carrier).
- Calibration lines (calType != 0) are never echoes: their slots in ``echo`` are zero lines (the PRF grid
  stays uniform, as for a lost line), their samples go to ``RawProduct.auxiliary`` under ``calibration/``
  (``echo`` (n_cal, n_channels, n_samples), ``line`` (index in the product), ``cal_type``, ``azimuth_time``).
- Channels: the receive polarizations of one transmit group share the pulse times and the range grid
  and become the channels of one product (``echo`` = first, ``echo_channels`` = the others, in the order
  of the root attribute ``polarizations``); groups whose grids differ (another frequency, or interleaved
  transmit polarizations) are separate products named ``"A_HH_HV"``.
- Orbit: ECEF state vectors as delivered (sarcli interpolates them with its Hermite interpolator).
  Attitude: quaternions -> pitch and yaw of the beam-centre plane (``.attitude``); roll = the
  telemetry's Euler roll when present.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from orbit.errors import OrbitError
from orbit.statevectors import StateVectors
from sarcli.errors import ConfigError, FormatError
from sarcli.io.nisar.attitude import model_attitude
from sarcli.io.nisar.h5util import (
    band_root,
    is_hdf5,
    member_names,
    need,
    number,
    open_h5,
    optional_text,
    seconds_between,
    text,
    time_axis,
)
from sarcli.model.constants import C_LIGHT
from sarcli.model.plausible import sample_windows
from sarcli.model.raw import Attitude, Orbit, Radar, RawProduct

CAL_TYPES = {0: "HPA", 1: "LNA", 2: "BYPASS"}
BLOCK_LINES = 1024  # lines decoded at a time (bounded memory on full frames)
_TX = re.compile(r"^tx([HVLR])$")
_RX = re.compile(r"^rx([HV])$")
_FREQ = re.compile(r"^frequency([A-Z])$")


@dataclass
class L0BContents:
    """What :func:`read_l0b` returns: the raw products by name and notes for the user."""

    products: dict[str, RawProduct]
    notes: list[str] = field(default_factory=list)


def sniff_l0b(path: str | os.PathLike) -> bool:
    """True when ``path`` is an HDF5 file with a NISAR ``/science/{L,S}SAR/RRSD`` group."""
    if not is_hdf5(path):
        return False
    try:
        with h5py.File(path, "r") as f:
            return any(isinstance(f.get(f"science/{b}/RRSD"), h5py.Group) for b in ("LSAR", "SSAR"))
    except (OSError, RuntimeError, KeyError, ValueError):  # h5py on a damaged file: not sniffable
        return False


def _find(group: h5py.Group, name: str) -> str | None:
    """Member of ``group`` named ``name`` ignoring case (the spec renamed UTCTime -> UTCtime)."""
    for k in group:
        if k.lower() == name.lower():
            return k
    return None


@dataclass
class _Grid:
    """One transmit group's pulse times, range grid and chirp (what channels must share)."""

    freq: str
    tx: str
    epoch: str
    t_tx: np.ndarray
    slant_range: np.ndarray
    spacing: float
    fc: float
    k: float
    pulse: float
    bandwidth: float | None
    nominal_prf: float | None
    cal_type: np.ndarray
    line_index: np.ndarray | None
    windows: np.ndarray  # (n_sub, n_lines, 2)
    rx: list[tuple[str, h5py.Dataset]]

    def key(self) -> tuple:
        return (self.freq, self.epoch, self.t_tx.tobytes(), self.slant_range.tobytes(), self.fc, self.k, self.pulse)


def _read_grid(txg: h5py.Group, freq: str, tx: str, path: Path, notes: list[str]) -> _Grid:
    name = _find(txg, "UTCtime")
    if name is None:
        raise FormatError(f"{path}: incomplete NISAR L0B: {txg.name}/UTCtime missing")
    epoch, t = time_axis(txg[name], path)
    n = t.size
    if n < 2:
        raise FormatError(f"{path}: {txg.name} holds {n} range line(s); at least 2 are needed")
    if not np.all(np.diff(t) > 0):
        raise FormatError(f"{path}: {txg.name}/{name} is not strictly increasing")
    sr_ds = need(txg, "slantRange", path)
    sr = np.asarray(sr_ds[()], np.float64).reshape(-1)
    spacing = number(txg, "slantRangeSpacing", path, positive=True)
    if sr.size < 2 or not np.all(np.isfinite(sr)) or np.max(np.abs(np.diff(sr) - spacing)) > 1e-6 * spacing:
        raise FormatError(f"{path}: {sr_ds.name} is not a uniform grid of spacing slantRangeSpacing = {spacing} m")
    fc = number(txg, "centerFrequency", path, positive=True)
    k = number(txg, "chirpSlope", path)
    pulse = number(txg, "chirpDuration", path, positive=True)
    if k == 0:
        raise FormatError(f"{path}: {txg.name}/chirpSlope is zero")
    bw = number(txg, "rangeBandwidth", path, positive=True) if "rangeBandwidth" in txg else None
    prf = number(txg, "nominalAcquisitionPRF", path, positive=True) if "nominalAcquisitionPRF" in txg else None
    if "calType" in txg:
        cal = np.asarray(txg["calType"][()]).astype(np.int64).reshape(-1)
        if cal.size != n:
            raise FormatError(f"{path}: {txg.name}/calType has {cal.size} entries for {n} range lines")
    else:
        cal = np.zeros(n, np.int64)
        notes.append(f"{txg.name}: no calType: every line taken as an echo")
    idx = None
    if "rangeLineIndex" in txg:
        idx = np.asarray(txg["rangeLineIndex"][()]).astype(np.int64).reshape(-1)
        if idx.size != n:
            raise FormatError(f"{path}: {txg.name}/rangeLineIndex has {idx.size} entries for {n} range lines")
        jumps = np.diff(idx)
        if np.any(jumps != 1):
            lost = int(np.sum(np.clip(jumps - 1, 0, None)))
            notes.append(f"{txg.name}: rangeLineIndex jumps at {int(np.count_nonzero(jumps != 1))} place(s) "
                         f"({lost} line(s) lost): the pulse times are not uniform there")
    n_sub = int(number(txg, "numberOfSubSwaths", path)) if "numberOfSubSwaths" in txg else 0
    windows = []
    for s in range(1, max(n_sub, 1) + 1):
        key = f"validSamplesSubSwath{s}"
        if key not in txg:
            if n_sub:
                raise FormatError(f"{path}: incomplete NISAR L0B: {txg.name}/{key} missing "
                                  f"(numberOfSubSwaths = {n_sub})")
            break
        w = np.asarray(txg[key][()]).astype(np.int64)
        if w.shape != (n, 2):
            raise FormatError(f"{path}: {txg.name}/{key} has shape {w.shape}, expected ({n}, 2)")
        sample_windows(str(path), f"{txg.name}/{key}", w, sr.size)
        windows.append(w)
    if not windows:
        windows = [np.tile(np.array([0, sr.size], np.int64), (n, 1))]
        notes.append(f"{txg.name}: no validSamplesSubSwath: every sample taken as valid")
    rx = []
    for rname in member_names(txg):
        m = _RX.match(rname)
        if m is None or not isinstance(txg[rname], h5py.Group):
            continue
        pol = tx + m.group(1)
        rxg = txg[rname]
        rx.append((pol, need(rxg, pol, path)))
    if not rx:
        raise FormatError(f"{path}: {txg.name} has no rx{{H,V}} group with echo data")
    return _Grid(freq, tx, epoch, t, sr, spacing, fc, k, pulse, bw, prf, cal, idx, np.stack(windows), rx)


def _lut(ds: h5py.Dataset, path: Path) -> np.ndarray | None:
    g = ds.parent
    if "BFPQLUT" not in g:
        return None
    lut = np.asarray(g["BFPQLUT"][()])
    if lut.ndim != 1 or lut.dtype.kind != "f" or lut.size < 2:
        raise FormatError(f"{path}: {g.name}/BFPQLUT must be a 1-D float table, has shape {lut.shape} "
                          f"dtype {lut.dtype}")
    return lut.astype(np.float32, copy=False)


def decode_codes(codes: np.ndarray, lut: np.ndarray, fill: int | None) -> np.ndarray:
    """complex64 samples ``lut[r] + j lut[i]`` of a block of (r, i) uint16 codes; fill codes -> 0."""
    out = np.empty(codes.shape, np.complex64)
    out.real = lut[codes["r"]]
    out.imag = lut[codes["i"]]
    if fill is not None:
        out[(codes["r"] == fill) | (codes["i"] == fill)] = 0
    return out


def _decode_channel(ds: h5py.Dataset, grid: _Grid, path: Path, out: np.ndarray, notes: list[str]) -> np.ndarray:
    """Decode every line of ``ds`` into ``out`` (n_lines, n_samples), samples outside the valid windows
    zeroed; returns a histogram of the codes used (65536 bins; empty for float storage)."""
    from sarcli.io.nisar.h5util import complex_rows

    n, ns = out.shape
    if ds.ndim != 2 or ds.shape != (n, ns):
        raise FormatError(f"{path}: {ds.name} has shape {ds.shape}, expected ({n}, {ns}) from UTCtime and "
                          "slantRange")
    lut = _lut(ds, path)
    hist = np.zeros(0, np.int64)
    fill_attr = ds.attrs.get("_FillValue")
    fill = int(np.asarray(fill_attr).reshape(-1)[0]) if fill_attr is not None else None
    if lut is not None:
        names = ds.dtype.names or ()
        if set(names) != {"r", "i"} or ds.dtype["r"].kind != "u" or ds.dtype["i"].kind != "u":
            raise FormatError(f"{path}: {ds.name} has dtype {ds.dtype}; with a BFPQLUT the samples must be "
                              "unsigned integer code pairs (r, i)")
        hist = np.zeros(max(lut.size, 65536), np.int64)
    n_fill = 0
    for a in range(0, n, BLOCK_LINES):
        b = min(n, a + BLOCK_LINES)
        keep = valid_mask(grid.windows[:, a:b], ns)
        if lut is not None:
            codes = ds[a:b]
            top = int(max(codes["r"].max(), codes["i"].max()))
            if top >= lut.size:
                raise FormatError(f"{path}: {ds.name} holds code {top}, beyond its {lut.size}-entry BFPQLUT")
            block = decode_codes(codes, lut, fill)
            for part in (codes["r"][keep], codes["i"][keep]):
                hist += np.bincount(part, minlength=hist.size)
            if fill is not None:
                n_fill += int(np.count_nonzero(((codes["r"] == fill) | (codes["i"] == fill)) & keep))
        else:
            block = complex_rows(ds, a, b)
        if not np.all(np.isfinite(block[keep].view(np.float32))):
            raise FormatError(f"{path}: {ds.name} decodes to NaN or inf samples (lines {a}..{b - 1})")
        block[~keep] = 0
        out[a:b] = block
    if fill is not None and 0 <= fill < hist.size:
        hist[fill] = 0  # a missing sample, not a quantization level
    if lut is not None and not np.all(np.isfinite(lut[np.flatnonzero(hist[:lut.size])])):
        raise FormatError(f"{path}: BFPQLUT of {ds.name} maps codes in use to NaN or inf")
    if n_fill:
        notes.append(f"{ds.name}: {n_fill} fill-value (missing) sample(s) inside the valid windows, set to 0")
    return hist


def valid_mask(windows: np.ndarray, n_samples: int) -> np.ndarray:
    """(n_lines, n_samples) bool: inside the union of the windows [start, stop) (n_sub, n_lines, 2)."""
    cols = np.arange(n_samples)
    keep = np.zeros((windows.shape[1], n_samples), bool)
    for w in windows:
        keep |= (cols[None, :] >= np.clip(w[:, :1], 0, n_samples)) & (cols[None, :] < np.clip(w[:, 1:], 0, n_samples))
    return keep


def _orbit(tel: h5py.Group, path: Path, epoch: str) -> tuple[Orbit, StateVectors]:
    og = need(tel, "orbit", path, "group")
    o_epoch, t = time_axis(need(og, "time", path), path)
    pos = np.asarray(need(og, "position", path)[()], np.float64)
    vel = np.asarray(need(og, "velocity", path)[()], np.float64)
    t = t + seconds_between(o_epoch, epoch)
    try:
        sv = StateVectors(t, pos, vel, "ECEF", epoch)
    except OrbitError as e:
        raise FormatError(f"{path}: {og.name}: {e}") from None
    return Orbit(t, pos, vel, "ECEF"), sv


def _attitude(tel: h5py.Group, path: Path, epoch: str, sv: StateVectors, side: str,
              notes: list[str]) -> Attitude | None:
    ag = tel.get("attitude")
    if not isinstance(ag, h5py.Group):
        notes.append("no attitude telemetry: the Doppler centroid predicted from orbit + attitude assumes "
                     "zero pitch and yaw")
        return None
    a_epoch, t = time_axis(need(ag, "time", path), path)
    q = np.asarray(need(ag, "quaternions", path)[()], np.float64)
    if q.ndim != 2 or q.shape != (t.size, 4):
        raise FormatError(f"{path}: {ag.name}/quaternions has shape {q.shape}, expected ({t.size}, 4)")
    t = t + seconds_between(a_epoch, epoch)
    roll = None
    if isinstance(ag.get("eulerAngles"), h5py.Dataset):
        e = np.asarray(ag["eulerAngles"][()], np.float64)
        if e.shape == (t.size, 3) and np.all(np.isfinite(e)):
            unit = text(ag["eulerAngles"].attrs.get("units", b"degrees")).lower()
            roll = e[:, 0] if unit.startswith("rad") else np.radians(e[:, 0])
    t0, t1 = sv.span
    inside = (t >= t0) & (t <= t1)
    if not np.any(inside):
        notes.append("attitude records lie outside the orbit span: not used")
        return None
    if not np.all(inside):
        notes.append(f"{int(np.count_nonzero(~inside))} attitude record(s) outside the orbit span dropped")
    return model_attitude(t[inside], q[inside], sv, side, None if roll is None else roll[inside],
                          f"{path}: {ag.name}")


def _look_side(ident: h5py.Group | None, path: Path) -> str:
    if ident is None or "lookDirection" not in ident:
        raise FormatError(f"{path}: incomplete NISAR product: identification/lookDirection missing")
    side = text(ident["lookDirection"]).lower()
    if side not in ("right", "left"):
        raise FormatError(f"{path}: identification/lookDirection is {side!r}, not Right or Left")
    return side


def _pass_direction(ident: h5py.Group | None, sv: StateVectors, t_mid: float, notes: list[str]) -> str:
    """"ascending"/"descending": the orbit's (ECEF z velocity at mid-scene); the file's label is checked."""
    _, v, _ = sv.interpolate(np.array([np.clip(t_mid, *sv.span)]))
    from_orbit = "ascending" if v[0, 2] > 0 else "descending"
    label = optional_text(ident, "orbitPassDirection").lower() if ident is not None else ""
    if label and not from_orbit.startswith(label[:4]):
        notes.append(f"identification/orbitPassDirection says {label!r} but the orbit is {from_orbit} at "
                     "mid-scene: the orbit's is used")
    return from_orbit


def _chirp(k: float, pulse: float, fs: float) -> np.ndarray:
    n = int(round(pulse * fs))
    t = (np.arange(n) - 0.5 * (n - 1)) / fs
    return np.exp(1j * np.pi * k * t * t).astype(np.complex64)


def _quantization_bits(hists: list[np.ndarray]) -> int:
    """Bits needed for the distinct codes in use (0: samples stored as floats)."""
    if not hists or hists[0].size == 0:
        return 0
    used = np.count_nonzero(np.sum(hists, axis=0))
    return int(np.ceil(np.log2(max(used, 2))))


def _product(grids: list[_Grid], path: Path, ident: h5py.Group | None, band: str, side: str,
             orbit: Orbit, sv: StateVectors, attitude: Attitude | None, notes: list[str]) -> tuple[str, RawProduct]:
    g = grids[0]
    channels = [(pol, ds) for gr in grids for pol, ds in gr.rx]
    n, ns = g.t_tx.size, g.slant_range.size
    echo_rows = np.flatnonzero(g.cal_type == 0)
    cal_rows = np.flatnonzero(g.cal_type != 0)
    if echo_rows.size < 2:
        raise FormatError(f"{path}: {g.freq}/tx{g.tx} has {echo_rows.size} echo line(s) (calType 0); at least 2 "
                          "are needed")
    data = np.empty((len(channels), n, ns), np.complex64)
    hists = [_decode_channel(ds, g, path, data[c], notes) for c, (_, ds) in enumerate(channels)]
    cal = {}
    if cal_rows.size:
        cal = {"calibration/echo": data[:, cal_rows].transpose(1, 0, 2).copy(),
               "calibration/line": cal_rows.astype(np.int64),
               "calibration/cal_type": g.cal_type[cal_rows].astype(np.uint8),
               "calibration/azimuth_time": g.t_tx[cal_rows] + 0.5 * g.pulse}
        data[:, cal_rows] = 0
        kinds = ", ".join(f"{int(np.count_nonzero(g.cal_type == c))} {CAL_TYPES.get(int(c), f'type {c}')}"
                          for c in np.unique(g.cal_type[cal_rows]))
        notes.append(f"{g.freq}/tx{g.tx}: {cal_rows.size} calibration line(s) ({kinds}) kept apart, their slots "
                     "zeroed in the echo")
    fs = C_LIGHT / (2.0 * g.spacing)
    t = g.t_tx + 0.5 * g.pulse
    dt = np.diff(t)
    med = float(np.median(dt))
    prf_per_line = None
    if np.max(np.abs(dt - med)) > 1e-3 * med:
        prf_per_line = 1.0 / np.r_[dt, dt[-1]]
        notes.append(f"{g.freq}/tx{g.tx}: pulse spacing varies ({1 / dt.max():.3f}..{1 / dt.min():.3f} Hz): "
                     "PRF per line stored")
    window_start = 2.0 * g.slant_range[0] / C_LIGHT - 0.5 * g.pulse
    radar = Radar(carrier_frequency_hz=g.fc, wavelength_m=C_LIGHT / g.fc, prf_hz=1.0 / med,
                  range_sampling_rate_hz=fs, chirp_rate_hz_per_s=g.k, pulse_length_s=g.pulse,
                  window_start_s=window_start, first_range_m=0.5 * C_LIGHT * window_start,
                  quantization_bits=_quantization_bits(hists), receiver_offsets_m=(0.0,) * len(channels))
    mid = g.windows[:, n // 2, :]
    pols = [p for p, _ in channels]
    extra: dict[str, Any] = {
        "polarizations": ",".join(pols), "pass_direction": _pass_direction(ident, sv, float(t[n // 2]), notes),
        "nisar_product": "L0B RRSD", "nisar_band": band, "nisar_frequency": g.freq,
        "nisar_mission_id": optional_text(ident, "missionId") if ident is not None else "",
        "nisar_slant_range_first_m": float(g.slant_range[0]),
        "nisar_valid_samples": np.clip(mid, 0, ns).astype(np.int64),
        "nisar_valid_samples_vary": bool(np.any(g.windows != g.windows[:, :1, :])),
        "nisar_calibration_lines": int(cal_rows.size),
        "nisar_cal_type_names": ", ".join(f"{k} = {v}" for k, v in CAL_TYPES.items()),
        "nisar_timing": "azimuth_time = UTCtime + chirpDuration/2, window_start_s = 2 slantRange[0]/c - "
                        "chirpDuration/2 (sarcli measures from the pulse centre, the L0B from its start)",
    }
    if g.bandwidth is not None:
        extra["nisar_range_bandwidth_hz"] = g.bandwidth
    if g.nominal_prf is not None:
        extra["nisar_nominal_prf_hz"] = g.nominal_prf
    if np.any(g.windows[:, :, 1] > ns):
        notes.append(f"{g.freq}/tx{g.tx}: valid-sample windows reach sample {int(g.windows[:, :, 1].max())}, beyond "
                     f"the {ns} samples stored (a range cut): clipped")
    p = RawProduct(echo=data[0], azimuth_time=t, epoch_utc=g.epoch, radar=radar, look_side=side,
                   source="nisar-l0b", echo_channels=data[1:] if len(channels) > 1 else None,
                   prf_per_line=prf_per_line, replica=_chirp(g.k, g.pulse, fs), orbit=orbit, attitude=attitude,
                   extra_attrs=extra, auxiliary=cal)
    return "_".join([g.freq, *pols]), p


def read_l0b(path: str | os.PathLike, frequencies: tuple[str, ...] = (),
             polarizations: tuple[str, ...] = ()) -> L0BContents:
    """Read a NISAR L0B file (module docstring): every frequency/polarization, or those asked for.

    ``frequencies``: e.g. ("A",); ``polarizations``: e.g. ("HH", "HV"). Bad or partial files raise
    :class:`~sarcli.errors.FormatError` (one line); asking for what the file lacks raises ConfigError.
    """
    path = Path(path)
    notes: list[str] = []
    with open_h5(path) as f:
        band, sci, _ = band_root(f, path, "RRSD")
        ident = sci.get("identification") if isinstance(sci.get("identification"), h5py.Group) else None
        rrsd = sci["RRSD"]
        swaths = need(rrsd, "swaths", path, "group")
        side = _look_side(ident, path)
        grids: list[_Grid] = []
        found_freqs = []
        for fname in member_names(swaths):
            m = _FREQ.match(fname)
            if m is None or not isinstance(swaths[fname], h5py.Group):
                continue
            found_freqs.append(m.group(1))
            if frequencies and m.group(1) not in frequencies:
                continue
            for tname in sorted(swaths[fname]):
                mt = _TX.match(tname)
                if mt is None or not isinstance(swaths[fname][tname], h5py.Group):
                    continue
                grid = _read_grid(swaths[fname][tname], m.group(1), mt.group(1), path, notes)
                if polarizations:
                    grid.rx = [(p, ds) for p, ds in grid.rx if p in polarizations]
                if grid.rx:
                    grids.append(grid)
        if not found_freqs:
            raise FormatError(f"{path}: incomplete NISAR L0B: {swaths.name} has no frequency{{A,B}} group")
        if not grids:
            if not (frequencies or polarizations):
                raise FormatError(f"{path}: incomplete NISAR L0B: no tx{{H,V,L,R}} group with echo data under "
                                  f"{swaths.name}")
            want = ", ".join([*frequencies, *polarizations])
            raise ConfigError(f"{path}: no data for {want}; the file has frequencies {', '.join(found_freqs)}")
        epoch = grids[0].epoch
        tel = need(rrsd, "lowRateTelemetry", path, "group")
        orbit, sv = _orbit(tel, path, epoch)
        attitude = _attitude(tel, path, epoch, sv, side, notes)
        groups: dict[tuple, list[_Grid]] = {}
        for gr in grids:
            if gr.epoch != epoch:
                shift = seconds_between(gr.epoch, epoch)
                gr.t_tx = gr.t_tx + shift
                gr.epoch = epoch
            groups.setdefault(gr.key(), []).append(gr)
        products = {}
        for members in groups.values():
            name, p = _product(members, path, ident, band, side, orbit, sv, attitude, notes)
            products[name] = p
    return L0BContents(products, notes)
