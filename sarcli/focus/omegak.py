"""Omega-k (range migration, wavenumber domain) focusing [Cafforio1991; CumWong2005, ch. 8; Bamler1992].

A plug-in beside ``rd`` (``sarcli focus --algorithm omegak``) with the same products, output grid,
azimuth blocks with overlap and block invariance: it reuses RD's plan grid (:func:`plan_grid`: column =
closest range on the raw range grid, line = zero-Doppler time t_raw - shift/PRF), its model grid and its
per-output-line corrections (:meth:`RangeDoppler.line_corrections`, :func:`correct_lines`); only what a
block does to its 2-D spectrum differs.

The 2-D spectrum of a point target. A range-compressed target at closest range R0 and zero-Doppler time
eta0 (hyperbolic range R(eta) = sqrt(R0^2 + V^2 (eta - eta0)^2), :mod:`sarcli.focus.kinematics`), sampled
in range from two-way time tau0 = 2 r_first / c, has by the stationary phase (POSP) the spectrum

    S(f_eta, f_tau) = W_r(f_tau) W_a(f_eta) exp(j theta),
    theta = -(4 pi R0 / c) sqrt((f0 + f_tau)^2 - a^2) + 2 pi f_tau tau0 - 2 pi f_eta eta0 - pi/4,
    a = c f_eta / (2 V)                                                                      (1)

with f_eta the ABSOLUTE azimuth frequency (the centroid may be many PRFs away: f_eta = fdc_ref +
wrap(f_bin - fdc_ref), wrap into [-PRF/2, PRF/2), around the block's centroid at mid-swath fdc_ref).

Full Stolt (``stolt = "full"``). Per block (V_ref, fdc_ref at the mid-swath column, block centre):

1. reference function multiply (RFM, bulk focusing) at R_ref, with the matched filter H_r:
   exp(+j (4 pi R_ref / c) sqrt((f0 + f_tau)^2 - a^2) - j 2 pi f_tau tau0): a target at R_ref is now
   focused; one at R0 keeps -(4 pi (R0 - R_ref) / c) sqrt((f0 + f_tau)^2 - a^2);
2. Stolt mapping f0 + f_tau' = sqrt((f0 + f_tau)^2 - a^2) [Stolt1978] (via [Cafforio1991]): the row is
   resampled on a uniform f_tau' grid, the input taken at f_tau = sqrt((f0 + f_tau')^2 + a^2) - f0 by a
   windowed-sinc (or linear) kernel (knob ``stolt_kernel``); the residual becomes LINEAR in f_tau',
   -(4 pi (R0 - R_ref) / c)(f0 + f_tau'): every range is focused at once, exactly for constant V; the
   samples are weighted by the Jacobian d f_tau / d f_tau' = (f0 + f_tau') / (f0 + f_tau) (~ D: the
   image keeps RD's and backprojection's scale although its band widens by 1 / D);
3. exp(-j (4 pi R_ref / c)(f0 + f_tau') + j 2 pi f_tau' tau0) restores the reference range: the range IFFT
   puts the target on sample (R0 - r_first) / dr with phase -4 pi R0 / lam (the SLC convention). The
   mapped spectrum of row f_eta is centred on c_k = f0 (D_k - 1), D_k = sqrt(1 - (lam f_eta / 2V)^2)
   (the target is seen at the squint angle: its closest-range wavenumber is k cos(theta)); the output
   bins take their absolute f_tau' = c_k + wrap(f_b - c_k), so the image carries the range carrier c_k
   that exact backprojection gives too, and its band is B / D_k (finer closest-range resolution);
4. per column (range-Doppler domain, after the range IFFT): the azimuth window W((f - fdc_i)/Ba) on each
   column's own centroid, exp(j pi/4 - j 2 pi f_bin shift / PRF) (the POSP phase, the output line
   convention of RD), the orbit-timing correction exp(-j 2 pi f dt_i + j ph0_i) (:func:`orbit_time_correction`)
   and the DIFFERENTIAL velocity correction below; then the azimuth IFFT and RD's per-line corrections.

The phase constants of 1 and 3 cancel ((4 pi R_ref / c) f0 D_k): both are computed without them (their
difference form, e.g. sqrt((f0 + f)^2 - a^2) - f0 D_k = (2 f0 f + f^2)/(sqrt(...) + f0 D_k)), in float64.
The interpolation needs a smooth row: after the RFM the targets of row k sit at range-time offsets
(R - R_ref / D_k) (R the recorded slant range), so R_ref = D(fdc_ref) r_mid centres them; the
range FFT is zero-padded to ``stolt_oversample`` x the recorded extent so that they fill at most
1 / oversample of the circular span, where the kernel's response is flat (the error of the
kernel interpolating a component at t cycles per bin is |sum_k w_k(mu) exp(j 2 pi t (k - mu)) - 1|,
t <= 1 / (2 oversample): tests measure it per kernel length; docs/focusing.md lists the numbers).

Range-varying effective velocity (orbit). Steps 1-2 use V_ref; a target at R0 with V(R0) keeps, after
the mapping, the phase -(4 pi R0 / c) sqrt((f0 + f_tau')^2 + a_ref^2 - a_V^2). At the band centre
f_tau' = c_k this is -(4 pi R0 / lam) D(f, V(R0)) instead of -(4 pi R0 / lam) D(f, V_ref): the column
correction exp(+j (4 pi R0 / lam)(D(f, V(R0)) - D(f, V_ref))) removes it exactly at the carrier
[CumWong2005, sec. 8.5, the differential azimuth compression]. Its slope in f_tau' moves the target's
range envelope by R0 (D_ref / D_V - 1) ~ R0 sin^2(theta) dV / V (0.3 m, 0.05 sample, at the edge of a
Radarsat-1 swath at -6 PRF with 3 m/s of V from its centre; zero with a linear track): the column
correction takes the envelope there (band-pass 8-tap sinc around the row's carrier, where the shift
exceeds 1e-3 sample: the differential RCMC). What remains is the curvature in f_tau' (a range-quadratic
phase (4 pi R0 / c) (a_V^2 - a_ref^2) f_tau'^2 / (2 f0^3 D^3), below 1e-4 rad there) and the
interpolation error of a shift of hundredths of a sample (< 1e-3, tests).
The centroid varying across the swath is exact (window per column) as long as each
column's processed band lies within half a PRF of fdc_ref (the absolute frequency of a 2-D bin is the
same for every column): |fdc(R) - fdc_ref| + Ba / 2 <= PRF / 2, checked in the plan (one-line error).

Monochromatic approximation (``stolt = "monochromatic"``). The Stolt mapping linearized at the carrier,
sqrt((f0 + f_tau)^2 - a^2) ~ f0 D + f_tau / D: the mapping becomes a per-row shift and scaling that the
range-Doppler domain applies as RCMC (R0 / D(f)) with the azimuth filter exp(j 4 pi R0 (D - 1) / lam) --
RD's fused kernel (:func:`sarcli.focus.rcmc.rcmc_azimuth`, per column V, centroid, dt, ph0) -- after the
RFM's NON-linear part at R_ref = r_mid (the bulk secondary range compression of all orders, exact at
R_ref) in the 2-D domain. The residual is the monochromatic error

    Phi_m(f_eta, f_tau) = -(4 pi (R0 - R_ref) / c) [sqrt((f0 + f_tau)^2 - a^2) - f0 D - f_tau / D]
                       ~ (4 pi (R0 - R_ref) / c) a^2 f_tau^2 / (2 f0^3 D^3)                     (2)

(:func:`monochromatic_phase_error`): quadratic in f_tau, growing with the distance to R_ref, the relative
bandwidth squared and sin^2(squint); RD's SRC at mid-swath leaves the same kind of residual.

Memory: the N x L block with L ~ stolt_oversample x (n_samples + n_ref / 2) (complex64), one buffer
of a chunk of rows per thread. FFT lengths are 5-smooth (:func:`smooth_len`).
"""

