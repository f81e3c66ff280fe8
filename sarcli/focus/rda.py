"""Range-Doppler algorithm (RDA), processed in azimuth blocks with overlap (bounded memory).

Per block of output lines [s, e) the raw lines [s - P, e + P) are read (zeros beyond the scene), with
P = ceil(aperture/2 + residual shift) lines so that every output line sees its whole processed
aperture, and processed as

1. AGC undone (x 10**(agc_db/20) per line), range FFT of length L >= n_samples + n_ref/2 + 64 in
   place (L: the shortest length whose circular correlation with the centred reference equals the
   linear one on the n_samples output samples, plus a guard for the SRC impulse response);
2. azimuth FFT (block length N >= e - s + 2P) in place: the block is now the 2-D spectrum;
3. per chunk of azimuth-frequency rows inside the processed band, ONE pass in the 2-D frequency domain
   (:func:`sarcli.focus.rangecomp.apply_range_filter_2d`): range matched filter x optional SRC at the
   mid-swath range x Fourier zero padding to ``rcmc_oversample`` x L (2x upsampling, knob); range IFFT;
4. RCMC + azimuth matched filter with the range-dependent centroid and rate of that block
   (:mod:`sarcli.focus.rcmc`), evaluated from the Doppler model at the block's centre time, written
   into the first n_samples columns of the block;
5. azimuth IFFT of those columns; lines [P, P + e - s) of the block are output lines [s, e).

Range compression, SRC and upsampling thus cost one range FFT and one range IFFT (the former design
compressed, transformed back and forth again for SRC and upsampling: two more range passes).
FFT lengths are 5-smooth (:func:`smooth_len`): pocketfft is markedly slower on factors 7 and 11.

Output geometry: column i is closest-approach slant range ``r_first + i dr`` (the raw range grid); line
j has ZERO-DOPPLER time ``t_raw[j] - shift/PRF``, where ``shift`` (integer lines) is the beam-centre
offset Delta = R0 tan(theta)/V at mid-swath and scene centre (:mod:`sarcli.focus.kinematics`):
every target lands within a few lines of its raw data, so squinted scenes (centroids of several PRFs)
need no more overlap than broadside ones. Lines closer than half an aperture to the scene ends see
only part of their aperture (``first_full_line`` / ``last_full_line``; a warning when none is whole).
Peak extra memory per block: the N x L block (complex64) plus a chunk of upsampled rows (bench_focus
reports it against a 1536 x 2048 input, including the output image).
"""

from __future__ import annotations

import math
import os
import queue
import time
import warnings
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass

import numpy as np
import scipy.fft as sfft

from sarcli.errors import SarcliError
from sarcli.focus.interp import parse_interpolator, table_for
from sarcli.focus.kinematics import aperture_time, beam_centre_offset, velocity_and_squint
from sarcli.focus.rangecomp import (
    C,
    apply_range_filter_2d,
    inverse_src_rate,
    range_filter,
    reference_pulse,
)
from sarcli.focus.rcmc import rcmc_azimuth
from sarcli.focus.windows import parse_window, window_table
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC, DopplerUsed

RANGE_GUARD = 64  # range samples beyond the correlation's wrap-free length (SRC impulse response)
CHUNK = 64  # azimuth-frequency rows per chunk of the filter + upsampling + RCMC pass


def smooth_len(n: int) -> int:
    """Smallest 5-smooth integer (2^a 3^b 5^c) >= n: a fast pocketfft length."""
    n = max(1, int(n))
    while True:
        m = n
        for q in (2, 3, 5):
            while m % q == 0:
                m //= q
        if m == 1:
            return n
        n += 1


@dataclass(frozen=True)
class RdKnobs:
    """Processing knobs of the RDA (each one's accuracy/cost is measured in bench/bench_focus.py).

    range_window, azimuth_window: window specs (:mod:`sarcli.focus.windows`); range_bandwidth_fraction:
    processed part of the chirp band (1 = all of it); azimuth_bandwidth_hz:
    processed Doppler band (default 0.8 PRF); rcmc: interpolator (nearest, linear, sinc4/8/16);
    src: secondary range compression; precision: "single" (complex64) or "double" (complex128);
    block_lines: azimuth FFT length per block; use_replica: the product's replica, else the nominal chirp;
    rcmc_oversample: 1 or 2, range Fourier upsampling before the RCMC interpolation (a windowed sinc
    attenuates frequencies near half the sampling rate: 8 taps pass only 0.31 of a component at
    0.467 cycles/sample, the edge of a Radarsat-1 chirp sampled at 1.07 x its band);
    orbit_timing: with an Earth orbit, place targets at their exact zero-Doppler time (see
    :func:`orbit_time_correction`) instead of the hyperbolic model's.
    """

    range_window: str = "kaiser:2.5"
    range_bandwidth_fraction: float = 1.0
    azimuth_window: str = "kaiser:2.5"
    azimuth_bandwidth_hz: float | None = None
    rcmc: str = "sinc8"
    src: bool = True
    precision: str = "single"
    block_lines: int = 4096
    use_replica: bool = True
    rcmc_oversample: int = 2
    orbit_timing: bool = True
    workers: int = -1


