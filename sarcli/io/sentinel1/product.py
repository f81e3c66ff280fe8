"""Level-0 measurement file(s) <-> raw products.

Reading (:func:`read_level0`): every packet is walked and its header decoded; packets with the
error flag set are dropped [S1-ISP, §3.2.5.1]; echo packets are grouped by swath and polarisation
(one product each, named ``S3_VV``, ``IW2_VH``, ...). Within a group, a change of the sampling
window (SWST, SWL / number of quads), PRI, rank, decimation filter or Tx pulse starts a new
product (``S3_VV_2``, ...): each product then has one exact window start and one range sampling
grid, and nothing is silently merged (zero-padding to a common window would need a per-line window
start that the raw model does not have, and would hide the change). Noise packets of the same
swath and Rx channel and all calibration packets of the Rx channel are stored in the product's
``auxiliary`` arrays, not in ``/echo``.

Geometry and timing [S1-ISP, §3.2.5; Sentinel-1 L1 Detailed Algorithm Definition, eq. 9-71]:

- the two-way time of the first stored sample after its pulse's transmission is
  ``window_start = rank * PRI + SWST + dt_suppr`` (dt_suppr = 320 / (8 f_ref), the suppressed filter
  transient);
- the packet time (GPS) is the receive time ``rx = tx + SWST + rank * PRI``, so the transmit time of
  a line is ``tx = rx - SWST - rank * PRI`` (stored as ``azimuth_time``, UTC after ``epoch_utc``), with
  ``rx`` on the PRI grid of the packets' PRI counter, its offset fitted to the datations (quantized to
  2^-16 s); the packet times themselves stay in ``auxiliary["s1/echo_time_gps"]``;
- the replica is the nominal transmitted chirp, exp(j (2 pi f0 t + pi K t^2)), t = k / f_dec,
  k = 0 .. ceil(TXPL f_dec) - 1 (f0: Tx pulse start frequency, K: ramp rate);
- the carrier is not in the packets: Sentinel-1's 5.405 GHz is used.

IW/EW (TOPS) data are read with their burst structure (``auxiliary["s1/burst_first_line"]``,
``["s1/burst_n_lines"]``) and marked not focusable (``extra_attrs["focusable"] = False``).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sarcli.errors import ConfigError, FormatError
from sarcli.io.sentinel1 import ancillary as anc
from sarcli.io.sentinel1.constants import (
    BURST_MODES,
    DELTA_T_SUPPR_S,
    ECC_MODES,
    F_REF_HZ,
    HEADER_BYTES,
    RANGE_DECIMATION,
    RX_CHANNEL_POLARISATION,
    SIGNAL_ECHO,
    SIGNAL_NOISE,
    TX_POLARISATION,
)
from sarcli.io.sentinel1.decode import decode_packets, decode_user_data, decoder_kind
from sarcli.io.sentinel1.headers import (
    check_headers,
    decode_headers,
    physical,
    range_sampling_rate_hz,
    walk_packets,
)
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import Orbit, Radar, RawProduct

#: Sentinel-1 C-band centre frequency (not carried by the packets).
S1_CARRIER_HZ = 5.405e9
NOT_FOCUSABLE_TOPS = "Sentinel-1 TOPS (IW/EW) bursts: focusing TOPS is not implemented"
#: Header fields that must stay constant within one product (a change starts a new product).
SEGMENT_KEYS = ("swst", "swl", "number_of_quads", "pri", "rank", "range_decimation", "tx_ramp_rate",
                "tx_pulse_start_frequency", "tx_pulse_length", "baq_mode")


@dataclass
class Level0:
    """What a Level-0 file decodes to: products by name, packet counts, status notes."""

    products: dict[str, RawProduct]
    n_packets: int
    notes: list[str] = field(default_factory=list)


class NoEchoPackets(FormatError):
    """A measurement file with only noise or calibration packets: nothing to make a raw product of."""


def read_packets(path: str | os.PathLike, allow_truncated: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(file bytes, checked header table) of a Level-0 measurement file."""
    try:
        data = np.fromfile(path, np.uint8)
    except OSError as e:
        raise FormatError(f"{path}: cannot read ({e.strerror})") from None
    where = str(path)
    h = decode_headers(data, walk_packets(data, where, allow_truncated))
    check_headers(h, where)
    return data, h


