"""Range-Doppler algorithm (RDA) [CumWong2005, ch. 6], processed in azimuth blocks with overlap (bounded memory).

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
4. RCMC + azimuth matched filter with the range-dependent centroid and rate of the block
   (:mod:`sarcli.focus.rcmc`), written into the first n_samples columns of the block;
5. azimuth IFFT of those columns; lines [P, P + e - s) of the block are output lines [s, e);
6. per output line, the correction from the block's model to the model at that line's own time
   (:meth:`RangeDoppler.line_corrections`): the block size does not change the focused image.

Block invariance. The Doppler model and the orbit-timing correction vary along azimuth (the
effective velocity V of an orbit by ~0.04 m/s per second, a centroid estimate by tens of Hz per
second), but in the range-Doppler domain one filter serves a whole block. The model is therefore
evaluated once, in the plan, on a fixed time grid (every ``GRID_LINES`` lines, every ``GRID_SAMPLES``
range samples, the same grid whatever the block layout) and interpolated linearly to each block's
centre (the filter) and to each output line's beam-centre time t_c (the correction). What a
different V does to a point target (derivation in :func:`velocity_correction`): with the
migration factor D(f, V) = sqrt(1 - (lam f / 2V)^2) the residual spectral phase is
E(f) = (4 pi R0 / lam)(D(f, V_block) - D(f, V(t_c))) = E0 + E1 (f - f_c) + E2 (f - f_c)^2 + ...
around the band centre f_c; E1 shifts the peak by -E1 / 2 pi and the phase AT the shifted peak is
E0 - E1 f_c (the tangent's intercept at f = 0: the image carries the absolute carrier f_c). At
Radarsat-1's squint (-5.3 PRF) dE/dV is 22 rad per m/s, so a block of 4096 lines (3.3 s) spans
about 3 rad and 0.07 line; E2 is 1/300 of it (0.13 rad per m/s at the edges of a 1000 Hz band).
Likewise the orbit-timing correction: its time shift dt and phase ph0 belong to each line's own
time. So each output pixel is taken at its corrected time (line + mu, mu = -E1 / 2 pi + dt_block -
dt(t_c), in lines: 16-tap band-pass sinc interpolation at the absolute carrier,
:func:`correct_lines`, skipped when |mu| < ``SHIFT_TOL_LINES`` everywhere in the block) and rotated
by -(E0 - E1 f_c) + ph0(t_c) - ph0_block. What remains between block sizes: E2, the interpolation
error (< 0.7 % at the band edge for |mu| <= 0.1 line, tests), and the azimuth window's centre
(the block's centroid: second order in the centroid change, 0.03 % of amplitude in the tests).
Linear interpolation on the grid errs by (h^2 / 8) |q''| for a quantity q, h = 256 lines (0.2 s):
a polynomial Doppler fit or an orbit varies on scales of the scene or of minutes, so this is below
1e-3 of the correction. Measured (tests): phases across block sizes 512 .. whole scene agree to
3e-3 rad, amplitudes to 0.03 %, positions to 1e-3 line.

Output geometry: column i is closest-approach slant range ``r_first + i dr`` (the raw range grid); line
j has ZERO-DOPPLER time ``t_raw[j] - shift/PRF``, where ``shift`` (integer lines) is the beam-centre
offset Delta = R0 tan(theta)/V at mid-swath and scene centre (:mod:`sarcli.focus.kinematics`):
every target lands within a few lines of its raw data, so squinted scenes (centroids of several PRFs)
need no more overlap than broadside ones. Lines closer than half an aperture to the scene ends see
only part of their aperture (``first_full_line`` / ``last_full_line``; a warning when none is whole).
Peak extra memory per block: the N x L block (complex64) plus a chunk of upsampled rows (bench_focus
reports it against a 1536 x 2048 input, including the output image).

FFT lengths are 5-smooth (:func:`smooth_len`): pocketfft is markedly slower on factors 7 and 11.
"""

from __future__ import annotations

import math
import queue
import time
import warnings
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.fft as sfft
from numba import njit, prange

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, SarcliError
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
from sarcli.gpu.device import check_device
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC, DopplerUsed
from sarcli.model.terrain import ConstantHeight, Terrain
from sarcli.threads import fft_workers

RANGE_GUARD = 64  # range samples beyond the correlation's wrap-free length (SRC impulse response)
CHUNK = 64  # azimuth-frequency rows per chunk of the filter + upsampling + RCMC pass
GRID_LINES = 256  # model grid: a node every GRID_LINES lines (module docstring: interpolation error)
GRID_SAMPLES = 32  # ... and every GRID_SAMPLES range samples (and the last one)
CORRECTION_LINES = 16  # per-line correction computed every 16 output lines, linear in between
SHIFT_TOL_LINES = 1e-3  # per-line time shifts below this (lines) are not applied (phase only)
SHIFT_INTERPOLATOR = "sinc16"  # azimuth interpolator of the per-line shift (tests: error < 1e-4 in band)


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
class RdOptions:
    """Processing knobs of the RDA (each one's accuracy/cost is measured in bench/bench_focus.py).

    range_window, azimuth_window: window specs (:mod:`sarcli.focus.windows`); range_bandwidth_fraction:
    processed part of the chirp band (1 = all of it); azimuth_bandwidth_hz:
    processed Doppler band (default 0.8 PRF); rcmc: interpolator (nearest, linear, sinc4/8/16);
    src: secondary range compression; precision: "single" (complex64) or "double" (complex128);
    block_lines: azimuth FFT length per block (memory; the image does not depend on it, see the
    module docstring); use_replica: the product's replica, else the nominal chirp;
    rcmc_oversample: 1 or 2, range Fourier upsampling before the RCMC interpolation (a windowed sinc
    attenuates frequencies near half the sampling rate: 8 taps pass only 0.31 of a component at
    0.467 cycles/sample, the edge of a Radarsat-1 chirp sampled at 1.07 x its band);
    orbit_timing: with an Earth orbit, place targets at their exact zero-Doppler time (see
    :func:`orbit_time_correction`) instead of the hyperbolic model's; workers: threads (scipy's
    convention: negative counts from the thread budget, :func:`sarcli.threads.budget`); device: cpu, or
    cuda (steps 1-5 on the GPU, :mod:`sarcli.gpu.rd_xp`; the image equals the CPU's within its bound).
    """

    range_window: str = "kaiser:2.5"
    range_bandwidth_fraction: float = 1.0
    azimuth_window: str = "kaiser:2.5"
    azimuth_bandwidth_hz: float | None = None
    rcmc: str = "sinc8"
    src: bool = True
    precision: Literal["single", "double"] = "single"
    block_lines: int = 4096
    use_replica: bool = True
    rcmc_oversample: int = 2
    orbit_timing: bool = True
    workers: int = -1
    device: Literal["cpu", "cuda"] = "cpu"

    def __post_init__(self) -> None:
        check_block_knobs(self)
        parse_interpolator(self.rcmc)
        if self.rcmc_oversample not in (1, 2):
            raise ConfigError(f"rcmc_oversample must be 1 or 2, got {self.rcmc_oversample}")


