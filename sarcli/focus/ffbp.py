"""Fast factorized backprojection (FFBP) [UlaHelSte2003] onto any 2-D grid of 3-D pixels, from any track.

**What it computes.** The exact backprojection (:mod:`sarcli.focus.backprojection`,
:mod:`sarcli.gbsar.backprojection`) of range-compressed lines ``line_n`` (baseband, sampled on the
relative ranges ``r_first + i dr``; line n references the range ``ref_n``, 0 for raw slant ranges) from
antenna positions ``p_n`` onto pixels X is

    I(X) = sum_n W_n(X) w_n line_n(rho_n) exp(+j k (rho_n - R_out(X))),   rho_n = |X - p_n| - ref_n,

k = 4 pi / lam (centre wavelength), w_n a per-pulse weight (taper, validity), W_n(X) a pixel-dependent
aperture window (stripmap: the window over the processed Doppler band; GB-SAR: the taper over the beam
footprint; otherwise 1) and R_out(X) the output phase reference (stripmap and GB-SAR slant images: the
pixel's range R0, phase -4 pi R0/lam at a scatterer; imported phase histories: 0, the reflectivity).
It costs O(pixels x pulses).

**Subaperture images on local polar grids.** Split the pulses into consecutive subapertures s of
length L_s (centre c_s = midpoint of its end pulses, unit chord d_s). A point Y has polar coordinates
r = |Y - c_s| and u = d_s . (Y - c_s) / r (the cosine of the angle to the chord: the sine of the squint).
The subaperture image, in the *residual-range* convention,

    I_s(Y) = sum_{n in s} w_n line_n(rho_n(Y)) exp(+j k (rho_n(Y) - r_s(Y))),

is smooth in (r, u): a scatterer at Y_t gives line_n = a env(rho_n - rho_tn) exp(-j k rho_tn), so
I_s(Y) = a sum_n env exp(j k (R_n(Y) - R_tn)) exp(-j k r_s(Y)); with R_n ~ r - s_n u + s_n^2 (1 - u^2)/(2 r)
(s_n the pulse's offset along the chord) the carrier exp(j k r) of the first factor cancels the second:
in r the image is baseband (the range envelope, bandwidth B as the lines), in u it is a sum of
exp(-j 2 pi (2 f s_n / c) u) over the band's frequencies f <= f_max and |s_n| <= L_s/2.

**Angular Nyquist.** Its spectrum in u lies within |nu| <= 2 f_max (L_s/2) / c = L_s / lam_min (cycles per
unit of u), so the polar grid needs

    du <= lam_min / (2 L_s)      (d(sin squint) <= lam_min / (2 L_s)),

and FFBP samples at ``du = lam_min / (2 beta L_s)``, beta the angular *oversampling* (``oversample``;
L_s is taken as twice the largest |p_n - c_s|, which also bounds the off-chord track terms). Ranges are
sampled at c / (2 B U), U the range oversampling (``range_oversample``), and no finer than the lines'
own (upsampled) ``dr``. Doubling L_s halves du while the number of subapertures
halves: every stage holds about the same number of polar samples, which is the O(N^2 log N) of
[UlaHelSte2003].

**Stages.** Stage 0 backprojects the pulses of each subaperture of ``base`` pulses onto its polar grid
exactly as the exact kernels do (linear interpolation of the line at rho_n). Each merge stage builds a
subaperture of ``base`` children: for every polar sample Y of the parent, the children's images are
interpolated at their own (r_c, u_c) of Y (a kernel of ``order`` taps in u and ``range_order`` taps
in r, below) and re-referenced, ``I_p(Y) = sum_c I_c(Y) exp(+j k (r_c(Y) - r_p(Y)))``
(exact: the phase of the residual convention, no far-field step). The last stage evaluates the top
subapertures at the pixels, ``I(X) = sum_s Wbar_s(X) I_s(X) exp(+j k (r_s(X) - R_out(X)))``, so as the
knobs tighten FFBP tends to the exact backprojection. Stage 0 and the merges compute a polar row (fixed u)
per task, the last stage a chunk of pixels per task; the phasors of a row or chunk are formed in one
branch-free pass that the compiler vectorizes (:func:`sarcli.focus.phasor.cis`, 1.5 ns a phasor against
10 ns one at a time), and no task's result depends on the others, so the image is the same for any
number of threads.

**The along-ray merge.** A parent row (fixed u, ranges r_i = r0 + i dr) crosses a child's polar grid along a
curve (r_c(r_i), u_c(r_i)). Interpolating it in 2-D at each sample costs ``order`` x ``range_order`` taps per
child; where the curve is *separable* the merge costs ``order + range_order`` instead, in two 1-D passes:
(i) at each child range column j that the row needs, the child is interpolated in angle at the angle
u_c(r_j) where the curve crosses that column (from the row's nearest sample below r_j along the row's mean
slope du_c/dr_c: error at most dr |du_c/dr_c - its mean| <= dr L_row max|u_c''|, L_row the row's length; for
a straight track |u_c''| ~ |s| / r^3 with s the child's offset along the chord: below 1e-9 angle samples for
the geometries here); (ii) that column sequence A(r_j) = I_c(r_j, u_c(r_j)) is
interpolated in range at each sample's r_c. A is band-limited in range to the child's band widened by the
angle's drift: a component of nu_u <= 1/(2 beta) cycles per angle sample moves
``gamma = |du_c/dr| dr / du_c`` angle samples per range sample, so A's band is at most 1/(2U) + gamma/(2 beta)
cycles per range sample: the range kernel sees ``U_eff = U / (1 + gamma U / beta)``. The merge takes a row
this way where the child ranges rise along it and ``gamma <= ALONG_RAY_SLACK beta / U`` (so U_eff >= U / 1.02);
otherwise that child is interpolated sample by sample in 2-D (GB-SAR rows within a few tens of metres of
the rail). For a straight track gamma ~ |s| (1 - u^2) dr / (r^2 du_c): about 2e-3 on GOTCHA, 1e-5 on a
spaceborne block. The error model below uses e_range_order(U / (1 + ALONG_RAY_SLACK)). Measured on GOTCHA:
the image differs from the 2-D merge's by 3e-6 of the peak, and the merges take 10-15 % less time.

**Where the polar samples are.** A polar sample (r, u) is a circle about the chord; it is placed where
that circle meets the plane fitted to the pixels (least squares), on the side of the scene. For a
straight track the ranges depend on (r, u) only, so the placement does not matter; for a curved one
(orbit, circular pass) the range to a pulse off the chord by delta changes by at most
``delta * (angle between the sample and the pixel about the chord)``: zero for pixels on a plane
(GOTCHA's z = 0 grid, GB-SAR), and ``k delta h / (r sin(theta))`` for pixels h off the fitted plane
(a spaceborne block: delta = L^2 / (8 R_orbit) ~ 6 cm for L = 1.9 km, h of a few hundred metres:
below 0.05 rad).

**The aperture window W_n(X).** It depends on the pixel, with hard edges (the band's ends), so it is
not band-limited in u and cannot be applied on the coarse early polar grids. It is applied at the
last stage instead: the top subapertures are kept shorter than the synthetic aperture (``aperture_split``
of them per aperture; stripmap and beam-limited GB-SAR), and each contributes its image times the
mean of W_n over its pulses at that pixel, ``Wbar_s(X)``: the normalized coordinate of W (Doppler
(f - fdc)/Ba, or the footprint position t - 1/2) is linear in n over a short subaperture, so
Wbar_s = integral of W over [u_first - delta/2, u_last + delta/2] / (n_s delta), exact through the
cumulative window table. At a scatterer's peak all its pulses add in phase, so this is exact there
where the echo's amplitude is the same over the subaperture (up to a fraction of one pulse at each
band edge); a subaperture across a band edge also brings its out-of-band pulses, weighted as its
in-band ones, so the antenna pattern's change over one top subaperture at the band edge, and
elsewhere the first moment of the subaperture's pulses times ``W' L_top / L_a``, are the errors: both
fall as ``aperture_split`` rises (measured on the Radarsat-1-like scene: split 4 moves the azimuth
PSLR by 0.5 dB, split 16 by 0.03 dB; docs/focusing.md).

**Interpolation kernels and error model.** Two taps: linear interpolation. N >= 4 taps: the sinc
windowed by Knab's approximate prolate window for a signal oversampled by beta [Knab1979],
``h(x) = sinc(x) cosh(pi v (N/2) sqrt(1 - (2x/N)^2)) / cosh(pi v N/2)``, v = 1 - 1/beta (the guard band),
tabulated at 1/512 sample. Interpolating ``exp(j 2 pi nu x)``, |nu| <= 1/(2 beta) cycles per sample,
errs by at most

    e_2(beta) = (pi / beta)^2 / 8 (linear),   e_N(beta) ~ 1 / cosh(pi v N / 2) (Knab)   (:func:`kernel_error`),

(the measured maximum is 0.76 - 1.14 times the second for beta in [1.5, 3], N in [4, 8]: tests/focus/test_ffbp.py);
e.g. e_6(2) = 1.8e-2, e_8(2) = 3.7e-3, e_6(3) = 3.7e-3, e_8(3) = 4.6e-4. The range axis sees the same
with beta -> U = c / (2 B dr_polar) (``range_oversample``). Every merge and the last stage interpolate
once in each axis, so at a scatterer's peak (all components coherent) the relative error is below

    eps <= (S + 1) (e_order(beta) + e_range_order(U / (1 + ALONG_RAY_SLACK))),  S = merge stages
                                                                                  (:func:`peak_error_bound`),

a worst case (the whole spectrum at the band edge): windows weight the band's edges down, so measured
errors are well below it (tests/focus/test_ffbp.py, bench/bench_ffbp.py). Block invariance: the
subapertures are aligned to the global pulse index (``first_index``), the polar grids to global lattices
(r0 and u0 multiples of the steps) and every polar sample is a function of its stencil only, so a
pixel's value does not depend on the other pixels of its block (to the rounding of the samples'
positions, r0 + i dr from different origins: 1e-5 of the peak measured) as long as the grids hold its
stencil; where a top subaperture's grid does not hold a pixel, the last stage backprojects that
subaperture there pulse by pulse.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from sarcli.errors import ConfigError
from sarcli.focus.phasor import cis

MAX_ORDER = 8
ALONG_RAY_SLACK = 0.02  # the along-ray merge may widen the range band by this fraction (module docstring)
FINAL_CHUNK = 256  # pixels per task of the last stage
DU_MAX = 0.05  # coarsest angular step (a single pulse's image does not depend on u)


@dataclass(frozen=True)
class FfbpKnobs:
    """The accuracy knobs (module docstring): ``base`` pulses per first subaperture and subapertures merged per
    stage (2..8); ``oversample`` the angular oversampling beta (>= 1); ``order`` kernel taps in angle
    (2 = linear, 4, 6, 8 = Knab-windowed sinc); ``range_order`` kernel taps in range (on the lines' upsampled
    spacing); ``range_oversample``: the polar grids' range spacing is the range cell c/(2B) over it (at
    least the lines' spacing); ``aperture_split``: top subapertures per synthetic aperture where the aperture window is
    pixel-dependent (stripmap, beam-limited GB-SAR)."""

    base: int = 4
    oversample: float = 2.0
    order: int = 6
    range_order: int = 6
    range_oversample: float = 2.0
    aperture_split: int = 16

    def __post_init__(self) -> None:
        if not 2 <= self.base <= 8:
            raise ConfigError(f"ffbp base must be 2..8, got {self.base}")
        if not (math.isfinite(self.oversample) and 1.0 <= self.oversample <= 64.0):
            raise ConfigError(f"ffbp oversample must be in [1, 64], got {self.oversample}")
        for name, v in (("order", self.order), ("range_order", self.range_order)):
            if v not in (2, 4, 6, 8):
                raise ConfigError(f"ffbp {name} must be 2, 4, 6 or 8 (kernel taps), got {v}")
        if not (math.isfinite(self.range_oversample) and 1.0 <= self.range_oversample <= 64.0):
            raise ConfigError(f"ffbp range_oversample must be in [1, 64], got {self.range_oversample}")
        if not 1 <= self.aperture_split <= 1024:
            raise ConfigError(f"ffbp aperture_split must be 1..1024, got {self.aperture_split}")


def kernel_error(order: int, oversample: float) -> float:
    """Error model of one interpolation of a unit phasor with |nu| <= 1/(2 oversample) cycles per sample
    by the kernel of ``order`` taps (module docstring)."""
    if order == 2:
        return float((np.pi / oversample) ** 2 / 8)
    return float(1.0 / np.cosh(np.pi * (1.0 - 1.0 / oversample) * order / 2))


def peak_error_bound(knobs: FfbpKnobs, stages: int, range_oversample: float) -> float:
    """Worst-case relative error of a scatterer's peak after ``stages`` merges (module docstring): the range
    kernel at the along-ray merge's narrowest effective oversampling."""
    return (stages + 1) * (kernel_error(knobs.order, knobs.oversample)
                           + kernel_error(knobs.range_order, range_oversample / (1.0 + ALONG_RAY_SLACK)))


