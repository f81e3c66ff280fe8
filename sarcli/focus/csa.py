"""Chirp scaling algorithm (CSA) [Raney1994; CumWong2005, ch. 7], on the RD focuser's grid and blocks.

Chirp scaling works on range-UNcompressed data in the range-Doppler domain and replaces RD's
RCMC interpolation by phase multiplies: the differential range cell migration of every target is
made equal to that of a reference range by a quadratic phase along range (the "chirp scaling"),
after which the remaining (bulk) migration is one linear phase in range frequency. Notation of
:mod:`sarcli.focus.kinematics` and :mod:`sarcli.focus.rangecomp` (tau two-way range time, f the
absolute azimuth frequency, K the signed chirp rate, f0 the carrier, phase ``exp(-j 4 pi R / lam)``),
D(f, V) = sqrt(1 - (lam f / 2V)^2).

Signal. A point at closest range R0, zero-Doppler time eta0, seen with effective velocity V, has in the
range-Doppler domain (azimuth FFT of the raw lines, stationary phase) [CumWong2005, eq. 7.17]

    S1(tau, f) = exp(j pi Km (tau - tau_t)^2) exp(-j 4 pi R0 D / lam) exp(-j 2 pi f eta0) exp(-j pi/4),
    tau_t(f) = 2 R0 / (c D(f, V)),     1 / Km(f, R0) = 1 / K - Z,   Z = c R0 f^2 / (2 V^2 f0^3 D^3):

the second-order expansion in range frequency f_tau of the exact 2-D phase
-(4 pi R0 / c) sqrt((f0 + f_tau)^2 - (c f / 2V)^2) - pi f_tau^2 / K gives the range-Doppler-domain
chirp rate Km, i.e. K with secondary range compression (Z = 1 / K_src of
:func:`sarcli.focus.rangecomp.inverse_src_rate`). The reference range R_ref (knob, default the middle
of the imaged closest ranges) fixes, per block, V_r = V(R_ref), f_ref = fdc(R_ref) and, per
azimuth-frequency row, the absolute f = f_ref + wrap(f_bin - f_ref) (one per row: the centroid may vary
across the swath by at most (PRF - Ba) / 2, checked), D = D(f, V_r), Km = Km(f, R_ref); the migration
every target is scaled to, D_ref = D(fdc, V) at R_ref and the scene centre, is the plan's (a block's
own would put the range read of step 3 at block-dependent fractions of a sample: 0.56 sample for 50 Hz
of centroid at 3.4 PRF, 0.25 % of amplitude between block sizes with the 8-tap read).

1. Chirp scaling [CumWong2005, eq. 7.30]: x exp(j pi Km a (tau - tau_r)^2), a = D_ref / D - 1 (a few
   1e-4 across Radarsat-1's band, a few per cent at 40 degrees airborne),
   tau_r = 2 R_ref / (c D). Completing the square, S1 becomes a chirp of rate K' = Km (1 + a)
   centred at tau_s = tau_r + (tau_t - tau_r) / (1 + a), times exp(j theta), theta = pi Km a / (1 + a)
   (tau_t - tau_r)^2: every target now migrates like the reference, tau_s - tau_r = 2 (R0 - R_ref) /
   (c D_ref) in every row.
2. Range FFT (length L) and, in the 2-D frequency domain, range compression of the scaled chirp
   (stationary phase: exp(+j pi f_tau^2 / K') exp(-j (pi/4) sgn K), amplitude 1 / (T sqrt|K'|), so
   a unit chirp compresses to about 1 as in RD), the range window over the scaled band
   (1 + a) x range_bandwidth_fraction x |K| T, and bulk RCMC exp(+j 2 pi f_tau Delta_b),
   Delta_b = (2 R_ref / c)(1 / D - 1 / D_ref) [CumWong2005, eq. 7.32]; zero padding to
   ``range_oversample`` x L and range IFFT. The target is compressed in every row at
   rho = R0 D(f, V_r) / (D(f, V) D_ref) (tau_s - Delta_b in range): at R0 / D_ref when V = V_r.
3. Per output column i (closest range R0_i on the raw range grid, V_i, fdc_i, orbit-timing dt_i,
   ph0_i of the block's model, exactly as RD): the range position rho_i at f = fdc_i is read by
   ``interpolator`` (one position per column, the same in every row: a range stretch by 1 / D_ref
   about zero range, the price of RD's output grid; exact at broadside, where rho_i = R0_i), times the
   azimuth window W((f - fdc_i) / Ba), the azimuth matched filter and the residual phase
   exp(j 4 pi R0_i (D(f, V_i) - 1) / lam + j pi/4 - j theta(f, R0_i)) [CumWong2005, eq. 7.34], and RD's
   shift, dt and ph0 terms (:mod:`sarcli.focus.rcmc`): the peak has phase -4 pi R0 / lam.
4. Azimuth IFFT; per-line corrections from the block's model to each line's
   (:meth:`sarcli.focus.rda.RangeDoppler.line_corrections`): the image does not depend on the block
   size, as RD's.

What is approximated, and when it matters (measured in tests/focus/test_csa.py):

- Km at R_ref (the range dependence of SRC; RD applies SRC at mid-swath, the same error): a quadratic
  phase pi (B/2)^2 |Z(R0) - Z(R_ref)| at the band edge; Z / (1/K) is 1e-3 for Radarsat-1 but several
  per cent for an airborne squint of 40 degrees, where targets a few hundred metres from R_ref defocus.
- The cubic and higher terms of the range-frequency expansion (as RD): (2 pi R0 / c)(1 - D^2) f_tau^3 /
  (f0^2 D^5), 0.09 rad at the band edge for X band, 40 degrees, 2 km, 100 MHz: below the quality bar.
- The range spectrum of a target at tau_t - tau_r is shifted by Km a (tau_t - tau_r): a is a few per
  cent at most across the processed band (it is zero at f_ref), so this costs resolution only far from
  R_ref at high squint.
- V_r for the differential migration: a target of velocity V != V_r keeps the residual migration
  R0 (1 / D(f, V) - 1 / D(f, V_r)) - its value at fdc (corrected by rho_i); 0.01 sample for Radarsat-1.

Measured (bench/bench_csa.py, docs/focusing.md): spaceborne point targets at 0, 3.4 and 6 PRF of
centroid meet RD's bars (IRW within 0.5 % of window theory, PSLR 0.3 dB, position 0.01 pixel, phase
0.02 rad); airborne 40 degrees, X / C band: phase against exact backprojection -0.025 / -0.053 rad
(RD -0.39 / -0.64, and csa with R_ref moved to mid-swath -0.37 / -0.63: the difference is the
reference range of Km); the 1536 x 2048 Radarsat-1 block in 1.3x RD's time.

Extended CSA. The extended chirp scaling of [Moreira1996] adds an azimuth scaling (ScanSAR and
spotlight output grids without interpolation) and range-dependent motion-compensation phases for
airborne data with track deviations; nonlinear chirp scaling [Davidson1996] handles the range
dependence of Km (wide swaths at high squint). sarcli's airborne case is the linear track without
motion errors (the hyperbolic model is exact there) and its output grid is RD's zero-Doppler grid, so
neither is needed for these geometries; the bar they would lift is the Km-at-R_ref one above.

Linear FM only. Chirp scaling needs the pulse to be the linear FM chirp of rate K (the scaling and
the compression are stationary-phase expressions of it). The product's replica is not used for
compression; it is compared with the nominal chirp (:func:`replica_deviation`: phase rms after a
constant and a linear term, relative amplitude rms) and a warning says when it deviates by more than
``REPLICA_TOLERANCE_RAD`` (about 1 % of peak power lost in the matched filter, sigma^2).
"""