def check_block_knobs(opts) -> None:
    """Check (and normalize ``device`` of) the knobs the frequency-domain focusers' options share under the
    same names (:class:`RdOptions`, :class:`sarcli.focus.csa.CsaOptions`): device, range_window,
    azimuth_window, precision, block_lines, range_bandwidth_fraction, azimuth_bandwidth_hz."""
    object.__setattr__(opts, "device", check_device(opts.device))
    parse_window(opts.range_window)
    parse_window(opts.azimuth_window)
    if opts.precision not in ("single", "double"):
        raise ConfigError(f"precision must be 'single' or 'double', got {opts.precision!r}")
    if opts.block_lines < 64:
        raise ConfigError(f"block_lines must be at least 64, got {opts.block_lines}")
    if not (math.isfinite(opts.range_bandwidth_fraction) and 0 < opts.range_bandwidth_fraction <= 1):
        raise ConfigError(f"range_bandwidth_fraction must be in (0, 1], got {opts.range_bandwidth_fraction}")
    if opts.azimuth_bandwidth_hz is not None and not (math.isfinite(opts.azimuth_bandwidth_hz)
                                                      and opts.azimuth_bandwidth_hz > 0):
        raise ConfigError(f"azimuth_bandwidth_hz must be a positive number of Hz, got {opts.azimuth_bandwidth_hz}")


def _uniform_prf(t: np.ndarray, radar_prf: float) -> float:
    """The line rate of uniformly spaced azimuth times: (n - 1) / (t[-1] - t[0]). Not 1 / median(diff):
    times carried as float64 absolute seconds (e.g. GPS ~1.3e9 s, ulp 2.4e-7 s) jitter each spacing by
    an ulp, and a median picks one of the jittered values (a PRF error of 4e-4 relative at 1700 Hz, a
    third of a line over a 2.3 s squint offset); the end-to-end span has the error of two times only."""
    if t.size < 2:
        return radar_prf
    dt = np.diff(t)
    mean = float(t[-1] - t[0]) / (t.size - 1)
    if np.max(np.abs(dt - mean)) > 1e-3 * mean:
        raise SarcliError("azimuth lines are not uniformly spaced (PRF change or gap): the RD focuser needs a"
                          " uniform PRF; split the scene at the gap")
    return 1.0 / mean


def doppler_on_grid(doppler, r0: np.ndarray, t, wavelength: float):
    """(fdc, fr, V, sin_squint) per closest range r0 at raw time(s) t (broadcast with r0).

    The model is indexed by beam-centre range R_c = R0 / cos(theta): evaluated at R0 first, then at
    the R_c that this gives, and again until R_c moves by less than 1e-12 of itself (a few steps: the
    error shrinks ~tan^2(theta)-fold per step; at 40 deg the first R_c is 5 % short and V 1 % off, and
    after two steps V is still 2.6e-7 off, 0.08 rad of azimuth phase at R0 = 1.4 km, X band). Refuses NaN/inf.
    """
    r0, tt = np.broadcast_arrays(np.asarray(r0, np.float64), np.asarray(t, np.float64))
    fdc = np.broadcast_to(np.asarray(doppler.fdc(r0, tt), np.float64), r0.shape)
    fr = np.broadcast_to(np.asarray(doppler.fr(r0, tt), np.float64), r0.shape)
    v, s = velocity_and_squint(fdc, fr, r0, wavelength)
    rc = r0 / np.sqrt(1.0 - s * s)
    for _ in range(50):
        fdc = np.broadcast_to(np.asarray(doppler.fdc(rc, tt), np.float64), r0.shape).copy()
        fr = np.broadcast_to(np.asarray(doppler.fr(rc, tt), np.float64), r0.shape).copy()
        v, s = velocity_and_squint(fdc, fr, r0, wavelength)
        rc_new = r0 / np.sqrt(1.0 - s * s)
        if np.all(np.abs(rc_new - rc) <= 1e-12 * rc):
            break
        rc = rc_new
    return fdc, fr, v, s