# --- numba kernels -------------------------------------------------------------------------------------

TABLE_Q = 512  # kernel table points per sample


def kernel_table(order: int, oversample: float) -> np.ndarray:
    """The interpolation kernel in polyphase layout, ``tab[j, i] = h(j / TABLE_Q - node_i)`` (TABLE_Q + 1,
    ``order``): the weight of node i = -order/2 + 1 + i at the offset mu = j / TABLE_Q in [0, 1] (module
    docstring); h is the triangle for ``order`` 2, else the Knab-windowed sinc for a signal oversampled by
    ``oversample``, ``sinc(x) cosh(pi v (N/2) sqrt(1 - (2x/N)^2)) / cosh(pi v N/2)``, v = 1 - 1/oversample."""
    nodes = np.arange(order) - order // 2 + 1
    x = np.arange(TABLE_Q + 1)[:, None] / TABLE_Q - nodes[None, :]
    if order == 2:
        return np.ascontiguousarray(np.maximum(0.0, 1.0 - np.abs(x)))
    c = np.pi * (1.0 - 1.0 / oversample) * order / 2
    window = np.cosh(c * np.sqrt(np.clip(1.0 - (2 * x / order) ** 2, 0.0, None))) / np.cosh(c)
    return np.ascontiguousarray(np.sinc(x) * window)