from __future__ import annotations

import math
import queue
import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.fft as sfft
from numba import njit

from sarcli.errors import ConfigError, SarcliError
from sarcli.focus.interp import parse_interpolator, table_for
from sarcli.focus.rangecomp import C, chirp_band, inverse_src_rate, reference_pulse
from sarcli.focus.rda import (
    CHUNK,
    RANGE_GUARD,
    SHIFT_INTERPOLATOR,
    ModelGrid,
    OutputGrid,
    RangeDoppler,
    _add,
    _coverage_warnings,
    _fft_inplace,
    _n_threads,
    _pooled,
    check_block_knobs,
    model_grid,
    plan_grid,
    smooth_len,
)
from sarcli.focus.windows import table_lookup, window_table
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC
from sarcli.model.terrain import ConstantHeight, Terrain

REPLICA_TOLERANCE_RAD = 0.1  # rms phase deviation of the replica from the nominal chirp that warns


@dataclass(frozen=True)
class CsaOptions:
    """Processing knobs of the CSA (the same names as :class:`sarcli.focus.rda.RdOptions` where they
    mean the same).

    range_window, azimuth_window: window specs (:mod:`sarcli.focus.windows`); range_bandwidth_fraction:
    processed part of the chirp band; azimuth_bandwidth_hz: processed Doppler band (default 0.8 PRF);
    src: secondary range compression in Km (module docstring); reference_range_m: R_ref, where the Km
    and migration approximations are exact (default: the middle of the closest ranges the raw window
    images, (r_first + r_last cos(theta)) / 2 with the largest squint of the model); interpolator: the per-column range
    read of step 3 (nearest, linear, sinc4/8/16); range_oversample: 1 or 2, Fourier upsampling before it
    (as RD's rcmc_oversample); precision: "single" (complex64) or "double"; block_lines: azimuth FFT
    length per block (memory; the image does not depend on it); orbit_timing: exact zero-Doppler timing
    with an Earth orbit (:func:`sarcli.focus.rda.orbit_time_correction`); workers: threads; device: cpu, or
    cuda (steps 1-4 on the GPU, :mod:`sarcli.gpu.csa_xp`).
    """

    range_window: str = "kaiser:2.5"
    range_bandwidth_fraction: float = 1.0
    azimuth_window: str = "kaiser:2.5"
    azimuth_bandwidth_hz: float | None = None
    src: bool = True
    reference_range_m: float | None = None
    interpolator: str = "sinc8"
    range_oversample: int = 2
    precision: Literal["single", "double"] = "single"
    block_lines: int = 4096
    orbit_timing: bool = True
    workers: int = -1
    device: Literal["cpu", "cuda"] = "cpu"

    def __post_init__(self) -> None:
        check_block_knobs(self)
        parse_interpolator(self.interpolator)
        if self.range_oversample not in (1, 2):
            raise ConfigError(f"range_oversample must be 1 or 2, got {self.range_oversample}")
        if self.reference_range_m is not None and not (math.isfinite(self.reference_range_m)
                                                       and self.reference_range_m > 0):
            raise ConfigError(f"reference_range_m must be a positive number of metres, got {self.reference_range_m}")