from __future__ import annotations

import dataclasses
import math
import queue
import time
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.fft as sfft
from numba import njit

from sarcli.errors import ConfigError, SarcliError
from sarcli.focus.interp import interpolate_numpy, parse_interpolator, table_for
from sarcli.focus.kinematics import migration_factor
from sarcli.focus.rangecomp import C, chirp_band, range_filter, reference_pulse
from sarcli.focus.rda import (
    CHUNK,
    RANGE_GUARD,
    RangeDoppler,
    RdOptions,
    RdPlan,
    _add,
    _fft_inplace,
    _filter_rcmc_rows,
    _n_threads,
    _pooled,
    active_rows,
    smooth_len,
)
from sarcli.focus.windows import parse_window, table_lookup
from sarcli.gpu.device import check_device
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC
from sarcli.model.terrain import Terrain

STOLT_MODES = ("full", "monochromatic")
SHIFT_TOL_SAMPLES = 1e-3  # differential range shifts below this (samples) are not interpolated
RESTART = 64  # exact restarts of the Stolt kernel's phasor recurrences, every RESTART bins
DIFF_INTERPOLATOR = "sinc8"  # the differential range shift's kernel (shifts are hundredths of a sample)


@dataclass(frozen=True)
class OmegakOptions:
    """Processing knobs of omega-k (the module docstring; measured in docs/focusing.md).

    stolt: "full" (Stolt interpolation) or "monochromatic" (its linearization, RD's RCMC kernel);
    stolt_kernel: interpolator of the full mapping (linear, sinc4, sinc8, sinc16); stolt_oversample:
    range FFT length over the recorded extent (>= 1; 2 keeps the rows' content within half the span);
    rcmc, rcmc_oversample: the monochromatic mode's RCMC interpolator and range upsampling (as RD's).
    device: cpu, or cuda (steps 1-4 on the GPU, :mod:`sarcli.gpu.omegak_xp`).
    The rest mean what they mean in :class:`sarcli.focus.rda.RdOptions`.
    """

    stolt: Literal["full", "monochromatic"] = "full"
    stolt_kernel: str = "sinc16"
    stolt_oversample: float = 2.0
    range_window: str = "kaiser:2.5"
    range_bandwidth_fraction: float = 1.0
    azimuth_window: str = "kaiser:2.5"
    azimuth_bandwidth_hz: float | None = None
    rcmc: str = "sinc8"
    rcmc_oversample: int = 2
    precision: Literal["single", "double"] = "single"
    block_lines: int = 4096
    use_replica: bool = True
    orbit_timing: bool = True
    workers: int = -1
    device: Literal["cpu", "cuda"] = "cpu"

    def __post_init__(self) -> None:
        object.__setattr__(self, "device", check_device(self.device))
        if self.stolt not in STOLT_MODES:
            raise ConfigError(f"stolt must be one of {', '.join(STOLT_MODES)}, got {self.stolt!r}")
        kind, _ = parse_interpolator(self.stolt_kernel)
        if kind == 0:
            raise ConfigError("stolt_kernel 'nearest' is not an interpolator of a spectrum: use linear or sinc4/8/16")
        if not (math.isfinite(self.stolt_oversample) and 1.0 <= self.stolt_oversample <= 4.0):
            raise ConfigError(f"stolt_oversample must be in [1, 4], got {self.stolt_oversample}")
        parse_window(self.range_window)
        parse_window(self.azimuth_window)
        self.rd_options()  # the shared knobs, checked as RD checks them

    def rd_options(self) -> RdOptions:
        """The RD options of the shared knobs (plan grid, model, range filter, monochromatic kernel)."""
        return RdOptions(range_window=self.range_window, range_bandwidth_fraction=self.range_bandwidth_fraction,
                         azimuth_window=self.azimuth_window, azimuth_bandwidth_hz=self.azimuth_bandwidth_hz,
                         rcmc=self.rcmc, src=False, precision=self.precision, block_lines=self.block_lines,
                         use_replica=self.use_replica, rcmc_oversample=self.rcmc_oversample,
                         orbit_timing=self.orbit_timing, workers=self.workers)