def make_knobs(**kw) -> RdKnobs:
    """RdKnobs from keyword arguments, refusing unknown names and bad values in one line."""
    names = set(RdKnobs.__dataclass_fields__)
    bad = sorted(set(kw) - names)
    if bad:
        raise SarcliError(f"unknown focus option(s) {', '.join(bad)}; known: {', '.join(sorted(names))}")
    k = RdKnobs(**{n: v for n, v in kw.items() if v is not None or n == "azimuth_bandwidth_hz"})
    parse_window(k.range_window)
    parse_window(k.azimuth_window)
    parse_interpolator(k.rcmc)
    if k.precision not in ("single", "double"):
        raise SarcliError(f"precision must be 'single' or 'double', got {k.precision!r}")
    if k.rcmc_oversample not in (1, 2):
        raise SarcliError(f"rcmc_oversample must be 1 or 2, got {k.rcmc_oversample}")
    if k.block_lines < 64:
        raise SarcliError(f"block_lines must be at least 64, got {k.block_lines}")
    return k


def _uniform_prf(t: np.ndarray, radar_prf: float) -> float:
    if t.size < 2:
        return radar_prf
    dt = np.diff(t)
    med = float(np.median(dt))
    if np.max(np.abs(dt - med)) > 1e-3 * med:
        raise SarcliError("azimuth lines are not uniformly spaced (PRF change or gap): the RD focuser needs a"
                          " uniform PRF; split the scene at the gap")
    return 1.0 / med


def doppler_on_grid(doppler, r0: np.ndarray, t: float, wavelength: float):
    """(fdc, fr, V, sin_squint) per closest range r0 at raw time t.

    The model is indexed by beam-centre range R_c = R0 / cos(theta): evaluated at R0 first, then at
    the R_c that this gives (one refinement; fdc and fr vary slowly with range). Refuses NaN/inf.
    """
    tt = np.full_like(r0, t)
    fdc = np.asarray(doppler.fdc(r0, tt), np.float64)
    fr = np.asarray(doppler.fr(r0, tt), np.float64)
    v, s = velocity_and_squint(fdc, fr, r0, wavelength)
    rc = r0 / np.sqrt(1.0 - s * s)
    fdc = np.broadcast_to(np.asarray(doppler.fdc(rc, tt), np.float64), r0.shape).copy()
    fr = np.broadcast_to(np.asarray(doppler.fr(rc, tt), np.float64), r0.shape).copy()
    v, s = velocity_and_squint(fdc, fr, r0, wavelength)
    return fdc, fr, v, s


def _coverage_warnings(doppler, r: np.ndarray, t: np.ndarray) -> list[str]:
    """Warn when the scene reaches beyond the blocks the Doppler model was estimated on.

    A block covers half the spacing of the block centres either side (a single block: the whole
    scene); beyond that the model is extrapolated.
    """
    blocks = getattr(doppler, "blocks", None)
    out = []
    if not (isinstance(blocks, dict) and "range_m" in blocks and "azimuth_time_s" in blocks):
        return out
    for name, axis, centres, unit in (("ranges", r, blocks["range_m"], "m"),
                                      ("times", t, blocks["azimuth_time_s"], "s")):
        c = np.unique(np.asarray(centres, float))
        if c.size == 0:
            continue
        half = 0.5 * float(np.median(np.diff(c))) if c.size > 1 else 0.5 * float(np.ptp(axis))
        half *= 1.01
        lo, hi = c.min() - half, c.max() + half
        if axis[0] < lo or axis[-1] > hi:
            out.append(f"Doppler table covers {name} {lo:.6g}-{hi:.6g} {unit}, scene {axis[0]:.6g}-{axis[-1]:.6g}"
                       f" {unit}: extrapolating")
    return out