def replica_deviation(radar, replica: np.ndarray | None) -> dict[str, float] | None:
    """How far the product's replica is from the nominal linear FM chirp (None without a replica).

    Over the pulse (:func:`sarcli.focus.rangecomp.reference_pulse`), the phase of replica x conj(nominal)
    with its best constant and linear terms removed (a delay and a carrier offset do not matter to
    chirp scaling), weighted by the replica's power: ``phase_rms_rad``; ``amplitude_rms``: relative rms
    of |replica| about its mean; ``loss_db``: the matched filter's peak loss of the nominal chirp on the
    replica, 10 log10 |<r, n>|^2 / (|r|^2 |n|^2) after the fitted terms.
    """
    if replica is None or np.size(replica) <= 1:
        return None
    rep = reference_pulse(radar, replica)
    nom = reference_pulse(radar, None)
    n = min(rep.size, nom.size)
    rep, nom = rep[:n], nom[:n]
    w = np.abs(rep) ** 2
    ph = np.unwrap(np.angle(rep * np.conj(nom)))
    x = np.arange(n) - 0.5 * (n - 1)
    coef = np.polyfit(x, ph, 1, w=np.sqrt(w))
    res = ph - np.polyval(coef, x)
    res -= np.sum(w * res) / np.sum(w)
    amp = np.abs(rep)
    corr = np.abs(np.sum(amp * np.exp(1j * res))) ** 2 / (np.sum(amp**2) * n)
    return {"phase_rms_rad": float(np.sqrt(np.sum(w * res**2) / np.sum(w))),
            "amplitude_rms": float(np.std(amp) / np.mean(amp)), "loss_db": float(10.0 * np.log10(corr))}


@dataclass
class CsaPlan:
    """Everything the CSA blocks share (:meth:`ChirpScaling.plan`); the attributes RD's per-line
    corrections read (raw, grid, model, block_time, block, block_rows) have RD's meaning."""

    raw: RawProduct
    options: CsaOptions
    terrain: Terrain
    grid: OutputGrid
    model: ModelGrid
    output_shape: tuple[int, int]
    n_blocks: int
    n_valid: int
    n_fft_az: int
    n_fft_r: int
    r_ref: float
    c_ref: float
    d_ref: float
    wtab_r: np.ndarray
    wtab_a: np.ndarray
    table: np.ndarray
    f_bin: np.ndarray
    shift_table: np.ndarray
    gain: np.ndarray | None
    block_time: np.ndarray
    block: list[dict[str, np.ndarray]]
    warnings: list[str]
    replica: dict[str, float] | None
    scaling_max: float
    timings: dict[str, float] = field(default_factory=dict)

    def block_rows(self, b: int) -> tuple[int, int]:
        s = b * self.n_valid
        return s, min(s + self.n_valid, self.output_shape[0])