@dataclass(kw_only=True)
class OmegakPlan(RdPlan):
    """RD's plan (grid, model, blocks, corrections) plus the omega-k parts: the range FFT length and
    filter for the Stolt block (``n_fft_r``, ``h``), the Stolt kernel (``stolt_kind``, ``stolt_table``)
    and per block the reference range (m) and velocity (m/s) and the centroid the 2-D bins unwrap on."""

    stolt_kind: int
    stolt_table: np.ndarray
    r_ref: np.ndarray
    v_ref: np.ndarray
    fdc_ref: np.ndarray


def absolute_doppler(f_bin: np.ndarray, fdc_ref: float, prf: float) -> np.ndarray:
    """Absolute azimuth frequency of FFT bins: fdc_ref + wrap(f_bin - fdc_ref) into [-PRF/2, PRF/2)."""
    off = np.asarray(f_bin, np.float64) - fdc_ref
    return fdc_ref + off - prf * np.floor(off / prf + 0.5)


def stolt_input_frequency(f_out: np.ndarray, f_eta: np.ndarray, v: float, f0: float) -> np.ndarray:
    """The Stolt mapping's inverse: the input range frequency f_tau = sqrt((f0 + f_tau')^2 + a^2) - f0,
    a = c f_eta / 2V, for output frequencies f_tau' (broadcast; Hz)."""
    a2 = (C * np.asarray(f_eta, np.float64) / (2.0 * v)) ** 2
    f = f0 + np.asarray(f_out, np.float64)
    return (f * f + a2 - f0 * f0) / (np.sqrt(f * f + a2) + f0)