def swath_name(ecc: int, rgdec: int, swath_number: int) -> str:
    """Swath label from the ECC mode [S1-ISP, Table 3.2-4] and the decimation filter (§3.2.5.4)."""
    mode = ECC_MODES.get(int(ecc))
    names = RANGE_DECIMATION.get(int(rgdec), (0, 0, 0, ()))[3]
    if mode is None or mode in ("RFC", "TEST"):
        return f"SW{int(swath_number)}"
    if mode in ("IW", "EW", "WV"):
        match = [n for n in names if n.startswith(mode)]
        return match[0] if len(match) == 1 else f"{mode}_SW{int(swath_number)}"
    return mode


def _polarisation(h: np.ndarray) -> np.ndarray:
    return np.array([TX_POLARISATION[int(p)] + RX_CHANNEL_POLARISATION.get(int(r), "?")
                     for p, r in zip(h["polarisation"], h["rx_channel_id"], strict=True)])


def _kinds(h: np.ndarray, where: str) -> np.ndarray:
    kinds = np.array([decoder_kind(int(b), int(t)) for b, t in zip(h["baq_mode"], h["test_mode"], strict=True)])
    bad = np.flatnonzero(kinds < 0)
    if bad.size:
        i = int(bad[0])
        raise FormatError(f"{where}: packet at byte {int(h['offset'][i])}: BAQ mode {int(h['baq_mode'][i])} with "
                          f"test mode {int(h['test_mode'][i])} is not a defined data format (S1-IF-ASD-PL-0007 "
                          "Table 3.3-2)")
    return kinds


def _decode(data: np.ndarray, h: np.ndarray, where: str) -> np.ndarray:
    starts = h["offset"].astype(np.int64) + HEADER_BYTES
    ends = h["offset"].astype(np.int64) + h["packet_data_length"].astype(np.int64) + 7
    return decode_packets(data, starts, ends, h["number_of_quads"], _kinds(h, where), where=where)