def _d(f, v, wavelength):
    return np.sqrt(1.0 - (wavelength * f / (2.0 * v)) ** 2)


def row_parameters(f_bin: np.ndarray, prf: float, fdc_ref: float, v_ref: float, r_ref: float, d_ref: float, radar,
                   src: bool) -> dict[str, np.ndarray]:
    """Per azimuth-frequency row of the block: absolute f (Hz, wrapped around the block's fdc_ref), D,
    D_ref (given: the plan's), Km (Hz/s), scaling a, tau_r (s) and the bulk shift Delta_b (s) of the
    module docstring."""
    lam = C / radar.carrier_frequency_hz
    off = f_bin - fdc_ref
    f = fdc_ref + off - prf * np.floor(off / prf + 0.5)
    d = _d(f, v_ref, lam)
    z = inverse_src_rate(f, r_ref, v_ref, radar.carrier_frequency_hz) if src else np.zeros_like(f)
    km = 1.0 / (1.0 / radar.chirp_rate_hz_per_s - z)
    a = d_ref / d - 1.0
    return {"f": f, "d": d, "d_ref": np.full_like(f, d_ref), "km": km, "a": a, "tau_r": 2.0 * r_ref / (C * d),
            "delta_b": 2.0 * r_ref / C * (1.0 / d - 1.0 / d_ref)}


def column_positions(r0: np.ndarray, fdc: np.ndarray, v: np.ndarray, v_ref: float, d_ref: float,
                     wavelength: float) -> np.ndarray:
    """rho_i (m): where step 2 compresses the target of closest range R0_i (velocity V_i) in the row of
    its centroid: R0 D(fdc, V_r) / (D(fdc, V_i) D_ref)."""
    return r0 * _d(fdc, v_ref, wavelength) / (_d(fdc, v, wavelength) * d_ref)


SEGMENT = 64  # samples per exactly restarted phasor recurrence (drift below 1e-12 rad, as rangecomp)
SPAN = 32  # columns of the azimuth kernel between exact phases (the model grid's GRID_SAMPLES)
SPAN_TOL_RAD = 1e-3  # largest curvature error of the linear phase over a span; rows above: exact


@njit(nogil=True, cache=True, fastmath=True)
def chirp_scale(x, nr, q2, tau_r, tau0, dtau):
    """x[k, m] *= exp(j q2[k] (tau0 + m dtau - tau_r[k])^2) for m < nr, in place (q2 = pi Km a).

    The phase is quadratic in m: a second-order phasor recurrence (two complex multiplies a sample),
    restarted exactly every SEGMENT samples."""
    for k in range(x.shape[0]):
        if q2[k] == 0.0:
            continue
        m = 0
        while m < nr:
            e = min(nr, m + SEGMENT)
            u = tau0 + m * dtau - tau_r[k]
            ph = q2[k] * u * u
            cur = complex(np.cos(ph), np.sin(ph))
            d1 = q2[k] * (2.0 * u * dtau + dtau * dtau)
            step = complex(np.cos(d1), np.sin(d1))
            d2 = 2.0 * q2[k] * dtau * dtau
            curv = complex(np.cos(d2), np.sin(d2))
            for q in range(m, e):
                x[k, q] *= cur
                cur *= step
                step *= curv
            m = e


@njit(nogil=True, cache=True, fastmath=True)
def csa_range_filter(x, f_tau, inv_band, c2, c1, c0, gain, wtab, out):
    """out[k, j(m)] = x[k, m] W(f_tau[m] inv_band[k]) gain[k] exp(j (c2[k] f^2 + c1[k] f + c0)),
    f = f_tau[m], with the zero-padding layout of :func:`sarcli.focus.rangecomp.apply_range_filter_2d`
    (out has n_out >= n_f columns, the negative half moved to the end, the gap zeroed). The phase is
    quadratic in m on each half of the FFT axis: a phasor recurrence restarted every SEGMENT samples."""
    na, nf = x.shape
    half = (nf + 1) // 2
    gap = out.shape[1] - nf
    for k in range(na):
        for q in range(half, half + gap):
            out[k, q] = 0.0
        m = 0
        while m < nf:
            e = min(nf, m + SEGMENT)
            if m < half < e:
                e = half  # the frequency axis jumps from +fs/2 to -fs/2 there
            f = f_tau[m]
            ph = (c2[k] * f + c1[k]) * f + c0
            cur = complex(np.cos(ph), np.sin(ph))
            df = f_tau[m + 1] - f if m + 1 < nf else 0.0
            d1 = c2[k] * (2.0 * f * df + df * df) + c1[k] * df
            step = complex(np.cos(d1), np.sin(d1))
            d2 = 2.0 * c2[k] * df * df
            curv = complex(np.cos(d2), np.sin(d2))
            for q in range(m, e):
                j = q if q < half else q + gap
                u = f_tau[q] * inv_band[k]
                if u < -0.5 or u > 0.5:
                    out[k, j] = 0.0
                else:
                    out[k, j] = x[k, q] * (table_lookup(wtab, u) * gain[k] * cur)
                cur *= step
                step *= curv
            m = e