@njit(cache=True, inline="always")
def _weights(order, mu, tab, out):
    """Kernel weights of the ``order`` nodes -order/2+1 .. order/2 at offset mu in [0, 1): the polyphase
    table's rows j and j + 1 about mu TABLE_Q, interpolated linearly (one fraction for every node)."""
    t = mu * TABLE_Q
    j = min(int(t), TABLE_Q - 1)
    f = t - j
    for i in range(order):
        out[i] = tab[j, i] * (1.0 - f) + tab[j + 1, i] * f


@njit(cache=True, inline="always")
def _polar_point(fr, p0, nrm, r, u):
    """The 3-D point at polar (r, u) of frame ``fr`` (rows c, d, e1, e2) on the plane (p0, nrm), scene side."""
    rho = r * math.sqrt(max(0.0, 1.0 - u * u))
    a = nrm[0] * fr[2, 0] + nrm[1] * fr[2, 1] + nrm[2] * fr[2, 2]
    b = nrm[0] * fr[3, 0] + nrm[1] * fr[3, 1] + nrm[2] * fr[3, 2]
    dd = 0.0
    for i in range(3):
        dd += nrm[i] * (fr[0, i] + r * u * fr[1, i] - p0[i])
    m = math.sqrt(a * a + b * b)
    cp = 1.0
    sp = 0.0
    if m * rho > 1e-12:  # phi = psi +- acos(ca), psi = atan2(b, a): the root nearer e1 (larger cos phi)
        ca = min(1.0, max(-1.0, -dd / (m * rho)))
        st = math.sqrt(1.0 - ca * ca)
        c1 = (a * ca - b * st) / m
        c2 = (a * ca + b * st) / m
        if c1 >= c2:
            cp = c1
            sp = (b * ca + a * st) / m
        else:
            cp = c2
            sp = (b * ca - a * st) / m
    x = fr[0, 0] + r * u * fr[1, 0] + rho * (cp * fr[2, 0] + sp * fr[3, 0])
    y = fr[0, 1] + r * u * fr[1, 1] + rho * (cp * fr[2, 1] + sp * fr[3, 1])
    z = fr[0, 2] + r * u * fr[1, 2] + rho * (cp * fr[2, 2] + sp * fr[3, 2])
    return x, y, z


@njit(cache=True, inline="always")
def _band_u(mode, n, x, y, z, bpar, pos, vel, par):
    """Normalized aperture-window coordinate of pulse n at point (x, y, z) (inside the window: |u| <= 1/2).
    mode 1: Doppler ``(2 v.(X - p)/(lam R) - fdc)/Ba``, par = (lam, Ba), bpar = fdc; mode 2: footprint
    ``(x_n - a)/(b - a) - 1/2``, [a, b] = rail [x0, x1] within ``|x - x_n| <= hb R0``, par = (hb, x0, x1)."""
    if mode == 1:
        dx = x - pos[n, 0]
        dy = y - pos[n, 1]
        dz = z - pos[n, 2]
        rr = math.sqrt(dx * dx + dy * dy + dz * dz)
        f = 2.0 * (vel[n, 0] * dx + vel[n, 1] * dy + vel[n, 2] * dz) / (par[0] * rr)
        return (f - bpar) / par[1]
    if mode == 2:
        r0 = math.sqrt(y * y + z * z)
        a = max(par[1], x - par[0] * r0)
        b = min(par[2], x + par[0] * r0)
        if b < a:  # the footprint misses the rail
            return 1e9
        if b == a:
            return 0.0 if pos[n, 0] == a else 1e9
        return (pos[n, 0] - a) / (b - a) - 0.5
    return 0.0


@njit(cache=True, inline="always")
def _cum(ctab, u):
    """Cumulative window integral from -1/2 to u (table over [-1/2, 1/2], linear lookup)."""
    if u <= -0.5:
        return 0.0
    if u >= 0.5:
        return ctab[ctab.size - 1]
    t = (u + 0.5) * (ctab.size - 1)
    j = min(int(t), ctab.size - 2)
    a = t - j
    return ctab[j] * (1.0 - a) + ctab[j + 1] * a


@njit(cache=True, inline="always")
def _table(wtab, u):
    """The window table (over u in [-1/2, 1/2]) at u, linear lookup; 0 outside."""
    if u < -0.5 or u > 0.5:
        return 0.0
    t = (u + 0.5) * (wtab.size - 1)
    j = min(int(t), wtab.size - 2)
    f = t - j
    return wtab[j] * (1.0 - f) + wtab[j + 1] * f


@njit(cache=True, inline="always")
def _window_mean(mode, s0, s1, x, y, z, bpar, pos, vel, par, wtab, ctab, span_max):
    """(mean of the aperture window W over pulses s0..s1-1 at a point, whether to backproject them one
    by one instead: a band edge falls among them, or they span more than ``span_max`` of the window
    (a pixel whose aperture is short, e.g. cut by a rail end)) (module docstring)."""
    if mode == 0:
        return 1.0, False
    ua = _band_u(mode, s0, x, y, z, bpar, pos, vel, par)
    ub = ua if s1 - s0 == 1 else _band_u(mode, s1 - 1, x, y, z, bpar, pos, vel, par)
    n = s1 - s0
    delta = abs(ub - ua) / (n - 1) if n > 1 else 0.0
    lo = min(ua, ub) - 0.5 * delta
    hi = max(ua, ub) + 0.5 * delta
    if hi < -0.5 or lo > 0.5:
        return 0.0, False
    if lo < -0.5 or hi > 0.5 or hi - lo > span_max:
        return 0.0, True
    if delta <= 1e-12:
        return _table(wtab, ua), False
    return (_cum(ctab, hi) - _cum(ctab, lo)) / (hi - lo), False