def _segments(h: np.ndarray) -> list[np.ndarray]:
    """Index runs of packets whose segment keys do not change."""
    change = np.zeros(h.size, bool)
    for k in SEGMENT_KEYS:
        change[1:] |= h[k][1:] != h[k][:-1]
    bounds = np.r_[0, np.flatnonzero(change), h.size]
    return [np.arange(a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]


def replica(ramp_rate: float, start_frequency: float, pulse_length: float, fs: float) -> np.ndarray:
    """Nominal Tx chirp at the sampling rate, in sarcli's replica convention (centred: the pulse centre is
    at sample (n - 1)/2 of n = round(T fs) samples, as the focuser and the simulator assume).

    The packets give the chirp from its start, f(t') = f0 + K t' for 0 <= t' <= T [S1-ISP, §3.2.5.8]; with
    t = t' - T/2 it is exp(j (2 pi f_c t + pi K t^2)) up to a constant phase, f_c = f0 + K T/2 the centre
    frequency (0 for a chirp symmetric about the carrier). A replica built from t' = 0 on ceil(T fs)
    samples would put the pulse centre up to a sample off the one the focuser takes: 1.5 m of range
    (0.68 sample) on a 66.7 MHz S3 product."""
    n = int(round(pulse_length * fs))
    t = (np.arange(n) - 0.5 * (n - 1)) / fs
    f_c = start_frequency + 0.5 * ramp_rate * pulse_length
    return np.exp(1j * (2 * np.pi * f_c * t + np.pi * ramp_rate * t * t)).astype(np.complex64)


def _bursts(time: np.ndarray, pri: float) -> tuple[np.ndarray, np.ndarray]:
    """First line and length of each burst: a gap of more than 1.5 PRI between lines ends a burst."""
    gaps = np.flatnonzero(np.diff(time) > 1.5 * pri) + 1
    first = np.r_[0, gaps]
    return first, np.diff(np.r_[first, time.size])


#: resolution of the packet datation: fine time in units of 2^-16 s [S1-ISP, §3.2.1.1]
FINE_TIME_STEP_S = 2.0 ** -16


def _pri_grid(t_rx: np.ndarray, pri_count: np.ndarray, pri: float, where: str) -> np.ndarray:
    """Receive times of the lines on the PRI grid: t0 + (count - count_0) PRI, t0 fitted (least squares)
    to the packet datations. The datation is quantized to 2^-16 s = 15.3 us, 2.6 % of a 588 us PRI, so
    the packet times alone jitter the line spacing by up to a fine step (a 1.2 % error of the median
    spacing on a 1700 Hz PRF); the PRI counter and the PRI code are exact. The fitted offset averages
    the quantization over the lines (error ~ 15.3 us / sqrt(12 n)). A residual above two fine steps means
    the counter and the datation disagree (a clock reset, a PRI change inside the segment): refused."""
    k = (np.asarray(pri_count, np.int64) - int(pri_count[0])).astype(np.float64) * pri
    t0 = float(np.mean(t_rx - k))
    grid = t0 + k
    resid = float(np.max(np.abs(t_rx - grid))) if t_rx.size else 0.0
    if resid > 2 * FINE_TIME_STEP_S:
        raise FormatError(f"{where}: packet times depart from the PRI counter by {resid * 1e6:.3g} us (more than two "
                          "datation steps): the segment's timing is inconsistent")
    return grid


def _product(data, h, rows, noise, cal, orbit_rec, swath, where) -> RawProduct:
    hs = h[rows]
    r0 = hs[0]
    p = physical(hs[:1])
    fs = range_sampling_rate_hz(int(r0["range_decimation"]))
    pri = float(p["pri_s"][0])
    rank, swst = int(r0["rank"]), float(p["swst_s"][0])
    t_rx = physical(hs)["time_gps_s"]
    # times after the first line's whole GPS second, exact in float64 (absolute GPS seconds ~1.3e9 carry
    # only 2.4e-7 s: an ulp of jitter per line spacing)
    c0 = int(hs["coarse_time"][0])
    t_rel = (hs["coarse_time"].astype(np.int64) - c0) + (hs["fine_time"].astype(np.float64) + 0.5) / 65536.0
    t_tx_rel = _pri_grid(t_rel, hs["pri_count"], pri, where) - swst - rank * pri
    e_rel = np.floor(t_tx_rel[0] * 1e6) / 1e6
    epoch_gps = c0 + e_rel
    epoch_utc = anc.gps_to_utc_string(epoch_gps)
    window_start = rank * pri + swst + DELTA_T_SUPPR_S
    k, f0, tp = (float(p[n][0]) for n in ("tx_ramp_rate_hz_per_s", "tx_start_frequency_hz", "tx_pulse_length_s"))
    baq = int(r0["baq_mode"])
    radar = Radar(carrier_frequency_hz=S1_CARRIER_HZ, wavelength_m=C_LIGHT / S1_CARRIER_HZ, prf_hz=1.0 / pri,
                  range_sampling_rate_hz=fs, chirp_rate_hz_per_s=k, pulse_length_s=tp, window_start_s=window_start,
                  first_range_m=C_LIGHT / 2 * window_start,
                  quantization_bits=10 if baq == 0 else (baq if baq < 12 else 0))
    mode = ECC_MODES.get(int(r0["ecc_number"]), "")
    aux: dict[str, np.ndarray] = {"s1/echo_headers": hs, "s1/echo_time_gps": t_rx}
    extra = {"s1_swath": swath, "s1_mode": mode,
             "s1_ecc_number": int(r0["ecc_number"]), "s1_data_take_id": int(r0["data_take_id"]),
             "s1_baq_mode": baq, "s1_range_decimation": int(r0["range_decimation"]),
             "s1_swath_number": int(r0["swath_number"]), "s1_rank": rank, "s1_swst_s": swst,
             "s1_tx_start_frequency_hz": f0, "s1_gps_minus_utc_s": anc.gps_minus_utc(epoch_gps),
             "s1_polarisation": str(_polarisation(hs[:1])[0]), "s1_n_noise_lines": int(noise.size),
             "s1_n_calibration_lines": int(cal.size),
             "s1_carrier_note": "carrier not in the packets: Sentinel-1 nominal 5.405 GHz"}
    for label, sel in (("noise", noise), ("calibration", cal)):
        if sel.size:
            aux[f"s1/{label}"] = _decode(data, h[sel], where)
            aux[f"s1/{label}_headers"] = h[sel]
            aux[f"s1/{label}_time_gps"] = physical(h[sel])["time_gps_s"]
    if mode in BURST_MODES:
        first, n = _bursts(t_rx, pri)
        aux["s1/burst_first_line"], aux["s1/burst_n_lines"] = first, n
        extra |= {"focusable": False, "not_focusable_reason": NOT_FOCUSABLE_TOPS, "s1_n_bursts": int(first.size)}
    orbit = None
    if orbit_rec.pvt_time.size:
        orbit = Orbit(orbit_rec.pvt_time - epoch_gps, orbit_rec.position, orbit_rec.velocity, "ECEF")
    if orbit_rec.attitude_time.size:
        aux["s1/attitude_time"] = orbit_rec.attitude_time - epoch_gps
        aux["s1/attitude_quaternion"] = orbit_rec.quaternion
        aux["s1/attitude_angular_rate"] = orbit_rec.angular_rate
        aux["s1/attitude_pointing_status"] = orbit_rec.pointing_status
    return RawProduct(
        echo=_decode(data, hs, where), azimuth_time=t_tx_rel - e_rel, epoch_utc=epoch_utc, radar=radar,
        look_side="right", source="sentinel1-l0", agc_db=(0.5 * hs["rx_gain"]).astype(np.float32),
        replica=replica(k, f0, tp, fs), orbit=orbit, extra_attrs=extra, auxiliary=aux)


def read_level0(path: str | os.PathLike, allow_truncated: bool = False) -> Level0:
    """Decode a Level-0 measurement file into raw products (module docstring)."""
    where = str(path)
    data, h = read_packets(path, allow_truncated)
    notes = []
    if allow_truncated and h.size and int(h["offset"][-1] + h["packet_data_length"][-1]) + 7 != data.size:
        notes.append("file truncated: the trailing partial packet was dropped")
    orbit_rec = anc.reassemble(h["subcom_word_index"], h["subcom_word"])
    bad = h["error_flag"] == 1
    if bad.any():
        notes.append(f"{int(bad.sum())} packet(s) with the SES error flag set were dropped")
        h = h[~bad]
    sig = h["signal_type"]
    echo = np.flatnonzero(sig == SIGNAL_ECHO)
    if echo.size == 0:
        raise NoEchoPackets(f"{where}: no echo packets among {h.size} (signal types "
                          f"{sorted(set(sig.tolist()))}): nothing to make a raw product of")
    pol = _polarisation(h)
    names = np.array([swath_name(e, r, s) for e, r, s in zip(h["ecc_number"], h["range_decimation"],
                                                               h["swath_number"], strict=True)])
    products: dict[str, RawProduct] = {}
    for key in dict.fromkeys(zip(names[echo], pol[echo], strict=True)):
        rows = echo[(names[echo] == key[0]) & (pol[echo] == key[1])]
        noise = np.flatnonzero((sig == SIGNAL_NOISE) & (h["swath_number"] == h["swath_number"][rows[0]])
                               & (h["rx_channel_id"] == h["rx_channel_id"][rows[0]]))
        cal = np.flatnonzero((sig > 7) & (h["rx_channel_id"] == h["rx_channel_id"][rows[0]]))
        segs = _segments(h[rows])
        for n, seg in enumerate(segs, start=1):
            name = f"{key[0]}_{key[1]}" + (f"_{n}" if len(segs) > 1 else "")
            products[name] = _product(data, h, rows[seg], noise, cal, orbit_rec, str(key[0]), where)
        if len(segs) > 1:
            notes.append(f"{key[0]}_{key[1]}: the sampling window or pulse changes {len(segs) - 1} time(s): "
                         f"{len(segs)} products")
    if not orbit_rec.pvt_time.size:
        notes.append("no complete orbit (PVT) record in the ancillary data: products have no orbit")
    return Level0(products, int(h.size), notes)


# ---------------------------------------------------------------------------------------------
# Writing


def _rgdec_for(fs: float) -> int:
    for code, (num, den, _, _) in RANGE_DECIMATION.items():
        if abs(num / den * 4 * F_REF_HZ - fs) <= 1e-9 * fs:
            return code
    rates = ", ".join(f"{num / den * 4 * F_REF_HZ / 1e6:.6f}" for num, den, _, _ in RANGE_DECIMATION.values())
    raise ConfigError(f"range sampling rate {fs / 1e6:.6f} MHz is not a Sentinel-1 rate after decimation "
                      f"(MHz: {rates}): simulate with one of them")


def _code(value: float, unit: float, bits: int, what: str) -> int:
    c = round(value / unit)
    if not 0 <= c < 2 ** bits:
        raise ConfigError(f"{what} {value} does not fit the {bits}-bit packet field")
    return c


def _signed16(value: float, unit: float, what: str) -> int:
    mag = _code(abs(value), unit, 15, what)
    return (0x8000 if value > 0 else 0) | mag


def write_level0(raw: RawProduct, path: str | os.PathLike, *, compression: str = "fdbaq", brc: int = 3,
                 ecc_number: int = 3, swath_number: int = 2, polarisation: str = "VV",
                 data_take_id: int = 1) -> dict:
    """Write ``raw``'s echo as a Level-0 packet stream (one packet per line) at ``path`` (atomically).

    ``compression``: "fdbaq" (FDBAQ mode 0, one bit-rate code ``brc`` 0..4 for all blocks), "baq3",
    "baq4", "baq5" or "bypass" (decimation only: values rounded to integers, |v| <= 511). The product's
    range sampling rate must be one of the Sentinel-1 rates after decimation; PRI, window start, pulse
    length, ramp rate and times are rounded to their packet codes (steps: 1/f_ref = 26.6 ns, ramp
    f_ref^2/2^21 MHz/us, time 2^-16 s). The window start gives rank and SWST; an ECEF orbit becomes the
    sub-commutated PVT words (one record per 64 packets, in turn). ECC number 3 = Stripmap 3.
    Returns a summary (packets, bytes, mode codes, quantisation SNR in dB)."""
    from sarcli.io.atomic import atomic_path
    from sarcli.io.sentinel1.encode import blank_headers, encode_user_data, pack_packets, quantise

    kinds = {"fdbaq": 12, "baq3": 3, "baq4": 4, "baq5": 5, "bypass": 0}
    if compression not in kinds:
        raise ConfigError(f"compression must be one of {', '.join(kinds)}, got {compression!r}")
    if len(polarisation) != 2 or polarisation[0] not in "HV" or polarisation[1] not in "HV":
        raise ConfigError(f"polarisation must be HH, HV, VH or VV, got {polarisation!r}")
    kind = kinds[compression]
    r = raw.radar
    n_lines, n_samples = raw.echo.shape
    if n_samples % 2:
        raise ConfigError(f"a Level-0 line holds an even number of samples (2 x quads), got {n_samples}")
    rgdec = _rgdec_for(r.range_sampling_rate_hz)
    pri_code = _code(1.0 / r.prf_hz, 1 / F_REF_HZ, 24, "PRI")
    pri = pri_code / F_REF_HZ
    rank = int((r.window_start_s - DELTA_T_SUPPR_S) // pri)
    swst_code = _code(r.window_start_s - DELTA_T_SUPPR_S - rank * pri, 1 / F_REF_HZ, 24, "SWST")
    if rank > 31:
        raise ConfigError(f"window start {r.window_start_s} s is {rank} PRIs: more than the 31 a packet can say")
    f_mhz = F_REF_HZ * 1e-6
    ramp_code = _signed16(r.chirp_rate_hz_per_s * 1e-12, f_mhz * f_mhz / 2**21, "chirp rate (MHz/us)")
    ramp = (1 if ramp_code >> 15 else -1) * (ramp_code & 0x7FFF) * f_mhz * f_mhz / 2**21  # MHz/us
    tpl_code = _code(r.pulse_length_s, 1 / F_REF_HZ, 24, "pulse length")
    start_mhz = -ramp * (tpl_code / F_REF_HZ * 1e6) / 2  # centred chirp
    start_code = _signed16(start_mhz - ramp / (4 * f_mhz), f_mhz / 2**14, "start frequency (MHz)")

    epoch_gps = anc.utc_string_to_gps(raw.epoch_utc)
    t_rx = epoch_gps + np.asarray(raw.azimuth_time, np.float64) + swst_code / F_REF_HZ + rank * pri
    coarse = np.floor(t_rx).astype(np.int64)
    fine = np.rint((t_rx - coarse) * 65536 - 0.5).astype(np.int64)
    coarse += fine // 65536
    fine %= 65536
    tx_pol, rx_pol = polarisation
    h = blank_headers(n_lines)
    h["coarse_time"], h["fine_time"] = coarse, fine
    h["data_take_id"], h["ecc_number"], h["rx_channel_id"] = data_take_id, ecc_number, int(rx_pol == "H")
    h["baq_mode"], h["range_decimation"] = kind, rgdec
    h["rx_gain"] = 0 if raw.agc_db is None else np.clip(np.rint(2 * np.asarray(raw.agc_db)), 0, 255)
    h["tx_ramp_rate"], h["tx_pulse_start_frequency"], h["tx_pulse_length"] = ramp_code, start_code, tpl_code
    h["rank"], h["pri"], h["swst"] = rank, pri_code, swst_code
    h["swl"] = n_samples  # informative: the line length is carried by the number of quads
    h["polarisation"] = {"H": 3, "V": 7}[tx_pol]
    h["swath_number"], h["number_of_quads"] = swath_number, n_samples // 2
    h["pri_count"] = np.arange(n_lines)
    if raw.orbit is not None and raw.orbit.frame == "ECEF":
        o = raw.orbit
        n_sets = n_lines // 64
        if n_sets < o.time.size:
            raise ConfigError(f"{o.time.size} state vectors need {64 * o.time.size} lines to be carried in the "
                              f"ancillary data; the product has {n_lines}")
        words = np.stack([anc.ancillary_words(epoch_gps + o.time[i], o.position[i], o.velocity[i])
                          for i in (np.arange(n_sets) * o.time.size // n_sets)])
        h["subcom_word_index"][:64 * n_sets] = np.tile(np.arange(1, 65), n_sets)
        h["subcom_word"][:64 * n_sets] = words.ravel()
    elif raw.orbit is not None:
        warnings.warn(f"the orbit is in the {raw.orbit.frame} frame; Level-0 carries ECEF: not written",
                      stacklevel=2)
    user_data = []
    signal = noise = 0.0
    for line in raw.echo:
        sym, brcs, thidx = quantise(line, kind, brc)
        ud = encode_user_data(sym, kind, brcs, thidx)
        user_data.append(ud)
        back = decode_user_data(ud, line.size // 2, kind, 0)
        signal += float(np.sum(np.abs(line) ** 2))
        noise += float(np.sum(np.abs(back - line) ** 2))
    blob = pack_packets(h, user_data)
    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(blob)
    snr = float("inf") if noise == 0 else 10 * np.log10(signal / noise) if signal > 0 else float("-inf")
    return {"output": str(path), "packets": n_lines, "bytes": len(blob), "baq_mode": kind,
            "range_decimation": rgdec, "rank": rank, "quantisation_snr_db": snr}