@njit(inline="always", fastmath=True)
def _azimuth_phase(i, f, psh, g, tau_k, r0, v, dt, ph0, wavelength):
    """Phase of output column i in the row of absolute frequency f (see :func:`csa_azimuth`)."""
    x = (wavelength * f / (2.0 * v[i])) ** 2
    d = np.sqrt(1.0 - x)
    dm1 = -x / (1.0 + d)
    e = 2.0 * r0[i] / (299792458.0 * d) - tau_k
    return 4.0 * np.pi * r0[i] * dm1 / wavelength + psh - 2.0 * np.pi * f * dt[i] + ph0[i] - g * e * e


@njit(nogil=True, cache=True, fastmath=True)
def csa_azimuth(up, f_row, f_bin, pos, r0, v, fdc, dt, ph0, km, a, tau_r, wavelength, prf, ba, shift, wtab,
                kind, table, out):
    """Per row k and output column i: the range-compressed row ``up`` read at ``pos[i]`` (samples of
    ``up``: nearest, linear or the windowed-sinc ``table``), times the azimuth window
    W((f - fdc_i) / Ba), exp(j 4 pi R0_i (D(f, V_i) - 1) / lam + j pi/4 - j theta) and RD's shift, dt and
    ph0 terms; theta = pi Km a / (1 + a) (2 R0_i / (c D(f, V_i)) - tau_r)^2, f = f_row[k]. Writes
    out[k, i] (float64 geometry and phase).

    Speed: the phase is exact every SPAN columns and advanced by a fixed rotation in between (as
    :func:`sarcli.focus.rcmc.rcmc_azimuth`); the residual theta is quadratic in R0, so a row whose
    curvature error over a span, |theta''| SPAN^2 / 8 with theta'' = 2 |g| (2 dr / (c D))^2, exceeds
    SPAN_TOL_RAD (airborne high squint) is computed column by column. The azimuth filter's own curvature
    (V_i, dt_i and ph0_i are linear between the model grid's columns) is RD's."""
    na = up.shape[0]
    nrow = up.shape[1]
    nout = r0.shape[0]
    nph = table.shape[0] - 1
    taps = table.shape[1]
    k0 = taps // 2 - 1
    zero = np.zeros(1, up.dtype)[0]
    dr = (r0[nout - 1] - r0[0]) / max(nout - 1, 1)
    for k in range(na):
        f = f_row[k]
        psh = -2.0 * np.pi * f_bin[k] * shift / prf + 0.25 * np.pi
        g = np.pi * km[k] * a[k] / (1.0 + a[k])
        dmin = np.sqrt(1.0 - (wavelength * f / (2.0 * v[0])) ** 2)
        curv = 2.0 * abs(g) * (2.0 * dr / (299792458.0 * dmin)) ** 2 * SPAN * SPAN / 8.0
        exact = curv > SPAN_TOL_RAD
        i0 = 0
        while i0 < nout:
            i1 = min(i0 + SPAN, nout - 1)
            n = i1 - i0
            stop = i1 if i1 < nout - 1 else nout
            cur = complex(1.0, 0.0)
            rot = complex(1.0, 0.0)
            if not exact and n > 0:
                q0 = _azimuth_phase(i0, f, psh, g, tau_r[k], r0, v, dt, ph0, wavelength)
                q1 = _azimuth_phase(i1, f, psh, g, tau_r[k], r0, v, dt, ph0, wavelength)
                cur = complex(np.cos(q0), np.sin(q0))
                rot = complex(np.cos((q1 - q0) / n), np.sin((q1 - q0) / n))
            for i in range(i0, stop):
                if exact or n == 0:
                    q = _azimuth_phase(i, f, psh, g, tau_r[k], r0, v, dt, ph0, wavelength)
                    ph_c = complex(np.cos(q), np.sin(q))
                else:
                    ph_c = cur
                    cur *= rot
                u = (f - fdc[i]) / ba
                if u < -0.5 or u > 0.5:
                    out[k, i] = 0.0
                    continue
                p = pos[i]
                val = zero
                if kind == 2:
                    j = int(np.floor(p))
                    jp = int((p - j) * nph + 0.5)
                    b = j - k0
                    if b >= 0 and b + taps <= nrow:
                        for t in range(taps):
                            val += up[k, b + t] * table[jp, t]
                    else:
                        for t in range(taps):
                            if 0 <= b + t < nrow:
                                val += up[k, b + t] * table[jp, t]
                elif kind == 1:
                    j = int(np.floor(p))
                    mu = p - j
                    if 0 <= j < nrow:
                        val += up[k, j] * (1.0 - mu)
                    if 0 <= j + 1 < nrow:
                        val += up[k, j + 1] * mu
                else:
                    j = int(np.floor(p + 0.5))
                    if 0 <= j < nrow:
                        val = up[k, j]
                out[k, i] = val * (table_lookup(wtab, u) * ph_c)
            i0 = stop