def _reference_height(raw: RawProduct) -> float:
    if raw.truth is not None and "reference_height_m" in raw.truth:
        return float(np.asarray(raw.truth["reference_height_m"]))
    return 0.0


def orbit_time_correction(raw: RawProduct, t: float, r0: np.ndarray, fdc: np.ndarray, v: np.ndarray,
                          s: np.ndarray, wavelength: float, step: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Orbit corrections of the hyperbolic model per range bin: (time shift dt s, phase ph0 rad).

    The RDA puts a target seen at beam-centre time t at ``t - Delta_model``, Delta_model = R0 tan(theta)/V,
    with phase -4 pi R0_model / lam, R0_model = R_c cos(theta). With a squint of several PRFs Delta is
    seconds long and the hyperbola, fitted to fdc and fr at the beam centre, misplaces the zero-Doppler
    time by a fraction of a line (0.17 line for the Radarsat-1 sample) and the closest range by
    millimetres (2 rad of phase). With an Earth orbit the target seen at (t, R_c = R0/cos(theta), fdc)
    is geolocated (height: the truth's reference height, else 0) and its exact zero-Doppler time t_zd
    and closest range R0_true solved (``orbit.geometry``): dt = Delta_model - (t - t_zd) and
    ph0 = 4 pi (R0 - R0_true) / lam. Evaluated every ``step`` range bins, interpolated between.
    Zeros without an Earth orbit.
    """
    if raw.orbit is None or raw.orbit.frame not in ("ECI", "ECEF"):
        return np.zeros_like(r0), np.zeros_like(r0)
    from orbit.errors import GeometryError
    from orbit.geometry import doppler_time, geolocate
    from sarcli.focus.geolocation import state_vectors

    sv = state_vectors(raw.orbit, raw.epoch_utc)
    idx = np.unique(np.r_[np.arange(0, r0.size, step), r0.size - 1])
    rc = r0[idx] / np.sqrt(1.0 - s[idx] ** 2)
    try:
        p = geolocate(sv, np.full(idx.size, t), rc, wavelength, fdc[idx], _reference_height(raw), raw.look_side)
        t_zd, r0_true = doppler_time(sv, p, t_guess=t)
    except GeometryError as e:
        raise SarcliError(f"orbit timing correction failed ({e}); use orbit_timing=False") from None
    delta_model = beam_centre_offset(r0[idx], v[idx], s[idx])
    grid = np.arange(r0.size)
    dt = np.interp(grid, idx, delta_model - (t - t_zd))
    ph0 = np.interp(grid, idx, 4.0 * np.pi * (r0[idx] - r0_true) / wavelength)
    return dt, ph0


@dataclass
class _Plan:
    prf: float
    ranges: np.ndarray
    wavelength: float
    ba: float
    shift: int
    pad: int
    n_fft_az: int
    n_valid: int
    n_fft_r: int
    full_aperture: float


def _plan(raw: RawProduct, shape: tuple[int, int], doppler, k: RdKnobs) -> _Plan:
    radar = raw.radar
    n_lines = shape[0]
    prf = _uniform_prf(raw.azimuth_time, radar.prf_hz)
    ranges = radar.first_range_m + np.arange(shape[1]) * C / (2.0 * radar.range_sampling_rate_hz)
    lam = C / radar.carrier_frequency_hz
    ba = 0.8 * prf if k.azimuth_bandwidth_hz is None else float(k.azimuth_bandwidth_hz)
    if not 0.0 < ba <= prf:
        raise SarcliError(f"azimuth bandwidth {ba:.4g} Hz must be in (0, PRF = {prf:.4g} Hz]")
    t = raw.azimuth_time
    offsets, fr_abs = [], []
    for tb in (t[0], 0.5 * (t[0] + t[-1]), t[-1]):
        _, fr, v, s = doppler_on_grid(doppler, ranges, float(tb), lam)
        offsets.append(beam_centre_offset(ranges, v, s) * prf)
        fr_abs.append(np.abs(fr))
    mid = len(ranges) // 2
    shift = int(round(float(offsets[1][mid])))
    resid = max(float(np.max(np.abs(o - shift))) for o in offsets)
    aperture = float(np.max(aperture_time(np.min(fr_abs, axis=0), ba))) * prf
    pad = int(math.ceil(0.5 * aperture + resid)) + 4
    n_fft_az = smooth_len(max(k.block_lines, 4 * pad) if n_lines + 2 * pad > k.block_lines
                          else n_lines + 2 * pad)
    n_valid = min(n_lines, n_fft_az - 2 * pad)
    n_ref = reference_pulse(radar, raw.replica if k.use_replica else None).size
    n_fft_r = smooth_len(len(ranges) + n_ref // 2 + RANGE_GUARD)
    return _Plan(prf, ranges, lam, ba, shift, pad, n_fft_az, n_valid, n_fft_r, aperture)


def _fft_inplace(y: np.ndarray, axis: int, inverse: bool, workers: int, cols: int = 256) -> None:
    """FFT of ``y`` along ``axis`` in place (scipy's pocketfft writes into ``y`` with overwrite_x).

    Along axis 0 in chunks of ``cols`` columns: 1.8x faster than one call on a 2304 x 2880 block
    (cache: bench machine, single thread).
    """
    f = sfft.ifft if inverse else sfft.fft
    for c in range(0, y.shape[1], cols if axis == 0 else y.shape[1]):
        v = y[:, c:c + cols] if axis == 0 else y
        r = f(v, axis=axis, overwrite_x=True, workers=workers)
        if not np.may_share_memory(r, v):
            v[...] = r


def _n_threads(workers: int) -> int:
    """Threads for the chunk pool: ``workers`` (scipy's convention: negative = every usable core)."""
    if workers >= 0:
        return max(1, workers)
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else max(1, os.cpu_count() or 1)


def _range_rows(y: np.ndarray, off: int, data: np.ndarray, gain: np.ndarray | None, workers: int,
                rows: int = 128) -> None:
    """Fill the fresh block ``y`` (N x L, uninitialized): ``data`` (n x nr) times ``gain`` per line in
    lines [off, off + n) and columns [0, nr), zeros elsewhere, and range FFT of those lines in place.
    In chunks of ``rows`` lines on a pool of ``workers`` threads (single-threaded FFTs): the first touch
    of the block's pages (page faults, ~0.2 ms per MB) is shared by the threads."""
    n, nr = data.shape

    def run(c: int, d: int) -> None:
        a, b = max(c, off), min(d, off + n)
        if a >= b:
            y[c:d] = 0.0
            return
        y[c:a] = 0.0
        y[b:d] = 0.0
        part = y[a:b]
        part[:, :nr] = data[a - off:b - off]
        part[:, nr:] = 0.0
        if gain is not None:
            part[:, :nr] *= gain[a - off:b - off, None]
        _fft_inplace(part, 1, False, 1)

    _pooled([(c, min(c + rows, y.shape[0])) for c in range(0, y.shape[0], rows)], run, workers)


def _pooled(chunks: list[tuple[int, int]], run: Callable[[int, int], None], workers: int) -> None:
    """``run(c, d)`` for every chunk, on a pool of ``workers`` threads (serially with one)."""
    n_threads = min(_n_threads(workers), max(1, len(chunks)))
    if n_threads == 1:
        for c, d in chunks:
            run(c, d)
        return
    with ThreadPoolExecutor(n_threads) as pool:
        for f in [pool.submit(run, c, d) for c, d in chunks]:
            f.result()


def _filter_rcmc_rows(y, nr, h, inv_k, f_bin, p, fs, factor, v, fdc, dt, ph0, wtab, kind, table, workers,
                      rows=CHUNK):
    """Range filter (+ SRC), upsampling and RCMC + azimuth filter of the 2-D spectrum ``y`` (N x L).

    Every azimuth-frequency row is independent, so rows are processed in chunks: the matched filter
    ``h`` times the SRC phase ``exp(-j pi f_tau^2 inv_k[row])`` (zero: none), zero padding in the
    middle of the spectrum to ``factor`` x L (Fourier interpolation), IFFT, and the kernel interpolates
    on the ``factor`` x finer grid into ``y[:, :nr]`` (range-Doppler domain, raw range grid). With
    factor 2 the data sit below a quarter of the sampling rate, where the windowed sinc is flat (a
    Radarsat-1 chirp is sampled at only 1.07 x its band: bench). ``factor`` is folded into the window
    table (the IFFT of the longer spectrum divides by factor x L instead of L).
    Chunks go to a pool of ``workers`` threads (serial GIL-free kernels, single-threaded FFTs, one
    buffer per thread): no synchronization inside a chunk, so a busy machine slows it gracefully.
    """
    n_fft = y.shape[1]
    f_tau = sfft.fftfreq(n_fft, 1.0 / fs)
    w = wtab * factor
    dr = C / (2.0 * fs)
    out = y[:, :nr]
    # rows whose frequency lies outside the processed band at every range are zero: skip their FFTs
    off = f_bin[:, None] - fdc[None, ::16]
    off -= p.prf * np.floor(off / p.prf + 0.5)
    active = np.any(np.abs(off) <= 0.5 * p.ba * (1.0 + 1e-9), axis=1)
    out[~active] = 0.0
    edges = np.flatnonzero(np.diff(np.r_[0, active.astype(np.int8), 0]))
    chunks = [(c, min(b, c + rows)) for a, b in zip(edges[::2], edges[1::2], strict=True) for c in range(a, b, rows)]
    n_threads = min(_n_threads(workers), max(1, len(chunks)))
    buffers: queue.SimpleQueue = queue.SimpleQueue()
    for _ in range(n_threads):
        buffers.put(np.empty((min(rows, y.shape[0]), factor * n_fft), y.dtype))

    def run(c: int, d: int) -> None:
        buf = buffers.get()
        try:
            up = buf[:d - c]
            apply_range_filter_2d(y[c:d], h, f_tau, inv_k[c:d], up)
            _fft_inplace(up, 1, True, 1)
            rcmc_azimuth(up, f_bin[c:d], float(p.ranges[0]), dr / factor, p.ranges, v, fdc, dt, ph0, p.wavelength,
                         p.prf, p.ba, w, kind, table, p.shift, out[c:d])
        finally:
            buffers.put(buf)  # also on error: the other chunks must not wait for this buffer

    _pooled(chunks, run, workers)


def focus_stream(raw: RawProduct, read_lines: Callable[[int, int], np.ndarray],
                 sink: Callable[[int, np.ndarray], None], doppler, knobs: RdKnobs,
                 shape: tuple[int, int], on_block: Callable[[int, int], None] | None = None) -> SLC:
    """Focus lines read by ``read_lines(a, b)`` and hand output blocks to ``sink(first_line, block)``.

    ``raw`` supplies metadata (its echo may be empty), ``shape`` = (n_lines, n_samples) of the echo;
    returns the SLC metadata with an empty image.
    """
    k = knobs
    t_start = time.perf_counter()
    timings = {"range_fft_s": 0.0, "azimuth_fft_s": 0.0, "range_filter_rcmc_azimuth_s": 0.0,
               "azimuth_ifft_s": 0.0, "io_s": 0.0}
    radar = raw.radar
    n_lines = shape[0]
    if n_lines < 2:
        raise SarcliError("the scene has fewer than two azimuth lines: nothing to focus")
    p = _plan(raw, shape, doppler, k)
    nr = p.ranges.size
    cdt = np.complex64 if k.precision == "single" else np.complex128
    h, _ = range_filter(radar, p.n_fft_r, k.range_window, raw.replica if k.use_replica else None,
                        k.range_bandwidth_fraction)
    h = h.astype(cdt)
    wtab = window_table(k.azimuth_window)
    kind, table = table_for(k.rcmc)
    table = table.astype(np.float32 if k.precision == "single" else np.float64)  # single: complex64 taps
    f_bin = sfft.fftfreq(p.n_fft_az, 1.0 / p.prf)
    gain = raw.line_gain()
    t_raw = raw.azimuth_time
    dt = 1.0 / p.prf
    msgs = _coverage_warnings(doppler, p.ranges, t_raw)
    first_full = int(math.ceil(0.5 * p.full_aperture))
    last_full = n_lines - 1 - first_full
    if first_full > last_full:
        msgs.append(f"scene ({n_lines} lines) is shorter than the synthetic aperture ({p.full_aperture:.0f} lines):"
                    " no line is fully focused")
    for m in msgs:
        warnings.warn(m, stacklevel=2)
    r_mid = float(p.ranges[nr // 2])
    block_times, fdcs, frs, vs, dts = [], [], [], [], []
    n_blocks = int(math.ceil(n_lines / p.n_valid))
    for b in range(n_blocks):
        s = b * p.n_valid
        e = min(s + p.n_valid, n_lines)
        a, z = max(0, s - p.pad), min(n_lines, e + p.pad)
        t0 = time.perf_counter()
        data = np.asarray(read_lines(a, z))
        timings["io_s"] += time.perf_counter() - t0
        if data.shape != (z - a, nr):
            raise SarcliError(f"echo block has shape {data.shape}, expected {(z - a, nr)}")
        t0 = time.perf_counter()
        y = np.empty((p.n_fft_az, p.n_fft_r), cdt)
        _range_rows(y, a - (s - p.pad), data, None if gain is None else gain[a:z], k.workers)
        del data
        timings["range_fft_s"] += time.perf_counter() - t0
        t0 = time.perf_counter()
        _fft_inplace(y, 0, False, k.workers)
        timings["azimuth_fft_s"] += time.perf_counter() - t0
        tb = float(t_raw[0] + 0.5 * (s + e - 1) * dt)
        fdc, fr, v, sq = doppler_on_grid(doppler, p.ranges, tb, p.wavelength)
        dt_orbit, ph_orbit = (orbit_time_correction(raw, tb, p.ranges, fdc, v, sq, p.wavelength)
                              if k.orbit_timing else (np.zeros(nr), np.zeros(nr)))
        block_times.append(tb)
        fdcs.append(fdc)
        frs.append(fr)
        vs.append(v)
        dts.append(dt_orbit)
        inv_k = np.zeros(p.n_fft_az)
        if k.src:
            off_f = f_bin - fdc[nr // 2]
            f_abs = fdc[nr // 2] + off_f - p.prf * np.floor(off_f / p.prf + 0.5)
            inv_k = inverse_src_rate(f_abs, r_mid, float(v[nr // 2]), radar.carrier_frequency_hz)
        t0 = time.perf_counter()
        _filter_rcmc_rows(y, nr, h, inv_k, f_bin, p, radar.range_sampling_rate_hz, k.rcmc_oversample, v, fdc,
                          dt_orbit, ph_orbit, wtab, kind, table, k.workers)
        timings["range_filter_rcmc_azimuth_s"] += time.perf_counter() - t0
        img = y[:, :nr]
        t0 = time.perf_counter()
        _fft_inplace(img, 0, True, k.workers)
        timings["azimuth_ifft_s"] += time.perf_counter() - t0
        t0 = time.perf_counter()
        sink(s, img[p.pad:p.pad + (e - s)].astype(np.complex64, copy=False))
        timings["io_s"] += time.perf_counter() - t0
        if on_block is not None:
            on_block(b + 1, n_blocks)
    timings["total_s"] = time.perf_counter() - t_start
    v_mid = float(np.median(np.asarray(vs)[:, nr // 2]))
    params = {"algorithm": "rd", **asdict(k), "azimuth_bandwidth_hz": p.ba, "prf_hz": p.prf,
              "shift_lines": p.shift, "overlap_lines": p.pad, "azimuth_fft_length": p.n_fft_az,
              "range_fft_length": p.n_fft_r, "n_blocks": n_blocks, "aperture_lines": p.full_aperture,
              "orbit_timing_correction_max_s": float(np.max(np.abs(dts))),
              "replica_used": bool(k.use_replica and raw.replica is not None and np.size(raw.replica) > 1),
              "warnings": msgs}
    return SLC(
        image=np.zeros((0, 0), np.complex64),
        azimuth_time=t_raw[0] + (np.arange(n_lines) - p.shift) * dt,
        slant_range=p.ranges.copy(), epoch_utc=raw.epoch_utc, radar=radar,
        doppler=DopplerUsed(np.asarray(block_times), p.ranges.copy(), np.asarray(fdcs), np.asarray(frs),
                            np.asarray(vs)),
        look_side=raw.look_side, source=raw.source, algorithm="rd",
        azimuth_spacing_m=v_mid / p.prf, first_full_line=first_full, last_full_line=last_full,
        parameters=params, timings=timings, orbit=raw.orbit, attitude=raw.attitude, truth=raw.truth,
    )


def focus_rd(raw: RawProduct, doppler, channel: int = 0, **knobs) -> SLC:
    """Focus one receive channel of an in-memory raw product with the RDA (contract 5).

    ``doppler``: any object with vectorized ``fdc(range_m, t)`` and ``fr(range_m, t)``. Knobs: see
    :class:`RdKnobs`. Returns an :class:`sarcli.io.slc.SLC` with zero-Doppler times and slant ranges.
    """
    k = make_knobs(**knobs)
    echo = raw.channel(channel)
    n_lines, nr = echo.shape
    out = np.empty((n_lines, nr), np.complex64)  # the blocks cover every line

    def sink(s: int, block: np.ndarray) -> None:
        def put(c: int, d: int) -> None:  # first touch of the output's pages, shared by the threads
            out[s + c:s + d] = block[c:d]

        _pooled([(c, min(c + 256, block.shape[0])) for c in range(0, block.shape[0], 256)], put, k.workers)

    slc = focus_stream(raw, lambda a, b: echo[a:b], sink, doppler, k, (n_lines, nr))
    slc.image = out
    return slc