@njit(cache=True, inline="always")
def _row_points(fr, p0, nrm, r0, u, n, dr, pts, r):
    """The polar samples (r0 + i dr, u), i < n, of frame ``fr``: their ranges in ``r``, their points in ``pts``."""
    for i in range(n):
        r[i] = r0 + i * dr
        pts[i, 0], pts[i, 1], pts[i, 2] = _polar_point(fr, p0, nrm, r[i], u)


@njit(cache=True, inline="always")
def _phasors(k, a, b, n, cr, ci):
    """(cr + j ci)[i] = exp(j k (a[i] - b[i])), i < n: one branch-free loop that vectorizes."""
    for i in range(n):
        cr[i], ci[i] = cis(k * (a[i] - b[i]))


@njit(cache=True, inline="always")
def _line_at(lines, m, p):
    """(line ``m`` interpolated linearly at fractional sample ``p``, whether p lies in [0, n - 1); False for
    NaN): the exact kernels' read of a range-compressed line."""
    if not (p >= 0.0 and p < lines.shape[1] - 1):
        return 0j, False
    j = int(p)
    mu = p - j
    return lines[m, j] * (1.0 - mu) + lines[m, j + 1] * mu, True


@njit(cache=True)
def _stage0_row(lines, r_first, dr_in, k, pos, ref, w, n0, n1, fr, p0, nrm, r0, u, n, dr, pts, r, rho, cr, ci, acc):
    """``acc[:n]``: the stage-0 row (ranges r0 + i dr at angle u) of frame ``fr``, the pulses n0..n1-1
    backprojected there pulse by pulse (linear interpolation of the line at rho_n, the phasor of each
    pulse's ranges in one vectorizable pass); ``pts`` (>= n, 3), ``r``, ``rho``, ``cr``, ``ci``, ``acc``
    (>= n): scratch (the CPU and the CUDA kernels share this code)."""
    _row_points(fr, p0, nrm, r0, u, n, dr, pts, r)
    for i in range(n):
        acc[i] = 0j
    for m in range(n0, n1):
        if w[m] == 0.0:
            continue
        for i in range(n):
            dx = pts[i, 0] - pos[m, 0]
            dy = pts[i, 1] - pos[m, 1]
            dz = pts[i, 2] - pos[m, 2]
            rho[i] = math.sqrt(dx * dx + dy * dy + dz * dz) - ref[m]
        _phasors(k, rho, r, n, cr, ci)
        for i in range(n):
            v, ok = _line_at(lines, m, (rho[i] - r_first) / dr_in)
            if ok:
                acc[i] += w[m] * v * complex(cr[i], ci[i])


@njit(cache=True, parallel=True)
def stage0_kernel(lines, r_first, dr_in, k, pos, ref, w, sub_start, sub_stop, frames, p0, nrm,
                  g_r0, g_u0, g_du, g_nr, g_nu, g_off, dr, row_sub, row_iu, out):
    """Stage 0: the pulses of each subaperture backprojected onto its polar grid (rows (s, iu) in parallel,
    :func:`_stage0_row`)."""
    width = 1
    for s in range(g_nr.size):
        width = max(width, g_nr[s])
    for q in prange(row_sub.size):
        s = row_sub[q]
        n = g_nr[s]
        acc = np.empty(width, np.complex128)
        _stage0_row(lines, r_first, dr_in, k, pos, ref, w, sub_start[s], sub_stop[s], frames[s], p0, nrm, g_r0[s],
                    g_u0[s] + row_iu[q] * g_du[s], n, dr, np.empty((width, 3)), np.empty(width), np.empty(width),
                    np.empty(width), np.empty(width), acc)
        base = g_off[s] + row_iu[q] * n
        for i in range(n):
            out[base + i] = acc[i]


@njit(cache=True, inline="always")
def _inside(nr, nu, fr_, fu, order, range_order):
    """Whether the interpolation stencil at fractional (fr_, fu) lies in an nr x nu grid (False for NaN)."""
    if not (fr_ >= 0.0 and fu >= 0.0 and fr_ < nr and fu < nu):
        return False
    r_lo = int(fr_) - range_order // 2 + 1
    u_lo = int(fu) - order // 2 + 1
    return r_lo >= 0 and u_lo >= 0 and r_lo + range_order <= nr and u_lo + order <= nu


@njit(cache=True, inline="always")
def _interp(img, off, nr, nu, fr_, fu, order, range_order, tab_u, tab_r, wr, wu):
    """Interpolation of a polar image (rows u, columns r) at fractional (fr_, fu); 0 if the stencil
    leaves the grid (or a coordinate is not finite: compared before any integer conversion)."""
    if not _inside(nr, nu, fr_, fu, order, range_order):
        return 0j
    ir = int(math.floor(fr_))
    iu = int(math.floor(fu))
    r_lo = ir - range_order // 2 + 1
    u_lo = iu - order // 2 + 1
    _weights(range_order, fr_ - ir, tab_r, wr)
    _weights(order, fu - iu, tab_u, wu)
    acc_re = 0.0  # real and imaginary sums: real weights times complex64 samples without complex products
    acc_im = 0.0
    for a in range(order):
        row = off + (u_lo + a) * nr + r_lo
        s_re = 0.0
        s_im = 0.0
        for b in range(range_order):
            v = img[row + b]
            s_re += wr[b] * v.real
            s_im += wr[b] * v.imag
        acc_re += wu[a] * s_re
        acc_im += wu[a] * s_im
    return complex(acc_re, acc_im)


@njit(cache=True, inline="always")
def _child_polar(cf, x, y, z):
    """(r_c, u_c) of the point (x, y, z) in the polar frame ``cf`` of a child subaperture."""
    dx = x - cf[0, 0]
    dy = y - cf[0, 1]
    dz = z - cf[0, 2]
    rc = math.sqrt(dx * dx + dy * dy + dz * dz)
    return rc, (dx * cf[1, 0] + dy * cf[1, 1] + dz * cf[1, 2]) / rc


@njit(cache=True, inline="always")
def _ray_is_separable(rcs, ucs, n, dr, du, gamma_max):
    """Whether a parent row's child ranges ``rcs[:n]`` rise strictly and its child angles ``ucs`` change by at
    most ``gamma_max`` child angle samples ``du`` per range sample ``dr`` (module docstring: the along-ray merge)."""
    if n < 2:
        return False
    for i in range(n - 1):
        step = rcs[i + 1] - rcs[i]
        if not step > 0.0:
            return False
        if abs(ucs[i + 1] - ucs[i]) * dr > gamma_max * du * step:
            return False
    return True