def block_parameters(plan: CsaPlan, b: int) -> dict[str, Any]:
    """What steps 1-4 of block ``b`` need besides the echo, computed on the host (float64), for the CPU
    and the GPU path alike: ``rows`` (:func:`row_parameters` at the reference column), ``pos`` (each
    column's read position in upsampled samples), the chirp-scaling phase q2 = pi Km a, the range filter's
    phase coefficients c2, c1, c0, band and gain per row, ``f_tau`` (range FFT frequencies), ``tau0``,
    ``dtau`` (s) and ``active`` (rows inside the processed band at some column)."""
    k, g, radar = plan.options, plan.grid, plan.raw.radar
    nr = plan.output_shape[1]
    q = plan.block[b]
    cols = np.arange(nr)
    fdc_r, v_r = (float(np.interp(plan.c_ref, cols, q[n])) for n in ("fdc", "v"))
    rp = row_parameters(plan.f_bin, g.prf, fdc_r, v_r, plan.r_ref, plan.d_ref, radar, k.src)
    pos = column_positions(g.ranges, q["fdc"], q["v"], v_r, plan.d_ref, g.wavelength)
    factor = k.range_oversample
    dr = float(g.ranges[1] - g.ranges[0])
    k2 = rp["km"] * (1.0 + rp["a"])
    # rows outside the processed band at every column are zero: skipped
    offs = rp["f"][:, None] - q["fdc"][None, ::16]
    return {"rows": rp, "pos": (pos - float(g.ranges[0])) / dr * factor,
            "inv_band": 1.0 / (chirp_band(radar) * k.range_bandwidth_fraction * (1.0 + rp["a"])),
            # 1 / (T sqrt|K'|): a unit chirp compresses to ~1 (module docstring); x factor: the IFFT of the
            # zero-padded spectrum divides by factor x L
            "gain": factor / (radar.pulse_length_s * np.sqrt(np.abs(k2))),
            "f_tau": sfft.fftfreq(plan.n_fft_r, 1.0 / radar.range_sampling_rate_hz),
            "tau0": 2.0 * float(g.ranges[0]) / C, "dtau": 1.0 / radar.range_sampling_rate_hz,
            "active": np.any(np.abs(offs) <= 0.5 * g.ba * (1.0 + 1e-9), axis=1),
            "q2": np.pi * rp["km"] * rp["a"], "c2": np.pi / k2, "c1": 2.0 * np.pi * rp["delta_b"],
            "c0": -0.25 * np.pi * np.sign(radar.chirp_rate_hz_per_s)}