def _coverage_warnings(doppler, r: np.ndarray, t: np.ndarray) -> list[str]:
    """Warn when the scene reaches beyond the blocks the Doppler model was estimated on.

    A block covers half the spacing of the block centres either side (a single block: the whole
    scene), and the fit also the partial block an estimator leaves at each edge (less than one block
    spacing: a smooth polynomial carried that far is not an extrapolation worth a warning, and the
    model estimated on this very scene always stops there); beyond that the model is extrapolated.
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
        half = 1.5 * float(np.median(np.diff(c))) if c.size > 1 else 0.5 * float(np.ptp(axis))
        half *= 1.01
        lo, hi = c.min() - half, c.max() + half
        if axis[0] < lo or axis[-1] > hi:
            out.append(f"Doppler table covers {name} {lo:.6g}-{hi:.6g} {unit}, scene {axis[0]:.6g}-{axis[-1]:.6g}"
                       f" {unit}: extrapolating")
    return out


@dataclass(frozen=True)
class OutputGrid:
    """The stripmap output grid shared by the RD and backprojection focusers (:func:`plan_grid`).

    prf (Hz), ranges (m, the raw range grid = closest ranges of the output columns), wavelength (m),
    ba (processed Doppler band, Hz), shift (integer lines: output line j has zero-Doppler time
    t_raw[j] - shift / PRF), offsets (beam-centre offset Delta PRF per column at scene centre, lines),
    pad (overlap lines a block needs either side), aperture (lines of the processed band).
    """

    prf: float
    ranges: np.ndarray
    wavelength: float
    ba: float
    shift: int
    offsets: np.ndarray
    pad: int
    aperture: float

    def zero_doppler_times(self, t_raw: np.ndarray) -> np.ndarray:
        """Zero-Doppler time of every output line (s after the epoch)."""
        return t_raw[0] + (np.arange(t_raw.size) - self.shift) / self.prf

    def full_lines(self, n_lines: int) -> tuple[int, int]:
        """(first_full_line, last_full_line): lines that see the whole processed aperture."""
        first = int(math.ceil(0.5 * self.aperture))
        return first, n_lines - 1 - first


def plan_grid(raw: RawProduct, shape: tuple[int, int], doppler, azimuth_bandwidth_hz: float | None) -> OutputGrid:
    """The output grid of a stripmap focuser (see :class:`OutputGrid`), from the model at the scene's
    start, centre and end (the overlap must hold the aperture and the drift of the beam-centre offset)."""
    radar = raw.radar
    prf = _uniform_prf(raw.azimuth_time, radar.prf_hz)
    ranges = radar.first_range_m + np.arange(shape[1]) * C / (2.0 * radar.range_sampling_rate_hz)
    lam = C / radar.carrier_frequency_hz
    ba = 0.8 * prf if azimuth_bandwidth_hz is None else float(azimuth_bandwidth_hz)
    if not 0.0 < ba <= prf:
        raise ConfigError(f"azimuth bandwidth {ba:.4g} Hz must be in (0, PRF = {prf:.4g} Hz]")
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
    # + 4 lines of margin, + 8 for the reach of the per-line shift interpolator (16 taps)
    pad = int(math.ceil(0.5 * aperture + resid)) + 4 + 8
    return OutputGrid(prf, ranges, lam, ba, shift, offsets[1], pad, aperture)


def orbit_time_correction(raw: RawProduct, t, r0: np.ndarray, fdc: np.ndarray, v: np.ndarray, s: np.ndarray,
                          wavelength: float, terrain: Terrain) -> tuple[np.ndarray, np.ndarray]:
    """Orbit corrections of the hyperbolic model at raw times ``t`` (broadcast with the other arrays):
    (time shift dt s, phase ph0 rad).

    The RDA puts a target seen at beam-centre time t at ``t - Delta_model``, Delta_model = R0 tan(theta)/V,
    with phase -4 pi R0_model / lam, R0_model = R_c cos(theta). With a squint of several PRFs Delta is
    seconds long and the hyperbola, fitted to fdc and fr at the beam centre, misplaces the zero-Doppler
    time by a fraction of a line (0.17 line for the Radarsat-1 sample) and the closest range by
    millimetres (2 rad of phase). With an Earth orbit the target seen at (t, R_c = R0/cos(theta), fdc)
    is geolocated on the terrain (:func:`sarcli.focus.geolocation.geolocate_on_terrain`) and its exact
    zero-Doppler time t_zd and closest range R0_true solved (``orbit.geometry``):
    dt = Delta_model - (t - t_zd) and ph0 = 4 pi (R0 - R0_true) / lam. Zeros without an Earth orbit.
    """
    r0, t, fdc, v, s = np.broadcast_arrays(np.asarray(r0, np.float64), np.asarray(t, np.float64), fdc, v, s)
    if raw.orbit is None or raw.orbit.frame not in ("ECI", "ECEF"):
        return np.zeros(r0.shape), np.zeros(r0.shape)
    from orbit.errors import GeometryError
    from orbit.geometry import doppler_time
    from sarcli.focus.geolocation import geolocate_on_terrain, state_vectors

    sv = state_vectors(raw.orbit, raw.epoch_utc)
    rc = r0 / np.sqrt(1.0 - s**2)
    try:
        p = geolocate_on_terrain(sv, t, rc, wavelength, fdc, raw.look_side, terrain)
        t_zd, r0_true = doppler_time(sv, p, t_guess=t)
    except GeometryError as e:
        raise SarcliError(f"orbit timing correction failed ({e}); use orbit_timing=False") from None
    delta_model = beam_centre_offset(r0, v, s)
    return delta_model - (t - t_zd), 4.0 * np.pi * (r0 - r0_true) / wavelength


@dataclass(frozen=True)
class ModelGrid:
    """The Doppler model and the orbit-timing correction on the plan's fixed (time, range) grid.

    ``times`` (n_t,) raw times s, ``columns`` (n_r,) output columns; arrays (n_t, n_r): fdc (Hz),
    fr (Hz/s), v (effective velocity m/s), s (sin squint), dt (s), ph0 (rad). Linear in time and
    range between nodes (module docstring).
    """

    times: np.ndarray
    columns: np.ndarray
    fdc: np.ndarray
    fr: np.ndarray
    v: np.ndarray
    s: np.ndarray
    dt: np.ndarray
    ph0: np.ndarray

    def at(self, t: float) -> dict[str, np.ndarray]:
        """Every quantity at time ``t`` on the grid's columns, (n_r,) each."""
        return self.at_nodes(np.full(self.columns.size, float(t)))

    def at_nodes(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Every quantity at times ``t`` (n_t, n_r) on the grid's own columns (one time per node column)."""
        tt = np.asarray(t, np.float64)
        x = np.clip((tt - self.times[0]) / (self.times[1] - self.times[0]) if self.times.size > 1 else 0 * tt,
                    0.0, self.times.size - 1.0)
        k = np.minimum(np.floor(x).astype(np.int64), max(self.times.size - 2, 0))
        w = x - k
        k1 = np.minimum(k + 1, self.times.size - 1)
        j = np.broadcast_to(np.arange(self.columns.size), tt.shape)
        return {n: (1.0 - w) * a[k, j] + w * a[k1, j] for n, a in
                (("fdc", self.fdc), ("fr", self.fr), ("v", self.v), ("s", self.s), ("dt", self.dt),
                 ("ph0", self.ph0))}

    def at_columns(self, t: float, n_cols: int) -> dict[str, np.ndarray]:
        """Every quantity at time t on every output column 0..n_cols-1 (linear along range)."""
        q = self.at(float(t))
        cols = np.arange(n_cols)
        return {n: np.interp(cols, self.columns, a) for n, a in q.items()}


def model_grid(raw: RawProduct, doppler, grid: OutputGrid, orbit_timing: bool, terrain: Terrain) -> ModelGrid:
    """Evaluate the model on the fixed grid covering every block centre and every output line's beam-centre
    time (raw times t_raw[j] + (offset - shift) / PRF)."""
    t = raw.azimuth_time
    nr = grid.ranges.size
    cols = np.unique(np.r_[np.arange(0, nr, GRID_SAMPLES), nr - 1])
    step = GRID_LINES / grid.prf
    lo = float(t[0] + min(0.0, float(np.min(grid.offsets)) - grid.shift) / grid.prf) - step
    hi = float(t[-1] + max(0.0, float(np.max(grid.offsets)) - grid.shift) / grid.prf) + step
    # nodes at t[0] + k step: the same nodes whatever the block layout
    k0, k1 = math.floor((lo - t[0]) / step), math.ceil((hi - t[0]) / step)
    times = t[0] + np.arange(k0, k1 + 1) * step
    r0 = np.broadcast_to(grid.ranges[cols][None, :], (times.size, cols.size))
    tt = np.broadcast_to(times[:, None], r0.shape)
    fdc, fr, v, s = doppler_on_grid(doppler, r0, tt, grid.wavelength)
    if orbit_timing:
        dt, ph0 = orbit_time_correction(raw, tt, r0, fdc, v, s, grid.wavelength, terrain)
    else:
        dt, ph0 = np.zeros(r0.shape), np.zeros(r0.shape)
    return ModelGrid(times, cols, fdc, fr, v, s, dt, ph0)


def _migration_terms(f: np.ndarray, v: np.ndarray, wavelength: float) -> tuple[np.ndarray, np.ndarray]:
    """(x, D) with x = (lam f / 2V)^2 and D = sqrt(1 - x)."""
    x = (wavelength * f / (2.0 * v)) ** 2
    return x, np.sqrt(1.0 - x)


def velocity_correction(r0: np.ndarray, f_c: np.ndarray, v_block: np.ndarray, v_line: np.ndarray,
                        wavelength: float) -> tuple[np.ndarray, np.ndarray]:
    """(phase rad to ADD at the peak, time s the peak lands late) of a target focused with velocity
    ``v_block`` whose own is ``v_line`` (band centre ``f_c``, closest range ``r0``).

    The target's spectrum carries -4 pi R0 D(f, V_line) / lam - 2 pi f eta0; the filter removes
    -4 pi R0 D(f, V_block) / lam, leaving E(f) = (4 pi R0 / lam)(D(f, V_block) - D(f, V_line)).
    Linearized at the band centre f_c, E = E0 + E1 (f - f_c): the image of the target is
    exp(j (E0 - E1 f_c)) G(eta - eta0 + E1 / 2 pi) with G peaking at 0 with phase 0 (the inverse FFT
    of exp(j E1 f) is a shift), so the peak lands -E1 / 2 pi late with its phase off by E0 - E1 f_c;
    the phase correction is the negative of that. E0 = K (x_l - x_b) / (D_b + D_l) (no
    cancellation), K = 4 pi R0 / lam, x, D of :func:`_migration_terms`; dD/df = -(lam / 2V)^2 f / D.
    The curvature E2 is left: |E2| Ba^2 / 12 of phase (2e-3 rad for 0.05 m/s at Radarsat-1's squint).
    """
    k = 4.0 * np.pi * r0 / wavelength
    xb, db = _migration_terms(f_c, v_block, wavelength)
    xl, dl = _migration_terms(f_c, v_line, wavelength)
    e0 = k * (xl - xb) / (db + dl)
    e1 = k * f_c * ((wavelength / (2.0 * v_line)) ** 2 / dl - (wavelength / (2.0 * v_block)) ** 2 / db)
    return -(e0 - e1 * f_c), -e1 / (2.0 * np.pi)


@njit(parallel=True, cache=True)
def correct_lines(img, pad, first, out, lines_c, cols_c, phi_c, mu_c, carrier, table):
    """out[j, i] = exp(j phi) s_i(pad + j + mu): column i of ``img`` (azimuth samples of a signal around
    ``carrier[i]`` cycles per line, the ABSOLUTE centroid / PRF) interpolated at a fractional line,
    then rotated; phi (rad) and mu (lines) bilinear between the coarse lines ``lines_c`` (global line
    numbers, ``first`` is output line 0) and columns ``cols_c``. ``img`` is OVERWRITTEN (its rows
    around the output lines demodulated, below): the caller's block buffer, not needed afterwards.

    Band-pass interpolation: s(p) = sum_m s[m] h(p - m) exp(j 2 pi c (p - m)) with the windowed-sinc
    table ``table`` (:mod:`sarcli.focus.interp`) for h: the carrier phase is kept as the absolute
    frequency dictates (the same shift in the frequency domain is exp(-j 2 pi f dt) with the absolute f).
    Computed as exp(j 2 pi c p) sum_m (s[m] exp(-j 2 pi c m)) h(p - m): each input sample is
    demodulated once (a per-column phasor advanced line by line in complex128: 1e-16 per step), and a
    pixel costs ``taps`` real-weighted multiply-adds (two real ones each, summed in float64) and one
    complex multiply (the remodulation, a rotation advanced line by line; the former form, a complex
    rotation per tap and two sines/cosines per pixel, was several times slower: bench_parallel).
    """
    n_out, nr = out.shape
    n_in = img.shape[0]
    nph = table.shape[0] - 1
    taps = table.shape[1]
    k0 = taps // 2 - 1
    nl = lines_c.shape[0]
    nc = cols_c.shape[0]
    # the input lines any tap can reach: mu is bilinear between the coarse values, so within their range
    r0 = max(0, pad + int(np.floor(np.min(mu_c))) - k0)
    r1 = min(n_in, pad + n_out + int(np.ceil(np.max(mu_c))) + taps)
    width = 64
    for blk in prange((nr + width - 1) // width):
        c_lo = blk * width
        c_hi = min(nr, c_lo + width)
        ph = np.empty(c_hi - c_lo, np.complex128)
        st = np.empty(c_hi - c_lo, np.complex128)
        for i in range(c_lo, c_hi):
            a = -2.0 * np.pi * ((carrier[i] * r0) % 1.0)
            ph[i - c_lo] = complex(np.cos(a), np.sin(a))
            st[i - c_lo] = complex(np.cos(2.0 * np.pi * carrier[i]), -np.sin(2.0 * np.pi * carrier[i]))
        for m in range(r0, r1):
            for i in range(c_lo, c_hi):
                img[m, i] *= ph[i - c_lo]
                ph[i - c_lo] *= st[i - c_lo]
    # per column block, per coarse line interval: along a column phi and p = pad + j + mu are linear in
    # the line there, so the remodulation exp(j (phi + 2 pi c p)) advances by a fixed rotation per
    # line (two sines/cosines per column and interval; 16 complex128 steps: 1e-15)
    for blk in prange((nr + width - 1) // width):
        c_lo = blk * width
        c_hi = min(nr, c_lo + width)
        cur = np.empty(c_hi - c_lo, np.complex128)
        rot = np.empty(c_hi - c_lo, np.complex128)
        pos = np.empty(c_hi - c_lo)  # p at the interval's first line
        dpos = np.empty(c_hi - c_lo)  # its change per line
        c = 0
        for k in range(nl - 1):
            j_lo = max(0, lines_c[k] - first)
            j_hi = min(n_out, (lines_c[k + 1] if k < nl - 2 else lines_c[k + 1] + 1) - first)
            if j_lo >= j_hi:
                continue
            span = lines_c[k + 1] - lines_c[k]
            for i in range(c_lo, c_hi):
                while c < nc - 2 and cols_c[c + 1] <= i:
                    c += 1
                while c > 0 and cols_c[c] > i:
                    c -= 1
                t = (i - cols_c[c]) / (cols_c[c + 1] - cols_c[c])
                ph_a = (1.0 - t) * phi_c[k, c] + t * phi_c[k, c + 1]  # at line lines_c[k]
                ph_b = (1.0 - t) * phi_c[k + 1, c] + t * phi_c[k + 1, c + 1]  # at line lines_c[k + 1]
                mu_a = (1.0 - t) * mu_c[k, c] + t * mu_c[k, c + 1]
                mu_b = (1.0 - t) * mu_c[k + 1, c] + t * mu_c[k + 1, c + 1]
                w0 = (first + j_lo - lines_c[k]) / span
                q = i - c_lo
                pos[q] = pad + j_lo + mu_a + (mu_b - mu_a) * w0
                dpos[q] = 1.0 + (mu_b - mu_a) / span
                ang = ph_a + (ph_b - ph_a) * w0 + 2.0 * np.pi * ((carrier[i] * pos[q]) % 1.0)
                cur[q] = complex(np.cos(ang), np.sin(ang))
                d = (ph_b - ph_a) / span + 2.0 * np.pi * ((carrier[i] * dpos[q]) % 1.0)
                rot[q] = complex(np.cos(d), np.sin(d))
            for j in range(j_lo, j_hi):
                for i in range(c_lo, c_hi):
                    q = i - c_lo
                    p = pos[q] + (j - j_lo) * dpos[q]
                    n0 = int(np.floor(p))
                    jp = int((p - n0) * nph + 0.5)
                    b = n0 - k0
                    # real weights on the real and imaginary parts (a complex-by-real product in numba
                    # is a full complex multiply), accumulated in float64
                    acc_re = 0.0
                    acc_im = 0.0
                    if b >= 0 and b + taps <= n_in:  # every tap inside the block: a fixed-length loop
                        for tap in range(taps):
                            s = img[b + tap, i]
                            w = table[jp, tap]
                            acc_re += s.real * w
                            acc_im += s.imag * w
                    else:
                        for tap in range(max(0, -b), min(taps, n_in - b)):
                            s = img[b + tap, i]
                            w = table[jp, tap]
                            acc_re += s.real * w
                            acc_im += s.imag * w
                    out[j, i] = complex(acc_re, acc_im) * cur[q]
                    cur[q] *= rot[q]


def correct_lines_numpy(img: np.ndarray, pad: int, first: int, n_out: int, lines_c: np.ndarray, cols_c: np.ndarray,
                        phi_c: np.ndarray, mu_c: np.ndarray, carrier: np.ndarray, interpolator: str,
                        table: np.ndarray | None = None) -> np.ndarray:
    """Plain-numpy reference of :func:`correct_lines` (complex128): exact windowed-sinc weights, or
    with ``table`` the kernel's tabulated ones (the nearest of its phases)."""
    from sarcli.focus.interp import sinc_weights

    lines = first + np.arange(n_out)
    cols = np.arange(img.shape[1])

    def grid(v):
        by_col = np.stack([np.interp(lines, lines_c, v[:, c]) for c in range(cols_c.size)], axis=1)
        return np.stack([np.interp(cols, cols_c, row) for row in by_col])

    phi, mu = grid(phi_c), grid(mu_c)
    taps = int(interpolator[4:])
    p = pad + np.arange(n_out)[:, None] + mu
    n0 = np.floor(p).astype(int)
    if table is None:
        wts = sinc_weights(taps, p - n0)
    else:
        wts = np.asarray(table, np.float64)[((p - n0) * (table.shape[0] - 1) + 0.5).astype(int)]
    out = np.zeros((n_out, img.shape[1]), complex)
    for tap in range(taps):
        m = n0 - (taps // 2 - 1) + tap
        ok = (m >= 0) & (m < img.shape[0])
        val = img[np.clip(m, 0, img.shape[0] - 1), cols[None, :]]
        out += np.where(ok, val * wts[..., tap] * np.exp(2j * np.pi * carrier[None, :] * (p - m)), 0)
    return out * np.exp(1j * phi)


@njit(parallel=True, cache=True)
def apply_line_phase(out, first, lines_c, cols_c, phi_c):
    """out[j, i] *= exp(j phi(first + j, i)), phi linear between the coarse lines ``lines_c`` and columns
    ``cols_c`` where it is given (``phi_c`` (n_lines_c, n_cols_c); at least two of each, covering the
    block's lines and every column); in place.

    Along range the phasor advances by a constant rotation between coarse columns (one complex multiply
    per pixel; phi is linear there, so the recurrence is exact up to round-off: < 1e-12 rad over a span).
    """
    n = out.shape[0]
    nl = lines_c.shape[0]
    nc = cols_c.shape[0]
    for j in prange(n):
        line = first + j
        k = 0
        while k < nl - 2 and lines_c[k + 1] <= line:
            k += 1
        w = (line - lines_c[k]) / (lines_c[k + 1] - lines_c[k])
        for c in range(nc - 1):
            a0 = (1.0 - w) * phi_c[k, c] + w * phi_c[k + 1, c]
            a1 = (1.0 - w) * phi_c[k, c + 1] + w * phi_c[k + 1, c + 1]
            i0 = cols_c[c]
            i1 = cols_c[c + 1]
            step = (a1 - a0) / (i1 - i0)
            cur = complex(np.cos(a0), np.sin(a0))
            rot = complex(np.cos(step), np.sin(step))
            stop = i1 if c < nc - 2 else i1 + 1
            for i in range(i0, stop):
                out[j, i] *= cur
                cur *= rot


def apply_line_phase_numpy(out: np.ndarray, first: int, lines_c: np.ndarray, cols_c: np.ndarray,
                           phi_c: np.ndarray) -> np.ndarray:
    """Plain-numpy reference of :func:`apply_line_phase` (returns the corrected copy)."""
    lines = first + np.arange(out.shape[0])
    by_col = np.stack([np.interp(lines, lines_c, phi_c[:, c]) for c in range(cols_c.size)], axis=1)
    phi = np.stack([np.interp(np.arange(out.shape[1]), cols_c, row) for row in by_col])
    return out * np.exp(1j * phi)


@dataclass
class RdPlan:
    """Everything the RD blocks share (:meth:`RangeDoppler.plan`); read-only while blocks run, except
    ``timings`` (seconds per stage, accumulated by the blocks: diagnostics only)."""

    raw: RawProduct
    options: RdOptions
    terrain: Terrain
    grid: OutputGrid
    model: ModelGrid
    output_shape: tuple[int, int]
    n_blocks: int
    n_valid: int
    n_fft_az: int
    n_fft_r: int
    h: np.ndarray
    wtab: np.ndarray
    kind: int
    table: np.ndarray
    f_bin: np.ndarray
    shift_table: np.ndarray
    gain: np.ndarray | None
    block_time: np.ndarray
    block: list[dict[str, np.ndarray]]
    warnings: list[str]
    timings: dict[str, float] = field(default_factory=dict)

    def block_rows(self, b: int) -> tuple[int, int]:
        s = b * self.n_valid
        return s, min(s + self.n_valid, self.output_shape[0])


class RangeDoppler:
    """The RDA as a focuser (:mod:`sarcli.focus.base`): ``sarcli focus --algorithm rd``."""

    name = "rd"
    Options = RdOptions
    streams = True
    needs_doppler = True

    def plan(self, raw: RawProduct, shape: tuple[int, int], doppler, options: RdOptions,
             terrain: Terrain) -> RdPlan:
        k = options
        n_lines, nr = shape
        if n_lines < 2:
            raise SarcliError("the scene has fewer than two azimuth lines: nothing to focus")
        if nr < 2:
            raise SarcliError("the scene has fewer than two range samples: nothing to focus")
        t0 = time.perf_counter()
        grid = plan_grid(raw, shape, doppler, k.azimuth_bandwidth_hz)
        pad = grid.pad
        n_fft_az = smooth_len(max(k.block_lines, 4 * pad) if n_lines + 2 * pad > k.block_lines
                              else n_lines + 2 * pad)
        n_valid = min(n_lines, n_fft_az - 2 * pad)
        n_ref = reference_pulse(raw.radar, raw.replica if k.use_replica else None).size
        n_fft_r = smooth_len(nr + n_ref // 2 + RANGE_GUARD)
        cdt = np.complex64 if k.precision == "single" else np.complex128
        h, _ = range_filter(raw.radar, n_fft_r, k.range_window, raw.replica if k.use_replica else None,
                            k.range_bandwidth_fraction)
        kind, table = table_for(k.rcmc)
        model = model_grid(raw, doppler, grid, k.orbit_timing, terrain)
        n_blocks = int(math.ceil(n_lines / n_valid))
        t_raw = raw.azimuth_time
        block_time = np.array([t_raw[0] + 0.5 * (b * n_valid + min((b + 1) * n_valid, n_lines) - 1) / grid.prf
                               for b in range(n_blocks)])
        blocks = [model.at_columns(tb, nr) for tb in block_time]
        msgs = _coverage_warnings(doppler, grid.ranges, t_raw)
        first_full, last_full = grid.full_lines(n_lines)
        if first_full > last_full:
            msgs.append(f"scene ({n_lines} lines) is shorter than the synthetic aperture ({grid.aperture:.0f} lines):"
                        " no line is fully focused")
        for m in msgs:
            warnings.warn(m, stacklevel=2)
        return RdPlan(raw=raw, options=k, terrain=terrain, grid=grid, model=model, output_shape=(n_lines, nr),
                      n_blocks=n_blocks, n_valid=n_valid, n_fft_az=n_fft_az, n_fft_r=n_fft_r, h=h.astype(cdt),
                      wtab=window_table(k.azimuth_window), kind=kind,
                      table=table.astype(np.float32 if k.precision == "single" else np.float64),
                      f_bin=sfft.fftfreq(n_fft_az, 1.0 / grid.prf),
                      shift_table=table_for(SHIFT_INTERPOLATOR)[1].astype(np.float32 if k.precision == "single"
                                                                           else np.float64),
                      gain=raw.line_gain(), block_time=block_time,
                      block=blocks, warnings=msgs, timings={"plan_s": time.perf_counter() - t0})

    def focus_block(self, plan: RdPlan, b: int, read_lines: Callable[[int, int], np.ndarray]) -> np.ndarray:
        k, g = plan.options, plan.grid
        n_lines, nr = plan.output_shape
        s, e = plan.block_rows(b)
        a, z = max(0, s - g.pad), min(n_lines, e + g.pad)
        tm = plan.timings
        t0 = time.perf_counter()
        data = np.asarray(read_lines(a, z))
        _add(tm, "io_s", t0)
        if data.shape != (z - a, nr):
            raise SarcliError(f"echo block has shape {data.shape}, expected {(z - a, nr)}")
        gain = None if plan.gain is None else plan.gain[a:z]
        prm = self.block_parameters(plan, b)
        if k.device == "cuda":
            t0 = time.perf_counter()
            img = self._focus_rows_cuda(plan, b, data, a - (s - g.pad), gain, prm)
            _add(tm, "cuda_block_s", t0)
        else:
            img = self._focus_rows(plan, b, data, a - (s - g.pad), gain, prm)
        del data
        return self._correct_block(plan, b, img)

    def block_parameters(self, plan: RdPlan, b: int) -> dict[str, Any]:
        """What block ``b``'s steps need besides the echo, computed once on the host for the CPU and the GPU path:
        for RD the SRC's inverse rates per azimuth-frequency bin (``inv_k``)."""
        return {"inv_k": src_inverse_rates(plan, b)}

    #: the module of :mod:`sarcli.gpu` that holds this focuser's block on the array namespace (``focus_rows``)
    gpu_block = "rd_xp"

    def _focus_rows_cuda(self, plan: RdPlan, b: int, data: np.ndarray, off: int, gain: np.ndarray | None,
                         prm: dict[str, Any]) -> np.ndarray:
        """The CPU's :meth:`_focus_rows` on the GPU (``sarcli.gpu.<gpu_block>.focus_rows``)."""
        import importlib

        from sarcli.gpu.device import require_cuda

        focus_rows = importlib.import_module(f"sarcli.gpu.{self.gpu_block}").focus_rows
        return focus_rows(plan, b, data, off, gain, prm, require_cuda())

    @staticmethod
    def _spectrum(plan: RdPlan, data: np.ndarray, off: int, gain: np.ndarray | None) -> np.ndarray:
        """Steps 1-2 on the CPU: the block's 2-D spectrum (N x L), raw lines ``data`` (times ``gain``) at row
        ``off``."""
        k, tm = plan.options, plan.timings
        t0 = time.perf_counter()
        y = np.empty((plan.n_fft_az, plan.n_fft_r), plan.h.dtype)
        _range_rows(y, off, data, gain, k.workers)
        _add(tm, "range_fft_s", t0)
        t0 = time.perf_counter()
        _fft_inplace(y, 0, False, k.workers)
        _add(tm, "azimuth_fft_s", t0)
        return y

    def _focus_rows(self, plan: RdPlan, b: int, data: np.ndarray, off: int, gain: np.ndarray | None,
                    prm: dict[str, Any]) -> np.ndarray:
        """Steps 1-5 of the module docstring on the CPU: the block's (N x n_samples) azimuth-compressed lines,
        raw lines ``data`` placed at row ``off`` of the block, with the host parameters ``prm``
        (:meth:`block_parameters`)."""
        k, g, raw = plan.options, plan.grid, plan.raw
        nr = plan.output_shape[1]
        tm = plan.timings
        y = self._spectrum(plan, data, off, gain)
        q = plan.block[b]
        t0 = time.perf_counter()
        _filter_rcmc_rows(y, nr, plan.h, prm["inv_k"], plan.f_bin, g, raw.radar.range_sampling_rate_hz,
                          k.rcmc_oversample, q["v"], q["fdc"], q["dt"], q["ph0"], plan.wtab, plan.kind, plan.table,
                          k.workers)
        _add(tm, "range_filter_rcmc_azimuth_s", t0)
        img = y[:, :nr]
        t0 = time.perf_counter()
        _fft_inplace(img, 0, True, k.workers)
        _add(tm, "azimuth_ifft_s", t0)
        return img

    def _correct_block(self, plan: RdPlan, b: int, img: np.ndarray) -> np.ndarray:
        """Step 6 of the module docstring: block ``b``'s output lines from its azimuth-compressed lines ``img``
        (N x n_samples), corrected per line to the model at each line's own time."""
        g = plan.grid
        s, e = plan.block_rows(b)
        nr = plan.output_shape[1]
        q = plan.block[b]
        tm = plan.timings
        out = img[g.pad:g.pad + (e - s)]
        t0 = time.perf_counter()
        lines_c, phi, mu = self.line_corrections(plan, b)
        if np.max(np.abs(mu)) >= SHIFT_TOL_LINES:
            shifted = np.empty((e - s, nr), img.dtype)
            correct_lines(img, g.pad, s, shifted, lines_c, plan.model.columns, phi, mu, q["fdc"] / g.prf,
                          plan.shift_table)
            out = shifted
        elif np.any(phi != 0.0):
            apply_line_phase(out, s, lines_c, plan.model.columns, phi)
        _add(tm, "line_correction_s", t0)
        # C-contiguous (a view of the block buffer is not): the sink's kernels see one layout, and the
        # HDF5 write would copy a strided block anyway
        return np.ascontiguousarray(out, np.complex64)

    @staticmethod
    def line_corrections(plan: RdPlan, b: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(coarse lines, phase rad, shift lines), the last two (n_lines_c, n_columns_c), that block
        ``b``'s output lines need: from the block's model (time ``block_time[b]``) to the model at each
        line's beam-centre time t_c = t_raw[0] + (line + offset - shift) / PRF. Velocity
        (:func:`velocity_correction`) and orbit timing: phase ph0(t_c) - ph0_block, and the target,
        placed dt_block - dt(t_c) late by the block's time shift, is taken from there. Zero at the block
        centre; exactly zero for a model that does not vary in time."""
        g, m = plan.grid, plan.model
        s, e = plan.block_rows(b)
        lines_c = np.r_[np.arange(s, e, CORRECTION_LINES), e].astype(np.int64)
        # the beam-centre time of the target on each line: zero-Doppler time + Delta(t_c), a fixed point
        # (two steps from the scene-centre offsets: Delta moves by R0 d(theta) / V, ~30 lines per 40 Hz of
        # centroid change at 850 km, and that time error would reach the velocity correction)
        t_zd = plan.raw.azimuth_time[0] + (lines_c[:, None] - g.shift) / g.prf
        r0 = g.ranges[m.columns][None, :]
        tc = t_zd + g.offsets[m.columns][None, :] / g.prf
        for _ in range(2):
            q = m.at_nodes(np.broadcast_to(tc, (lines_c.size, m.columns.size)))
            tc = t_zd + beam_centre_offset(r0, q["v"], q["s"])
        line = m.at_nodes(np.broadcast_to(tc, (lines_c.size, m.columns.size)))
        blk = m.at(float(plan.block_time[b]))
        fdc_b = plan.block[b]["fdc"][m.columns]
        phi, late = velocity_correction(r0, fdc_b[None, :], blk["v"][None, :], line["v"], g.wavelength)
        phi = phi + (line["ph0"] - blk["ph0"][None, :])
        mu = (late + blk["dt"][None, :] - line["dt"]) * g.prf
        return lines_c, np.ascontiguousarray(phi, np.float64), np.ascontiguousarray(mu, np.float64)

    def own_parameters(self, plan: RdPlan) -> dict[str, Any]:
        """The product parameters of this focuser beyond the ones every frequency-domain focuser records
        (:meth:`finish`)."""
        k, raw = plan.options, plan.raw
        return {"model_grid_lines": GRID_LINES, "model_grid_samples": GRID_SAMPLES,
                "replica_used": bool(k.use_replica and raw.replica is not None and np.size(raw.replica) > 1)}

    def finish(self, plan: RdPlan) -> SLC:
        g, raw, k = plan.grid, plan.raw, plan.options
        n_lines, nr = plan.output_shape
        first_full, last_full = g.full_lines(n_lines)
        fdcs = np.array([q["fdc"] for q in plan.block])
        frs = np.array([q["fr"] for q in plan.block])
        vs = np.array([q["v"] for q in plan.block])
        dts = np.array([q["dt"] for q in plan.block])
        params = {"algorithm": self.name, **to_mapping(k, keep_none=True), "azimuth_bandwidth_hz": g.ba,
                  "prf_hz": g.prf, "shift_lines": g.shift, "overlap_lines": g.pad, "azimuth_fft_length": plan.n_fft_az,
                  "block_output_lines": plan.n_valid, "range_fft_length": plan.n_fft_r, "n_blocks": plan.n_blocks,
                  "aperture_lines": g.aperture, "orbit_timing_correction_max_s": float(np.max(np.abs(dts))),
                  **self.own_parameters(plan), "terrain": plan.terrain.describe(), "warnings": plan.warnings}
        return SLC.from_raw(raw, image=np.zeros((0, 0), np.complex64),
                            azimuth_time=g.zero_doppler_times(raw.azimuth_time), slant_range=g.ranges.copy(),
                            doppler=DopplerUsed(plan.block_time.copy(), g.ranges.copy(), fdcs, frs, vs),
                            algorithm=self.name, azimuth_spacing_m=float(np.median(vs[:, nr // 2])) / g.prf,
                            first_full_line=first_full, last_full_line=last_full, parameters=params,
                            timings=dict(plan.timings))


RD = RangeDoppler()


def _add(timings: dict[str, float], key: str, t0: float) -> None:
    timings[key] = timings.get(key, 0.0) + time.perf_counter() - t0


def src_inverse_rates(plan: RdPlan, b: int) -> np.ndarray:
    """1 / K_src per azimuth-frequency bin of block ``b`` (zeros without SRC): at mid-swath, with the
    absolute frequency unwrapped around the block's centroid there (:func:`inverse_src_rate`)."""
    if not plan.options.src:
        return np.zeros(plan.n_fft_az)
    g, q = plan.grid, plan.block[b]
    mid = plan.output_shape[1] // 2
    off_f = plan.f_bin - q["fdc"][mid]
    f_abs = q["fdc"][mid] + off_f - g.prf * np.floor(off_f / g.prf + 0.5)
    return inverse_src_rate(f_abs, float(g.ranges[mid]), float(q["v"][mid]), plan.raw.radar.carrier_frequency_hz)


def active_rows(f_bin: np.ndarray, fdc: np.ndarray, prf: float, ba: float) -> np.ndarray:
    """Azimuth-frequency rows inside the processed band ``ba`` around the centroid ``fdc`` of some range
    column (every 16th column tested: the centroid varies slowly); the others are zero in the image."""
    off = f_bin[:, None] - fdc[None, ::16]
    off -= prf * np.floor(off / prf + 0.5)
    return np.any(np.abs(off) <= 0.5 * ba * (1.0 + 1e-9), axis=1)


def focus_rd(raw: RawProduct, doppler, channel: int = 0, terrain: Terrain | None = None, **options: Any) -> SLC:
    """Focus one receive channel of an in-memory raw product with the RDA.

    ``doppler``: any object with vectorized ``fdc(range_m, t)`` and ``fr(range_m, t)``; ``options``: the
    fields of :class:`RdOptions`; ``terrain``: the ground (default 0 m above the ellipsoid).
    Returns an :class:`sarcli.model.slc.SLC` with zero-Doppler times and slant ranges.
    """
    from sarcli.focus.base import focus_in_memory

    return focus_in_memory(RD, raw, doppler, options, terrain or ConstantHeight(0.0), channel)


def _fft_inplace(y: np.ndarray, axis: int, inverse: bool, workers: int, cols: int = 256) -> None:
    """FFT of ``y`` along ``axis`` in place (scipy's pocketfft writes into ``y`` with overwrite_x).

    Along axis 0 in chunks of ``cols`` columns: 1.8x faster than one call on a 2304 x 2880 block
    (cache: bench machine, single thread).
    """
    f = sfft.ifft if inverse else sfft.fft
    for c in range(0, y.shape[1], cols if axis == 0 else y.shape[1]):
        v = y[:, c:c + cols] if axis == 0 else y
        r = f(v, axis=axis, overwrite_x=True, workers=fft_workers(workers))
        if not np.may_share_memory(r, v):
            v[...] = r


def _n_threads(workers: int) -> int:
    """Threads for the chunk pool: ``workers`` (scipy's convention: negative counts from the thread
    budget, :func:`sarcli.threads.budget`: every usable core unless the caller limited it)."""
    return max(1, workers) if workers >= 0 else fft_workers(workers)


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
    active = active_rows(f_bin, fdc, p.prf, p.ba)
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