@njit(cache=True, inline="always")
def _column_along_ray(child, off, nr, nu, j, fu, order, tab_u, wu):
    """The child image's column ``j`` interpolated in angle at fractional row ``fu``; NaN where the angular
    stencil leaves the grid (so that any range interpolation using it is NaN, and dropped)."""
    if not (fu >= 0.0 and fu < nu):
        return complex(math.nan, math.nan)
    iu = int(math.floor(fu))
    u_lo = iu - order // 2 + 1
    if u_lo < 0 or u_lo + order > nu:
        return complex(math.nan, math.nan)
    _weights(order, fu - iu, tab_u, wu)
    acc_re = 0.0
    acc_im = 0.0
    for a in range(order):
        v = child[off + (u_lo + a) * nr + j]
        acc_re += wu[a] * v.real
        acc_im += wu[a] * v.imag
    return complex(acc_re, acc_im)


@njit(cache=True, inline="always")
def _merge_child_along_ray(child, c_r0, c_u0, c_du, nr, nu, off, rcs, ucs, cr, ci, n, dr, order, range_order, tab_u,
                           tab_r, wr, wu, col, acc):
    """Add one child to a parent row by the along-ray merge (module docstring): the child's columns j
    interpolated in angle where the row's ray crosses them (its angle there from the row's nearest sample
    below r_j along the row's mean slope), then each parent sample interpolated in range along that curve and
    re-referenced by the phasors ``cr + j ci``."""
    j0 = max(0, int(math.floor((rcs[0] - c_r0) / dr)) - range_order // 2 + 1)
    j1 = min(nr - 1, int(math.floor((rcs[n - 1] - c_r0) / dr)) + range_order // 2)
    slope = (ucs[n - 1] - ucs[0]) / ((rcs[n - 1] - rcs[0]) * c_du)  # angle samples per metre, the row's mean
    p = 0
    for j in range(j0, j1 + 1):
        rj = c_r0 + j * dr
        while p < n - 1 and rcs[p + 1] <= rj:
            p += 1
        fu = (ucs[p] - c_u0) / c_du + (rj - rcs[p]) * slope
        col[j - j0] = _column_along_ray(child, off, nr, nu, j, fu, order, tab_u, wu)
    for i in range(n):
        f_r = (rcs[i] - c_r0) / dr
        if not (f_r >= 0.0 and f_r < nr):
            continue
        ir = int(math.floor(f_r))
        r_lo = ir - range_order // 2 + 1
        if r_lo < 0 or r_lo + range_order > nr:
            continue
        _weights(range_order, f_r - ir, tab_r, wr)
        v_re = 0.0
        v_im = 0.0
        for b in range(range_order):
            v = col[r_lo + b - j0]
            v_re += wr[b] * v.real
            v_im += wr[b] * v.imag
        if v_re == v_re:  # not NaN: every column of the stencil lies in the child's grid
            acc[i] += complex(v_re, v_im) * complex(cr[i], ci[i])


@njit(cache=True)
def _merge_row(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, c0, c1, fr, p0, nrm, r0, u, n, dr, k, order,
               range_order, tab_u, tab_r, gamma_max, wr, wu, pts, r, rcs, ucs, cr, ci, col, acc):
    """``acc[:n]``: the parent row of frame ``fr`` at angle ``u`` (ranges r0 + i dr), its children c0..c1-1 each
    merged by the along-ray merge where the row is separable for it (:func:`_ray_is_separable`), else sample
    by sample (a 2-D interpolation at each sample), re-referenced (module docstring). ``wr``, ``wu``: scratch
    of MAX_ORDER; ``pts`` (>= n, 3), ``r``, ``rcs``, ``ucs``, ``cr``, ``ci``, ``acc`` (>= n), ``col`` (>= the
    widest child): scratch (the CPU and the CUDA kernels share this code)."""
    _row_points(fr, p0, nrm, r0, u, n, dr, pts, r)
    for i in range(n):
        acc[i] = 0j
    for c in range(c0, c1):
        if c_nr[c] == 0:
            continue
        for i in range(n):
            rcs[i], ucs[i] = _child_polar(c_frames[c], pts[i, 0], pts[i, 1], pts[i, 2])
        _phasors(k, rcs, r, n, cr, ci)
        if _ray_is_separable(rcs, ucs, n, dr, c_du[c], gamma_max):
            _merge_child_along_ray(child, c_r0[c], c_u0[c], c_du[c], c_nr[c], c_nu[c], c_off[c], rcs, ucs, cr, ci, n,
                                   dr, order, range_order, tab_u, tab_r, wr, wu, col, acc)
            continue
        for i in range(n):
            v = _interp(child, c_off[c], c_nr[c], c_nu[c], (rcs[i] - c_r0[c]) / dr, (ucs[i] - c_u0[c]) / c_du[c],
                        order, range_order, tab_u, tab_r, wr, wu)
            if v != 0j:
                acc[i] += v * complex(cr[i], ci[i])


@njit(cache=True, parallel=True)
def merge_kernel(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start, kid_stop, frames, p0, nrm, g_r0,
                 g_u0, g_du, g_nr, g_off, dr, k, order, range_order, tab_u, tab_r, row_sub, row_iu, gamma_max, out):
    """One merge stage, a parent row (s, iu) per task (:func:`_merge_row`)."""
    width = 1
    for s in range(g_nr.size):
        width = max(width, g_nr[s])
    c_width = 1
    for c in range(c_nr.size):
        c_width = max(c_width, c_nr[c])
    for q in prange(row_sub.size):
        s = row_sub[q]
        n = g_nr[s]
        acc = np.empty(width, np.complex128)
        _merge_row(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start[s], kid_stop[s], frames[s], p0, nrm,
                   g_r0[s], g_u0[s] + row_iu[q] * g_du[s], n, dr, k, order, range_order, tab_u, tab_r, gamma_max,
                   np.empty(MAX_ORDER), np.empty(MAX_ORDER), np.empty((width, 3)), np.empty(width), np.empty(width),
                   np.empty(width), np.empty(width), np.empty(width), np.empty(c_width, np.complex128), acc)
        base = g_off[s] + row_iu[q] * n
        for i in range(n):
            out[base + i] = acc[i]


@njit(cache=True)
def _final_pixels(img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix, r_outs, m0, m1, dr,
                  k, order, range_order, tab_u, tab_r, mode, bpars, pos, vel, par, wtab, ctab, span_max, lines, r_first,
                  dr_in, ref, w, wr, wu, rcs, frs, fus, cr, ci, acc, wsa, out, wsum):
    """out[m] (image) and wsum[m] (sum of the window x pulse weights used) of the pixels m0..m1-1 of ``pix``
    with output references ``r_outs`` and window parameters ``bpars`` (:func:`final_kernel`), a top
    subaperture at a time: the pixels' polar coordinates and phasors in one vectorizable pass, then each
    pixel's interpolation (or its pulse-by-pulse backprojection). ``rcs``, ``frs``, ``fus``, ``cr``, ``ci``,
    ``acc``, ``wsa`` (>= m1 - m0): scratch. The CPU kernel calls it once per chunk of pixels, the CUDA kernel
    once per pixel: they share this code."""
    n_m = m1 - m0
    for t in range(n_m):
        acc[t] = 0j
        wsa[t] = 0.0
    for s in range(g_r0.size):
        fr = frames[s]
        for t in range(n_m):
            dx = pix[m0 + t, 0] - fr[0, 0]
            dy = pix[m0 + t, 1] - fr[0, 1]
            dz = pix[m0 + t, 2] - fr[0, 2]
            rcs[t] = math.sqrt(dx * dx + dy * dy + dz * dz)
            frs[t] = (rcs[t] - g_r0[s]) / dr
            fus[t] = ((dx * fr[1, 0] + dy * fr[1, 1] + dz * fr[1, 2]) / rcs[t] - g_u0[s]) / g_du[s]
        _phasors(k, rcs, r_outs[m0:m1], n_m, cr, ci)
        for t in range(n_m):
            m = m0 + t
            x = pix[m, 0]
            y = pix[m, 1]
            z = pix[m, 2]
            wm, exact = _window_mean(mode, sub_start[s], sub_stop[s], x, y, z, bpars[m], pos, vel, par, wtab, ctab,
                                     span_max)
            if wm == 0.0 and not exact:
                continue
            # interpolate its polar image, or backproject it where that does not hold the pixel
            if not exact and _inside(g_nr[s], g_nu[s], frs[t], fus[t], order, range_order):
                v = _interp(img, g_off[s], g_nr[s], g_nu[s], frs[t], fus[t], order, range_order, tab_u, tab_r, wr, wu)
                acc[t] += wm * v * complex(cr[t], ci[t])
                wsa[t] += wm * sub_w[s]
                continue
            for n in range(sub_start[s], sub_stop[s]):
                wn = w[n] if mode == 0 else w[n] * _table(wtab, _band_u(mode, n, x, y, z, bpars[m], pos, vel, par))
                if wn == 0.0:
                    continue
                ex = x - pos[n, 0]
                ey = y - pos[n, 1]
                ez = z - pos[n, 2]
                rho = math.sqrt(ex * ex + ey * ey + ez * ez) - ref[n]
                v, ok = _line_at(lines, n, (rho - r_first) / dr_in)
                if not ok:
                    continue
                c, sn = cis(k * (rho - r_outs[m]))
                acc[t] += wn * v * complex(c, sn)
                wsa[t] += wn
    for t in range(n_m):
        out[m0 + t] = acc[t]
        wsum[m0 + t] = wsa[t]


@njit(cache=True, parallel=True)
def final_kernel(img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix, r_out, dr, k,
                 order, range_order, tab_u, tab_r, mode, bpar, pos, vel, par, wtab, ctab, span_max, lines, r_first,
                 dr_in, ref, w, out, wsum):
    """Last stage: the top subapertures at the pixels, each times its mean aperture window there; one
    across a band edge (or spanning much of a short window, :func:`_window_mean`), or whose polar grid
    does not hold the pixel, is backprojected pulse by pulse with the exact window instead, as the exact
    kernels do. ``wsum``: the sum of the window x pulse weights used."""
    n_pix = pix.shape[0]
    for q in prange((n_pix + FINAL_CHUNK - 1) // FINAL_CHUNK):  # scratch once per chunk, not per pixel
        _final_pixels(img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix, r_out,
                      q * FINAL_CHUNK, min(n_pix, (q + 1) * FINAL_CHUNK), dr, k, order, range_order, tab_u, tab_r,
                      mode, bpar, pos, vel, par, wtab, ctab, span_max, lines, r_first, dr_in, ref, w,
                      np.empty(MAX_ORDER), np.empty(MAX_ORDER), np.empty(FINAL_CHUNK), np.empty(FINAL_CHUNK),
                      np.empty(FINAL_CHUNK), np.empty(FINAL_CHUNK), np.empty(FINAL_CHUNK),
                      np.empty(FINAL_CHUNK, np.complex128), np.empty(FINAL_CHUNK), out, wsum)


@njit(cache=True, parallel=True)
def bounds_kernel(pts, bpts, frames, band_first, band_last, mode, pos, vel, par, out):
    """Polar extent of the pixel lattice ``pts`` (n1, n2, 3) seen by each subaperture: out[s] = (r_min,
    r_max, u_min, u_max, dr_step, du_step) over the lattice points inside the window of pulse band_first[s]
    or band_last[s] (or between), dilated by one lattice step; r_min > r_max where none is seen."""
    n1, n2 = pts.shape[0], pts.shape[1]
    for s in prange(frames.shape[0]):
        fr = frames[s]
        rr = np.empty((n1, n2))
        uu = np.empty((n1, n2))
        seen = np.zeros((n1, n2), np.bool_)
        for i in range(n1):
            for j in range(n2):
                dx = pts[i, j, 0] - fr[0, 0]
                dy = pts[i, j, 1] - fr[0, 1]
                dz = pts[i, j, 2] - fr[0, 2]
                rr[i, j] = math.sqrt(dx * dx + dy * dy + dz * dz)
                uu[i, j] = (dx * fr[1, 0] + dy * fr[1, 1] + dz * fr[1, 2]) / rr[i, j]
                if mode == 0:
                    seen[i, j] = True
                else:
                    ua = _band_u(mode, band_first[s], pts[i, j, 0], pts[i, j, 1], pts[i, j, 2], bpts[i, j], pos,
                                 vel, par)
                    ub = _band_u(mode, band_last[s], pts[i, j, 0], pts[i, j, 1], pts[i, j, 2], bpts[i, j], pos,
                                 vel, par)
                    seen[i, j] = min(ua, ub) <= 0.5 and max(ua, ub) >= -0.5
        r_lo, r_hi, u_lo, u_hi, sr, su = 1e300, -1e300, 1e300, -1e300, 0.0, 0.0
        for i in range(n1):
            for j in range(n2):
                near = False
                for a in range(max(0, i - 1), min(n1, i + 2)):
                    for b in range(max(0, j - 1), min(n2, j + 2)):
                        if seen[a, b]:
                            near = True
                if not near:
                    continue
                r_lo = min(r_lo, rr[i, j])
                r_hi = max(r_hi, rr[i, j])
                u_lo = min(u_lo, uu[i, j])
                u_hi = max(u_hi, uu[i, j])
                if i + 1 < n1:
                    sr = max(sr, abs(rr[i + 1, j] - rr[i, j]))
                    su = max(su, abs(uu[i + 1, j] - uu[i, j]))
                if j + 1 < n2:
                    sr = max(sr, abs(rr[i, j + 1] - rr[i, j]))
                    su = max(su, abs(uu[i, j + 1] - uu[i, j]))
        out[s, 0] = r_lo
        out[s, 1] = r_hi
        out[s, 2] = u_lo
        out[s, 3] = u_hi
        out[s, 4] = sr
        out[s, 5] = su


# --- the recursion -------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ApertureWindow:
    """The pixel-dependent aperture window W_n(X) (module docstring): ``mode`` 1 Doppler band (``par`` =
    (lam, Ba), ``per_pixel`` = the pixel's centroid fdc, ``vel`` the pulses' velocities), 2 GB-SAR
    footprint (``par`` = (half_beam, x0, x1), pulses' x = the rail positions); ``table``: the window
    over u in [-1/2, 1/2] (:func:`sarcli.focus.windows.window_table`); ``aperture_pulses``: the synthetic
    aperture in pulses (sets the top subaperture length)."""

    mode: int
    par: np.ndarray
    table: np.ndarray
    aperture_pulses: float
    per_pixel: np.ndarray | None = None
    vel: np.ndarray | None = None


@dataclass
class Level:
    start: np.ndarray  # (n_sub,) first pulse (local index)
    stop: np.ndarray
    frames: np.ndarray  # (n_sub, 4, 3)
    r0: np.ndarray
    u0: np.ndarray
    du: np.ndarray
    nr: np.ndarray
    nu: np.ndarray
    off: np.ndarray

    @property
    def size(self) -> int:
        return int(np.sum(self.nr * self.nu))


def _frames(pos: np.ndarray, start: np.ndarray, stop: np.ndarray, centroid: np.ndarray) -> tuple[np.ndarray,
                                                                                                  np.ndarray]:
    """Subaperture frames (c, d, e1, e2) and lengths (2 max |p_n - c|)."""
    n = pos.shape[0]
    first, last = pos[start], pos[stop - 1]
    c = 0.5 * (first + last)
    d = last - first
    single = stop - start == 1
    if np.any(single):
        i = start[single]
        d[single] = pos[np.minimum(i + 1, n - 1)] - pos[np.maximum(i - 1, 0)]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    v = centroid[None, :] - c
    v -= np.sum(v * d, axis=1, keepdims=True) * d
    e1 = v / np.linalg.norm(v, axis=1, keepdims=True)
    e2 = np.cross(d, e1)
    owner = np.repeat(np.arange(start.size), stop - start)
    dist = np.linalg.norm(pos[start[0]:stop[-1]] - c[owner], axis=1)
    length = 2.0 * np.maximum.reduceat(dist, start - start[0])
    return np.ascontiguousarray(np.stack([c, d, e1, e2], axis=1)), length


def _partition(n_pulses: int, first_index: int, length: int) -> tuple[np.ndarray, np.ndarray]:
    """Subapertures of ``length`` pulses aligned to the global index (local [start, stop))."""
    g0, g1 = first_index, first_index + n_pulses
    edges = np.arange((g0 // length) * length, g1 + length, length)
    edges = np.clip(edges, g0, g1) - g0
    edges = np.unique(edges)
    return edges[:-1].astype(np.int64), edges[1:].astype(np.int64)


def fit_plane(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(centroid, unit normal) of the least-squares plane through ``points`` (n, 3)."""
    p = np.asarray(points, np.float64).reshape(-1, 3)
    c = p.mean(axis=0)
    if p.shape[0] < 3:
        return c, np.array([0.0, 0.0, 1.0])
    return c, np.linalg.svd(p - c, full_matrices=False)[2][-1]


def top_length(knobs: FfbpKnobs, n_pulses: int, window: ApertureWindow | None) -> int:
    """Pulses per top subaperture: base^j, merged until at most ``base`` remain (no aperture window) or
    while it stays within aperture / ``aperture_split`` (aperture window)."""
    b = knobs.base
    top = b
    if window is None:
        while -(-n_pulses // top) > b:
            top *= b
    else:
        cap = max(b, window.aperture_pulses / knobs.aperture_split)
        while top * b <= cap:
            top *= b
    return top


def ffbp(lines: np.ndarray, r_first: float, dr: float, range_cell: float, wavelength: float, wavelength_min: float,
         pos: np.ndarray, ref: np.ndarray, weights: np.ndarray, pixels: np.ndarray, r_out: np.ndarray, knobs: FfbpKnobs,
         window: ApertureWindow | None = None, first_index: int = 0, plane: tuple[np.ndarray, np.ndarray] | None = None,
         stats: dict | None = None, device: str = "cpu") -> tuple[np.ndarray, np.ndarray]:
    """FFBP of ``lines`` (n_pulses, n_r) from ``pos`` (n_pulses, 3) onto ``pixels`` (n1, n2, 3) -> (image
    complex128 (n1, n2), weight sum (n1, n2)) (module docstring: notation, conventions, errors).
    ``range_cell`` = c/(2 B) the lines' resolution (m), ``ref`` (n_pulses,) the lines' reference ranges,
    ``weights`` w_n, ``r_out`` (n1, n2) the output phase reference, ``first_index`` the global index of
    pulse 0 (subapertures align to it), ``plane`` (a point towards the scene centre, its normal) where the
    polar samples lie (default: fitted to the pixels; a block-independent one keeps blocks identical),
    ``stats`` gets the stage count, the polar sample counts (total, per level, largest grid per level) and
    the stage times. ``device="cuda"``: the stages run as the CUDA kernels of :mod:`sarcli.gpu.ffbp_cuda`
    (the same helpers compiled for the card; the polar images stay on the device between stages), the plan
    (grids, extents) on the CPU."""
    pix = np.ascontiguousarray(pixels, np.float64)
    n1, n2 = pix.shape[:2]
    pos = np.ascontiguousarray(pos, np.float64)
    n_p = pos.shape[0]
    k = 4.0 * np.pi / wavelength
    w = np.ascontiguousarray(weights, np.float64)
    ref = np.ascontiguousarray(ref, np.float64)
    mode = 0 if window is None else window.mode
    par = np.zeros(3) if window is None else np.ascontiguousarray(window.par, np.float64)
    vel = np.zeros((1, 3)) if window is None or window.vel is None else np.ascontiguousarray(window.vel, np.float64)
    bpar = np.zeros((n1, n2)) if window is None or window.per_pixel is None else \
        np.ascontiguousarray(np.broadcast_to(window.per_pixel, (n1, n2)), np.float64)
    wtab = np.ones(2) if window is None else np.ascontiguousarray(window.table, np.float64)
    ctab = np.concatenate([[0.0], np.cumsum(0.5 * (wtab[1:] + wtab[:-1]))]) / (wtab.size - 1)
    # lattice of pixels for the polar extents; the plane of the polar samples
    ia = np.unique(np.linspace(0, n1 - 1, min(n1, 33)).round().astype(int))
    ja = np.unique(np.linspace(0, n2 - 1, min(n2, 33)).round().astype(int))
    lat = np.ascontiguousarray(pix[np.ix_(ia, ja)])
    blat = np.ascontiguousarray(bpar[np.ix_(ia, ja)])
    flat = pix.reshape(-1, 3)
    centroid, nrm = plane if plane is not None else fit_plane(lat.reshape(-1, 3))
    centroid = np.asarray(centroid, np.float64)
    nrm = np.asarray(nrm, np.float64)
    p0 = centroid.copy()
    top = top_length(knobs, n_p, window)
    b = knobs.base
    lengths = [b]
    while lengths[-1] < top:
        lengths.append(lengths[-1] * b)
    parts = [_partition(n_p, first_index, n) for n in lengths]
    t_start, t_stop = parts[-1]
    owner_top = np.repeat(np.arange(t_start.size), t_stop - t_start)
    dr_p = max(float(dr), range_cell / knobs.range_oversample)
    n_levels = len(lengths)
    geo = []
    for st, sp in parts:
        frames, length = _frames(pos, st, sp, centroid)
        anc = owner_top[st]
        ext = np.zeros((st.size, 6))
        bounds_kernel(lat, blat, frames, t_start[anc], t_stop[anc] - 1, mode, pos, vel, par, ext)
        du = wavelength_min / (2.0 * knobs.oversample * np.maximum(length, 1e-300))
        geo.append((st, sp, frames, ext, np.minimum(du, DU_MAX)))
    # margins beyond the pixels' extent: a subaperture's stencil (order/2 + 1 samples) plus the margin of
    # its parent, whose samples it must cover (the top level: the pixels)
    margins: list[tuple[float, np.ndarray]] = [(0.0, np.zeros(0))] * n_levels
    for li in range(n_levels - 1, -1, -1):
        st, du = geo[li][0], geo[li][4]
        m_u = (knobs.order // 2 + 1) * du
        m_r = (knobs.range_order // 2 + 1) * dr_p * (n_levels - li)
        if li < n_levels - 1:
            m_u = m_u + margins[li + 1][1][np.searchsorted(geo[li + 1][0], st, side="right") - 1]
        margins[li] = (m_r, m_u)
    levels: list[Level] = []
    for (st, sp, frames, ext, du), (m_r, m_u) in zip(geo, margins, strict=True):
        mr = m_r + ext[:, 4]
        mu = m_u + ext[:, 5]
        seen = ext[:, 0] <= ext[:, 1]
        ext[~seen, :4] = 0.0
        r0 = np.floor((ext[:, 0] - mr) / dr_p) * dr_p
        nr = np.where(seen, np.floor((ext[:, 1] + mr - r0) / dr_p).astype(np.int64) + 1, 0)
        iu0 = np.floor((ext[:, 2] - mu) / du)
        u0 = iu0 * du
        nu = np.where(seen, np.floor((ext[:, 3] + mu - u0) / du).astype(np.int64) + 1, 0)
        off = np.concatenate([[0], np.cumsum(nr * nu)[:-1]]).astype(np.int64)
        levels.append(Level(st, sp, frames, np.where(seen, r0, 0.0), u0, du, nr, nu, off))
    total = sum(lv.size for lv in levels)
    if max(lv.size for lv in levels) > 400_000_000:
        raise ConfigError(f"ffbp polar grids of {max(lv.size for lv in levels):.3g} samples: the pixels span too "
                          "wide an angle or range for one block; use smaller blocks or windows")
    lines_c = np.ascontiguousarray(lines)
    tab_u = kernel_table(knobs.order, knobs.oversample)
    tab_r = kernel_table(knobs.range_order, range_cell / dr_p)
    dev = None
    if device == "cuda":
        from sarcli.gpu import ffbp_cuda
        from sarcli.gpu.device import require_cuda
        dev = require_cuda()
        lines_c = dev.asarray(lines_c)
    img = None
    seconds = []
    for li, lv in enumerate(levels):
        t0 = time.perf_counter()
        row_sub = np.repeat(np.arange(lv.nu.size), lv.nu).astype(np.int64)
        row_iu = (np.arange(row_sub.size) - np.repeat(np.cumsum(lv.nu) - lv.nu, lv.nu)).astype(np.int64)
        if li == 0:
            args = (lines_c, float(r_first), float(dr), k, pos, ref, w, lv.start, lv.stop, lv.frames, p0, nrm,
                    lv.r0, lv.u0, lv.du, lv.nr)
            if dev is not None:
                out = ffbp_cuda.stage0(dev, *args, lv.off, dr_p, row_sub, row_iu, lv.size)
            else:
                out = np.zeros(lv.size, np.complex64)
                stage0_kernel(*args, lv.nu, lv.off, dr_p, row_sub, row_iu, out)
        else:
            ch = levels[li - 1]
            kid = np.searchsorted(ch.start, lv.start).astype(np.int64)
            kid_stop = np.searchsorted(ch.start, lv.stop).astype(np.int64)
            args = (img, ch.frames, ch.r0, ch.u0, ch.du, ch.nr, ch.nu, ch.off, kid, kid_stop, lv.frames, p0, nrm,
                    lv.r0, lv.u0, lv.du, lv.nr, lv.off, dr_p, k, knobs.order, knobs.range_order, tab_u, tab_r,
                    row_sub, row_iu)
            gamma_max = ALONG_RAY_SLACK * knobs.oversample * dr_p / range_cell
            if dev is not None:
                out = ffbp_cuda.merge(dev, *args, gamma_max, lv.size)
            else:
                out = np.zeros(lv.size, np.complex64)
                merge_kernel(*args, gamma_max, out)
        img = out
        seconds.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    lv = levels[-1]
    sub_w = np.add.reduceat(w, lv.start) if lv.start.size else np.zeros(0)
    args = (img, lv.frames, lv.r0, lv.u0, lv.du, lv.nr, lv.nu, lv.off, lv.start, lv.stop, sub_w,
            np.ascontiguousarray(flat), np.ascontiguousarray(np.broadcast_to(r_out, (n1, n2)).ravel(), np.float64),
            dr_p, k, knobs.order, knobs.range_order, tab_u, tab_r, mode, bpar.ravel(), pos, vel, par, wtab, ctab,
            1.0 / knobs.aperture_split, lines_c, float(r_first), float(dr), ref, w)
    if dev is not None:
        res, wsum = ffbp_cuda.final(dev, *args)
    else:
        res = np.zeros(n1 * n2, np.complex128)
        wsum = np.zeros(n1 * n2)
        final_kernel(*args, res, wsum)
    if stats is not None:
        stats.update({"merge_stages": n_levels - 1, "top_subapertures": int(lv.start.size),
                      "top_pulses": int(lengths[-1]), "polar_samples": total,
                      "level_samples": [lv.size for lv in levels],
                      "level_shape": [(int(lv.nu.max()), int(lv.nr.max()), int(lv.nu.size)) for lv in levels],
                      "stage_seconds": seconds + [time.perf_counter() - t0]})
    return res.reshape(n1, n2), wsum.reshape(n1, n2)