def block_parameters(plan: OmegakPlan, b: int) -> dict[str, Any]:
    """Block ``b``'s parameters that the CPU and the CUDA paths share: ``f_eta`` the absolute azimuth frequency
    of each row (unwrapped on the block's ``fdc_ref``), ``f_tau`` the range FFT frequencies (Hz), ``tau0`` the
    two-way time of the first range sample (s) and ``active`` the rows inside the processed band at some range
    (:func:`sarcli.focus.rda.active_rows`)."""
    g, radar = plan.grid, plan.raw.radar
    return {"f_eta": absolute_doppler(plan.f_bin, float(plan.fdc_ref[b]), g.prf),
            "f_tau": sfft.fftfreq(plan.n_fft_r, 1.0 / radar.range_sampling_rate_hz),
            "tau0": 2.0 * float(g.ranges[0]) / C,
            "active": active_rows(plan.f_bin, plan.block[b]["fdc"], g.prf, g.ba)}


def monochromatic_phase_error(r0: float, r_ref: float, f_eta, f_tau, v: float, f0: float) -> np.ndarray:
    """Phi_m of eq. (2) (rad, exact form): the phase the monochromatic mode leaves on a target at closest
    range ``r0`` at azimuth/range frequencies (f_eta, f_tau) (broadcast), reference range ``r_ref``."""
    a2 = (C * np.asarray(f_eta, np.float64) / (2.0 * v)) ** 2
    d = np.sqrt(1.0 - a2 / f0**2)
    f = np.asarray(f_tau, np.float64)
    # sqrt((f0 + f)^2 - a^2) - f0 D - f / D without cancellation of the large terms
    s = np.sqrt((f0 + f) ** 2 - a2)
    nl = (2.0 * f0 * f + f * f) / (s + f0 * d) - f / d
    return -(4.0 * np.pi * (r0 - r_ref) / C) * nl


@njit(nogil=True, cache=True)
def stolt_rows(x, h, f_tau, f_eta, v_ref, r_ref, tau0, f0, fs, kind, table, out):
    """Full Stolt step of rows of the 2-D spectrum: out[k] = IFFT-ready row k (FFT order), steps 1-3 of the
    module docstring. ``x`` (rows, L) the spectrum rows (FFT order, signed FFT frequencies ``f_tau``),
    ``h`` the range matched filter, ``f_eta`` (rows,) absolute azimuth frequencies; ``kind``/``table`` the
    interpolator (:mod:`sarcli.focus.interp`: 1 linear, 2 windowed sinc). Serial and GIL-free.

    Per row: u[j] = x h exp(j Phi_in) on the frequency-ordered axis (j = 0 .. L-1 for f = (j - L/2) df,
    Phi_in = (4 pi R_ref / c)(2 f0 f + f^2)/(sqrt((f0 + f)^2 - a^2) + f0 D) - 2 pi f tau0); output bin q
    takes f' = c_k + wrap(f_tau[q] - c_k), interpolates u at the input frequency of the mapping
    (zero beyond the sampled band: no wrap-around), and multiplies by
    exp(-j (4 pi R_ref / c)(f' - c_k) + j 2 pi f' tau0).
    """
    rows, n = x.shape
    df = fs / n
    half = n // 2
    nph = table.shape[0] - 1
    taps = table.shape[1]
    k0 = taps // 2 - 1
    kr = 4.0 * np.pi * r_ref / 2.99792458e8
    u = np.empty(n, np.complex128)
    u_re = np.empty(n)
    u_im = np.empty(n)
    for k in range(rows):
        a2 = (2.99792458e8 * f_eta[k] / (2.0 * v_ref)) ** 2
        d = math.sqrt(1.0 - a2 / (f0 * f0))
        ck = f0 * (d - 1.0)
        # input phasors: Phi_in is smooth in f, so exp(j Phi_in) advances by a second-order recurrence
        # (phase step and its increment from three exact values), restarted exactly every `span` bins, so
        # that the neglected third-order term, |d3 Phi/df3| (span df)^3 / 6, stays below 1e-6 rad:
        # |d3 Phi/df3| <= 3 kr a^2 (f0 + fs/2) / ((f0 - fs/2)^2 - a^2)^(5/2) (64 bins for Radarsat-1)
        smin2 = (f0 - 0.5 * fs) ** 2 - a2
        third = 3.0 * kr * a2 * (f0 + 0.5 * fs) / (smin2 * smin2 * math.sqrt(smin2))
        span = RESTART
        if third > 0.0:
            span = max(3, min(RESTART, int((6e-6 / third) ** (1.0 / 3.0) / df)))
        j = 0
        while j < n:
            e = min(n, j + span)
            p0 = _phi_in(j - half, df, kr, f0, a2, d, tau0)
            cur = complex(math.cos(p0), math.sin(p0))
            step = 1.0 + 0j
            curv = 1.0 + 0j
            if e - j > 2:
                p1 = _phi_in(j + 1 - half, df, kr, f0, a2, d, tau0)
                p2 = _phi_in(j + 2 - half, df, kr, f0, a2, d, tau0)
                step = complex(math.cos(p1 - p0), math.sin(p1 - p0))
                curv = complex(math.cos(p2 - 2.0 * p1 + p0), math.sin(p2 - 2.0 * p1 + p0))
            for jj in range(j, e):
                m = jj - half
                q = m if m >= 0 else m + n
                uv = x[k, q] * h[q] * cur
                u[jj] = uv
                u_re[jj] = uv.real
                u_im[jj] = uv.imag
                cur *= step
                step *= curv
            j = e
        # output: Phi_out = -kr w + 2 pi f' tau0 is linear in w, so its phasor advances by one rotation per
        # bin, restarted exactly every RESTART bins and wherever w wraps
        dph = -kr * df + 2.0 * np.pi * df * tau0
        rot = complex(math.cos(dph), math.sin(dph))
        w_prev = 1e300
        cur = 1.0 + 0j
        for q in range(n):
            w = f_tau[q] - ck
            w -= fs * math.floor(w / fs + 0.5)
            if q % RESTART == 0 or abs(w - w_prev - df) > 0.5 * df:
                ph = -kr * w + 2.0 * np.pi * (((ck + w) * tau0) % 1.0)
                cur = complex(math.cos(ph), math.sin(ph))
            else:
                cur *= rot
            w_prev = w
            # input frequency of the mapping (the module docstring's difference form)
            fin = (2.0 * f0 * d * w + w * w) / (math.sqrt((f0 * d + w) ** 2 + a2) + f0)
            p = fin / df + half
            val = 0j
            i = int(math.floor(p))
            if kind == 1:
                mu = p - i
                if 0 <= i < n:
                    val += u[i] * (1.0 - mu)
                if 0 <= i + 1 < n:
                    val += u[i + 1] * mu
            else:
                jp = int((p - i) * nph + 0.5)
                b = i - k0
                # real weights on the real and imaginary parts (a complex-by-real product in numba is a
                # full complex multiply)
                acc_re = 0.0
                acc_im = 0.0
                if b >= 0 and b + taps <= n:
                    for t in range(taps):
                        wt = table[jp, t]
                        acc_re += u_re[b + t] * wt
                        acc_im += u_im[b + t] * wt
                else:
                    for t in range(taps):
                        if 0 <= b + t < n:
                            wt = table[jp, t]
                            acc_re += u_re[b + t] * wt
                            acc_im += u_im[b + t] * wt
                val = complex(acc_re, acc_im)
            # Jacobian of the change of variable, d f_tau / d f_tau' = (f0 + f_tau') / (f0 + f_tau)
            out[k, q] = val * ((f0 + ck + w) / (f0 + fin)) * cur