class ChirpScaling(RangeDoppler):
    """The CSA as a focuser (:mod:`sarcli.focus.base`): ``sarcli focus --algorithm csa``. It shares RD's
    output grid, model grid and per-line corrections (:meth:`RangeDoppler.line_corrections`)."""

    name = "csa"
    azimuth_compression = "frequency"  # its processing gain (sarcli.calibration.radiometry)
    Options = CsaOptions  # type: ignore[assignment]  # a focuser's own knobs (base.Focuser.Options: type)
    streams = True
    needs_doppler = True

    def plan(self, raw: RawProduct, shape: tuple[int, int], doppler, options: CsaOptions,  # type: ignore[override]
             terrain: Terrain) -> CsaPlan:
        k = options
        n_lines, nr = shape
        if n_lines < 2:
            raise SarcliError("the scene has fewer than two azimuth lines: nothing to focus")
        if nr < 2:
            raise SarcliError("the scene has fewer than two range samples: nothing to focus")
        t0 = time.perf_counter()
        radar = raw.radar
        grid = plan_grid(raw, shape, doppler, k.azimuth_bandwidth_hz)
        pad = grid.pad
        n_fft_az = smooth_len(max(k.block_lines, 4 * pad) if n_lines + 2 * pad > k.block_lines
                              else n_lines + 2 * pad)
        n_valid = min(n_lines, n_fft_az - 2 * pad)
        model = model_grid(raw, doppler, grid, k.orbit_timing, terrain)
        if k.reference_range_m is None:
            # the middle of the closest ranges the raw window images: [r_first, r_last cos(theta)]
            s_mid = float(np.max(np.abs(model.s)))
            r_ref = 0.5 * (float(grid.ranges[0]) + float(grid.ranges[-1]) * math.sqrt(1.0 - s_mid * s_mid))
        else:
            r_ref = float(k.reference_range_m)
        dr = float(grid.ranges[1] - grid.ranges[0])
        c_ref = (r_ref - float(grid.ranges[0])) / dr
        if not 0.0 <= c_ref <= nr - 1:
            raise ConfigError(f"reference_range_m {r_ref:.6g} m is outside the swath "
                              f"{grid.ranges[0]:.6g}-{grid.ranges[-1]:.6g} m")
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
        # one absolute azimuth frequency per row: every column's band must lie within PRF/2 of f_ref
        spread = max(float(np.max(np.abs(q["fdc"] - np.interp(c_ref, np.arange(nr), q["fdc"])))) for q in blocks)
        if spread > 0.5 * (grid.prf - grid.ba) + 1e-9 * grid.prf:
            raise SarcliError(f"the Doppler centroid varies by {spread:.4g} Hz across the swath, more than "
                              f"(PRF - Ba)/2 = {0.5 * (grid.prf - grid.ba):.4g} Hz: chirp scaling needs one absolute"
                              " azimuth frequency per row; lower azimuth_bandwidth_hz or use --algorithm rd")
        # the scaled band (1 + a) B over the processed Doppler band, and on the output grid B / D(f)
        b_r = chirp_band(radar) * k.range_bandwidth_fraction
        lam = grid.wavelength
        smax, shift_max, band_max = 0.0, 0.0, 0.0
        # D_ref, the migration every target is scaled to, is the plan's (the scene-centre model at R_ref):
        # with a block's own, the range read of step 3 would sit at block-dependent fractions of a sample
        q_mid = model.at_columns(0.5 * (float(t_raw[0]) + float(t_raw[-1])), nr)
        d_ref = float(_d(*(float(np.interp(c_ref, np.arange(nr), q_mid[n])) for n in ("fdc", "v")), lam))
        for q in blocks:
            fdc_r, v_r = (float(np.interp(c_ref, np.arange(nr), q[n])) for n in ("fdc", "v"))
            f = fdc_r + np.linspace(-0.5, 0.5, 65) * grid.ba
            a = d_ref / _d(f, v_r, lam) - 1.0
            smax = max(smax, float(np.max(np.abs(a))))
            band_max = max(band_max, float(np.max(b_r / _d(f, v_r, lam))))
            # content moves by rho (D(f)/D_ref - 1) (step 2) and by the per-column read (step 3)
            ends = np.array([grid.ranges[0], grid.ranges[-1] + C * radar.pulse_length_s / 2])
            shift_max = max(shift_max, float(np.max(np.abs(ends[:, None] * (1.0 / (1.0 + a[None, :]) - 1.0)))) / dr)
        if band_max > radar.range_sampling_rate_hz:
            msgs.append(f"the processed range band on the zero-Doppler grid, B / D(f) = {band_max / 1e6:.4g} MHz,"
                        f" exceeds the sampling rate {radar.range_sampling_rate_hz / 1e6:.4g} MHz: range aliasing")
        replica = replica_deviation(radar, raw.replica)
        if replica is not None and replica["phase_rms_rad"] > REPLICA_TOLERANCE_RAD:
            msgs.append(f"the chirp replica deviates from a linear FM chirp by {replica['phase_rms_rad']:.3g} rad rms"
                        f" ({replica['loss_db']:.2g} dB of matched-filter loss): chirp scaling compresses with the"
                        " nominal chirp; use --algorithm rd to compress with the replica")
        for m in msgs:
            warnings.warn(m, stacklevel=2)
        n_ref = reference_pulse(radar, None).size
        n_fft_r = smooth_len(nr + n_ref + 2 * int(math.ceil(shift_max)) + RANGE_GUARD)
        rdt = np.float32 if k.precision == "single" else np.float64
        return CsaPlan(raw=raw, options=k, terrain=terrain, grid=grid, model=model, output_shape=(n_lines, nr),
                       n_blocks=n_blocks, n_valid=n_valid, n_fft_az=n_fft_az, n_fft_r=n_fft_r, r_ref=r_ref,
                       c_ref=c_ref, d_ref=d_ref, wtab_r=window_table(k.range_window),
                       wtab_a=window_table(k.azimuth_window),
                       table=table_for(k.interpolator)[1].astype(rdt), f_bin=sfft.fftfreq(n_fft_az, 1.0 / grid.prf),
                       shift_table=table_for(SHIFT_INTERPOLATOR)[1].astype(rdt), gain=raw.line_gain(),
                       block_time=block_time, block=blocks, warnings=msgs, replica=replica, scaling_max=smax,
                       timings={"plan_s": time.perf_counter() - t0})

    block_parameters = staticmethod(block_parameters)  # type: ignore[assignment]  # the host parameters
    gpu_block = "csa_xp"

    def _focus_rows(self, plan: CsaPlan, b: int, data: np.ndarray, off: int,  # type: ignore[override]
                    gain: np.ndarray | None, prm: dict[str, Any]) -> np.ndarray:
        """Steps 1-4 of the module docstring on the CPU: the block's (N x n_samples) azimuth-compressed lines,
        raw lines ``data`` (times ``gain`` per line) at row ``off``."""
        k, g = plan.options, plan.grid
        nr = plan.output_shape[1]
        tm = plan.timings
        t0 = time.perf_counter()
        cdt = np.complex64 if k.precision == "single" else np.complex128
        y = np.zeros((plan.n_fft_az, plan.n_fft_r), cdt)
        y[off:off + data.shape[0], :nr] = data
        if gain is not None:
            y[off:off + data.shape[0], :nr] *= gain[:, None]
        _fft_inplace(y[:, :nr], 0, False, k.workers)
        _add(tm, "azimuth_fft_s", t0)
        t0 = time.perf_counter()
        q, rp = plan.block[b], prm["rows"]
        factor = k.range_oversample
        out = y[:, :nr]
        active = prm["active"]
        out[~active] = 0.0
        edges = np.flatnonzero(np.diff(np.r_[0, active.astype(np.int8), 0]))
        chunks = [(c, min(bb, c + CHUNK)) for aa, bb in zip(edges[::2], edges[1::2], strict=True)
                  for c in range(aa, bb, CHUNK)]
        n_threads = min(_n_threads(k.workers), max(1, len(chunks)))
        buffers: queue.SimpleQueue = queue.SimpleQueue()
        for _ in range(n_threads):
            buffers.put(np.empty((min(CHUNK, y.shape[0]), factor * plan.n_fft_r), cdt))

        def run(c: int, d: int) -> None:
            buf = buffers.get()
            try:
                rows = y[c:d]
                chirp_scale(rows, nr, prm["q2"][c:d], rp["tau_r"][c:d], prm["tau0"], prm["dtau"])
                _fft_inplace(rows, 1, False, 1)
                up = buf[:d - c]
                csa_range_filter(rows, prm["f_tau"], prm["inv_band"][c:d], prm["c2"][c:d], prm["c1"][c:d],
                                 prm["c0"], prm["gain"][c:d], plan.wtab_r, up)
                _fft_inplace(up, 1, True, 1)
                csa_azimuth(up, rp["f"][c:d], plan.f_bin[c:d], prm["pos"], g.ranges, q["v"], q["fdc"], q["dt"],
                            q["ph0"], rp["km"][c:d], rp["a"][c:d], rp["tau_r"][c:d], g.wavelength, g.prf, g.ba,
                            g.shift, plan.wtab_a, parse_interpolator(k.interpolator)[0], plan.table, out[c:d])
            finally:
                buffers.put(buf)

        _pooled(chunks, run, k.workers)
        _add(tm, "scaling_compression_azimuth_s", t0)
        img = y[:, :nr]
        t0 = time.perf_counter()
        _fft_inplace(img, 0, True, k.workers)
        _add(tm, "azimuth_ifft_s", t0)
        return img

    def own_parameters(self, plan: CsaPlan) -> dict[str, Any]:  # type: ignore[override]
        return {"reference_range_used_m": plan.r_ref, "chirp_scaling_max": plan.scaling_max,
                "replica_deviation": plan.replica}


CSA = ChirpScaling()


def focus_csa(raw: RawProduct, doppler, channel: int = 0, terrain: Terrain | None = None, **options: Any) -> SLC:
    """Focus one receive channel of an in-memory raw product with the CSA (``options``: the fields of
    :class:`CsaOptions`); the SLC has RD's grid (zero-Doppler times, slant ranges)."""
    from sarcli.focus.base import focus_in_memory

    return focus_in_memory(CSA, raw, doppler, options, terrain or ConstantHeight(0.0), channel)