@njit(inline="always")
def _phi_in(m, df, kr, f0, a2, d, tau0):
    """Phi_in at the frequency-ordered bin m (f = m df), see :func:`stolt_rows`."""
    f = m * df
    return kr * (2.0 * f0 * f + f * f) / (math.sqrt((f0 + f) ** 2 - a2) + f0 * d) - 2.0 * np.pi * f * tau0


def stolt_rows_numpy(x: np.ndarray, h: np.ndarray, f_tau: np.ndarray, f_eta: np.ndarray, v_ref: float,
                     r_ref: float, tau0: float, f0: float, fs: float, interpolator: str) -> np.ndarray:
    """Plain-numpy reference of :func:`stolt_rows` (complex128, exact interpolation weights)."""
    n = x.shape[1]
    df = fs / n
    f_sorted = (np.arange(n) - n // 2) * df
    order = np.mod(np.arange(n) - n // 2, n)
    a2 = (C * np.asarray(f_eta, np.float64)[:, None] / (2.0 * v_ref)) ** 2
    d = np.sqrt(1.0 - a2 / f0**2)
    kr = 4.0 * np.pi * r_ref / C
    s = np.sqrt((f0 + f_sorted[None, :]) ** 2 - a2)
    ph_in = kr * (2 * f0 * f_sorted + f_sorted**2)[None, :] / (s + f0 * d) - 2 * np.pi * f_sorted[None, :] * tau0
    u = x[:, order] * h[order][None, :] * np.exp(1j * ph_in)
    ck = f0 * (d - 1.0)
    w = f_tau[None, :] - ck
    w = w - fs * np.floor(w / fs + 0.5)
    fin = stolt_input_frequency(ck + w, np.asarray(f_eta)[:, None], v_ref, f0)
    val = interpolate_numpy(u, fin / df + n // 2, interpolator)
    return val * (f0 + ck + w) / (f0 + fin) * np.exp(1j * (-kr * w + 2 * np.pi * (ck + w) * tau0))


@njit(nogil=True, cache=True)
def column_corrections(z, f_bin, r0, v, v_ref, fdc, dt, ph0, wavelength, prf, ba, wtab, shift, f0, dr, table, out):
    """Step 4 of the module docstring on rows of the range-Doppler domain (``z`` may be longer than the
    ``len(r0)`` output columns): out[k, i] = s_i x W((f - fdc_i) / Ba) x exp(j [(4 pi r0_i / lam)(D(f, v_i) -
    D(f, v_ref)) + pi/4 - 2 pi f_bin shift / PRF - 2 pi f dt_i + ph0_i]), f = fdc_i + wrap(f_bin - fdc_i)
    (zero outside the band). D(f, v_i) - D(f, v_ref) = (x_ref - x_i) / (D_i + D_ref), x = (lam f / 2v)^2:
    no cancellation. s_i: z[k, i], or where the differential range shift delta = r0_i (D_ref / D_i - 1) / dr
    reaches ``SHIFT_TOL_SAMPLES``, the row's ENVELOPE at i + delta: band-pass interpolation around the
    row's range carrier c = f0 (D_ref - 1) (cycles per sample c / fs = c dr 2 / c_light), remodulated at
    i (the carrier phase belongs to the differential azimuth term), with the windowed-sinc ``table``.
    Serial and GIL-free."""
    rows, n = z.shape
    nr = r0.shape[0]
    nph = table.shape[0] - 1
    taps = table.shape[1]
    k0 = taps // 2 - 1
    for k in range(rows):
        fb = f_bin[k]
        psh = -2.0 * np.pi * fb * shift / prf + 0.25 * np.pi
        for i in range(nr):
            off = fb - fdc[i]
            off -= prf * math.floor(off / prf + 0.5)
            u = off / ba
            if u < -0.5 or u > 0.5:
                out[k, i] = 0.0
                continue
            f = fdc[i] + off
            xi = (wavelength * f / (2.0 * v[i])) ** 2
            xr = (wavelength * f / (2.0 * v_ref)) ** 2
            di = math.sqrt(1.0 - xi)
            dref = math.sqrt(1.0 - xr)
            dd = (xr - xi) / (di + dref)
            ph = 4.0 * np.pi * r0[i] * dd / wavelength + psh - 2.0 * np.pi * f * dt[i] + ph0[i]
            delta = -r0[i] * dd / (di * dr)
            if abs(delta) < SHIFT_TOL_SAMPLES:
                val = complex(z[k, i])
            else:
                # carrier in cycles per sample: f0 (D_ref - 1) / fs, fs = c_light / (2 dr)
                cyc = -f0 * xr / (1.0 + dref) * 2.0 * dr / 2.99792458e8
                p = i + delta
                n0 = int(math.floor(p))
                jp = int((p - n0) * nph + 0.5)
                a = 2.0 * np.pi * ((cyc * (i - n0 + k0)) % 1.0)
                rot = complex(math.cos(a), math.sin(a))
                b = -2.0 * np.pi * (cyc % 1.0)
                step = complex(math.cos(b), math.sin(b))
                val = 0j
                for t in range(taps):
                    m = n0 - k0 + t
                    if 0 <= m < n:
                        val += z[k, m] * (table[jp, t] * rot)
                    rot *= step
            out[k, i] = val * (table_lookup(wtab, u) * complex(math.cos(ph), math.sin(ph)))


@njit(nogil=True, cache=True)
def bulk_phase_rows(x, f_tau, f_eta, v_ref, r_ref, f0):
    """Monochromatic mode: rows of the 2-D spectrum times exp(j (4 pi R_ref / c) NL(f_tau)), NL the
    non-linear part of sqrt((f0 + f_tau)^2 - a^2) in f_tau (eq. 2's bracket), in place."""
    rows, n = x.shape
    kr = 4.0 * np.pi * r_ref / 2.99792458e8
    for k in range(rows):
        a2 = (2.99792458e8 * f_eta[k] / (2.0 * v_ref)) ** 2
        d = math.sqrt(1.0 - a2 / (f0 * f0))
        for q in range(n):
            f = f_tau[q]
            nl = (2.0 * f0 * f + f * f) / (math.sqrt((f0 + f) ** 2 - a2) + f0 * d) - f / d
            ph = kr * nl
            x[k, q] *= complex(math.cos(ph), math.sin(ph))


class Omegak(RangeDoppler):
    """Omega-k as a focuser (:mod:`sarcli.focus.base`): ``sarcli focus --algorithm omegak``. It shares RD's
    grid, model, per-line corrections and metadata (``finish``); its blocks are the module docstring's."""

    name = "omegak"
    azimuth_compression = "frequency"  # its processing gain (sarcli.calibration.radiometry)
    Options = OmegakOptions

    def plan(self, raw: RawProduct, shape: tuple[int, int], doppler, options: OmegakOptions,
             terrain: Terrain) -> OmegakPlan:
        k = options
        base = super().plan(raw, shape, doppler, k.rd_options(), terrain)
        t0 = time.perf_counter()
        g = base.grid
        nr = shape[1]
        mid = nr // 2
        dr = C / (2.0 * raw.radar.range_sampling_rate_hz)
        self._check_wrap(base)
        fdc_ref = np.array([q["fdc"][mid] for q in base.block])
        v_ref = np.array([q["v"][mid] for q in base.block])
        d_ref = migration_factor(fdc_ref, v_ref, g.wavelength)
        n_ref = reference_pulse(raw.radar, raw.replica if k.use_replica else None).size
        cdt = np.complex64 if k.precision == "single" else np.complex128
        if k.stolt == "full":
            # rows hold the targets at R - R_ref / D(f) (R recorded): the extent of the recorded window
            # plus the pulse tails plus the migration across the band
            d_lo = np.array([migration_factor(fc + 0.5 * g.ba * np.array([-1.0, 1.0]), v, g.wavelength)
                             for fc, v in zip(fdc_ref, v_ref, strict=True)])
            r_ref = d_ref * g.ranges[mid]
            band_rcm = float(np.max(r_ref * np.abs(1.0 / d_lo[:, 0] - 1.0 / d_lo[:, 1]))) / dr
            extent = nr + n_ref // 2 + band_rcm
            # targets closer than r_first (seen at the near edge when squinted) land at negative range
            # samples, circularly at the end of the row: beyond the n_samples output columns
            below = float(np.max(g.ranges[0] * (1.0 - np.min(d_lo, axis=1)))) / dr
            n_fft_r = smooth_len(int(math.ceil(max(k.stolt_oversample * extent, nr + below + n_ref // 2)))
                                 + RANGE_GUARD)
            h, _ = range_filter(raw.radar, n_fft_r, k.range_window, raw.replica if k.use_replica else None,
                                k.range_bandwidth_fraction)
            h = h.astype(cdt)
        else:
            n_fft_r, h = base.n_fft_r, base.h
            r_ref = np.full(fdc_ref.size, float(g.ranges[mid]))
        skind, stab = table_for(k.stolt_kernel)
        fields = {f.name: getattr(base, f.name) for f in dataclasses.fields(RdPlan)}
        fields.update(options=k, n_fft_r=n_fft_r, h=h)
        plan = OmegakPlan(**fields, stolt_kind=skind, stolt_table=stab.astype(np.float64), r_ref=r_ref,
                          v_ref=v_ref, fdc_ref=fdc_ref)
        _add(plan.timings, "plan_s", t0)
        return plan

    @staticmethod
    def _check_wrap(plan: RdPlan) -> None:
        """Refuse a centroid that varies across the swath by more than (PRF - Ba) / 2 (module docstring)."""
        m, g = plan.model, plan.grid
        mid = int(np.argmin(np.abs(m.columns - g.ranges.size // 2)))
        spread = float(np.max(np.abs(m.fdc - m.fdc[:, mid:mid + 1])))
        if spread + 0.5 * g.ba > 0.5 * g.prf * (1.0 + 1e-9):
            raise SarcliError(f"the Doppler centroid varies by {spread:.0f} Hz across the swath, more than (PRF - Ba)/2"
                              f" = {0.5 * (g.prf - g.ba):.0f} Hz: a 2-D frequency-domain focuser cannot unwrap it;"
                              " use a narrower azimuth band or --algorithm rd")

    block_parameters = staticmethod(block_parameters)  # type: ignore[assignment]  # the host parameters
    gpu_block = "omegak_xp"

    def _focus_rows(self, plan: OmegakPlan, b: int, data: np.ndarray, off: int,  # type: ignore[override]
                    gain: np.ndarray | None, prm: dict[str, Any]) -> np.ndarray:
        """Steps 1-4 of the module docstring on the CPU: the block's (N x n_samples) azimuth-compressed lines,
        raw lines ``data`` (times ``gain`` per line) at row ``off``; ``prm`` from :func:`block_parameters`."""
        k, g, raw = plan.options, plan.grid, plan.raw
        nr = plan.output_shape[1]
        tm = plan.timings
        y = self._spectrum(plan, data, off, gain)
        q = plan.block[b]
        f_eta, f_tau = prm["f_eta"], prm["f_tau"]
        t0 = time.perf_counter()
        if k.stolt == "full":
            self._stolt_block(plan, b, y, prm, q)
        else:
            _pooled([(c, min(c + CHUNK, y.shape[0])) for c in range(0, y.shape[0], CHUNK)],
                    lambda c, d: bulk_phase_rows(y[c:d], f_tau, f_eta[c:d], float(plan.v_ref[b]),
                                                 float(plan.r_ref[b]), raw.radar.carrier_frequency_hz), k.workers)
            _filter_rcmc_rows(y, nr, plan.h, np.zeros(plan.n_fft_az), plan.f_bin, g, raw.radar.range_sampling_rate_hz,
                              k.rcmc_oversample, q["v"], q["fdc"], q["dt"], q["ph0"], plan.wtab, plan.kind, plan.table,
                              k.workers)
        _add(tm, "stolt_s" if k.stolt == "full" else "bulk_rcmc_azimuth_s", t0)
        img = y[:, :nr]
        t0 = time.perf_counter()
        _fft_inplace(img, 0, True, k.workers)
        _add(tm, "azimuth_ifft_s", t0)
        return img

    @staticmethod
    def _stolt_block(plan: OmegakPlan, b: int, y: np.ndarray, prm: dict[str, Any], q: dict) -> None:
        """Steps 1-4 on the active rows of the block's 2-D spectrum ``y``, the result in y[:, :nr]."""
        k, g, raw = plan.options, plan.grid, plan.raw
        nr = plan.output_shape[1]
        fs = raw.radar.range_sampling_rate_hz
        f0 = raw.radar.carrier_frequency_hz
        f_tau, f_eta, tau0 = prm["f_tau"], prm["f_eta"], prm["tau0"]
        out = y[:, :nr]
        # rows outside the processed band at every range are zero (as RD: their FFTs are skipped)
        active = prm["active"]
        out[~active] = 0.0
        edges = np.flatnonzero(np.diff(np.r_[0, active.astype(np.int8), 0]))
        chunks = [(c, min(bb, c + CHUNK)) for aa, bb in zip(edges[::2], edges[1::2], strict=True)
                  for c in range(aa, bb, CHUNK)]
        buffers: queue.SimpleQueue = queue.SimpleQueue()
        for _ in range(min(_n_threads(k.workers), max(1, len(chunks)))):
            buffers.put(np.empty((min(CHUNK, y.shape[0]), plan.n_fft_r), y.dtype))
        table = plan.stolt_table.astype(np.float32 if k.precision == "single" else np.float64)
        diff_table = table_for(DIFF_INTERPOLATOR)[1]

        def run(c: int, d: int) -> None:
            buf = buffers.get()
            try:
                row = buf[:d - c]
                stolt_rows(y[c:d], plan.h, f_tau, f_eta[c:d], float(plan.v_ref[b]), float(plan.r_ref[b]), tau0,
                           f0, fs, plan.stolt_kind, table, row)
                _fft_inplace(row, 1, True, 1)
                column_corrections(row, plan.f_bin[c:d], g.ranges, q["v"], float(plan.v_ref[b]), q["fdc"], q["dt"],
                                   q["ph0"], g.wavelength, g.prf, g.ba, plan.wtab, g.shift, f0, C / (2.0 * fs),
                                   diff_table, out[c:d])
            finally:
                buffers.put(buf)

        _pooled(chunks, run, k.workers)

    def finish(self, plan: OmegakPlan) -> SLC:
        slc = super().finish(plan)
        slc.parameters.update(reference_range_m=[float(r) for r in plan.r_ref],
                              reference_velocity_mps=[float(v) for v in plan.v_ref],
                              unwrap_centroid_hz=[float(f) for f in plan.fdc_ref])
        if plan.options.stolt == "monochromatic":
            # eq. (2) at the swath edges, the processed band's corners: the largest phase error predicted
            g, radar = plan.grid, plan.raw.radar
            half_b = 0.5 * plan.options.range_bandwidth_fraction * chirp_band(radar)
            err = [abs(float(monochromatic_phase_error(float(g.ranges[i]), float(r), fc + sa * 0.5 * g.ba,
                                                       sb * half_b, float(v), radar.carrier_frequency_hz)))
                   for r, v, fc in zip(plan.r_ref, plan.v_ref, plan.fdc_ref, strict=True)
                   for i in (0, -1) for sa in (-1.0, 1.0) for sb in (-1.0, 1.0)]
            slc.parameters["monochromatic_phase_error_max_rad"] = max(err)
        return slc


OMEGAK = Omegak()


def focus_omegak(raw: RawProduct, doppler, channel: int = 0, terrain: Terrain | None = None, **options) -> SLC:
    """Focus one receive channel of an in-memory raw product with omega-k (``options``: the fields of
    :class:`OmegakOptions`); as :func:`sarcli.focus.rda.focus_rd`."""
    from sarcli.focus.base import focus_in_memory
    from sarcli.model.terrain import ConstantHeight

    return focus_in_memory(OMEGAK, raw, doppler, options, terrain or ConstantHeight(0.0), channel)
