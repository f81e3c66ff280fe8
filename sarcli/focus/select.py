"""``--algorithm auto``: the cheapest focuser whose PREDICTED error for this geometry meets a quality.

For every registered focuser that has an error model here (``rd``, ``backprojection`` and, once
registered, ``csa``, ``omegak``, ``ffbp``) and every knob setting of :data:`KNOB_SETTINGS`, the
residual phase the algorithm leaves in the 2-D spectrum of a point target is written down
analytically (below), turned into an impulse response by a small 2-D FFT over the processed band
(the windows of the product), and measured as the map measures images: IRW change against the ideal
(the same band without error), PSLR change, peak phase and position error. The candidates that meet
:class:`Quality` are ranked by a predicted cost in units of "two ``fft2`` of the raw block"
(:func:`predicted_cost`); the cheapest is chosen. The map (``bench/bench_focus_family.py``) measures
the same quantities on simulated scenes and ``tests/focus/test_select.py`` checks the models
against it.

Notation (as :mod:`sarcli.focus.kinematics`): carrier f0, x the baseband range frequency
(|x| <= B/2), f the absolute azimuth frequency, V the effective velocity, R0 the closest range,
a = c f / (2V) and ``g(x, f) = sqrt((f0 + x)^2 - a^2)``. The exact 2-D spectrum of a range-compressed
point target on a straight (hyperbolic) track is [CumWong2005, eq. 5.x, 2-D POSP]

    Phi(x, f) = -(4 pi R0 / c) g(x, f) - 2 pi f eta0.

Expanding g in x about 0: g = g0 + x f0 / g0 - a^2 x^2 / (2 g0^3) + a^2 f0 x^3 / (2 g0^5) + ...,
g0 = f0 D(f), D = sqrt(1 - (lam f / 2V)^2). The constant term is the azimuth matched filter, the
linear one the range cell migration R0 / D, the quadratic one the secondary range compression
1 / K_src = 2 R0 a^2 / (c g0^3) (:func:`sarcli.focus.rangecomp.inverse_src_rate`). Let
``H(x, f) = g - g0 - x f0 / g0`` (everything beyond first order, computed exactly, not expanded).

Residual phase per algorithm (target at R0, reference range R_ref = mid-swath, V_ref its velocity):

- ``rd`` (:mod:`sarcli.focus.rda`): RCMC and azimuth filter exact per range column, SRC (its
  azimuth-frequency dependence included) at R_ref only:
  ``dPhi = -(4 pi / c) [R0 H(x, f) + R_ref a^2 x^2 / (2 g0^3)]``: the cubic and higher terms of H
  (~ pi/4 (R0 B / c) (B / f0)^2 sin^2(theta) / cos^5(theta) at the band edge, x = B/2, f = fdc) that
  no RDA compensates [Bamler1992; CumWong2005, sec. 6.3], plus the range dependence of SRC,
  (pi B^2 / (2 c f0)) (R0 - R_ref) sin^2(theta) / cos^3(theta) [CumWong2005, sec. 6.3.3]. The RCMC
  interpolation (sinc8 on a 2x range grid) adds < 0.3 % of IRW (``bench_focus``): not modelled.
- ``csa``: the chirp-scaling algorithm [Raney1994] keeps the same second-order expansion (its
  scaled chirp rate K_m(f) is that of R_ref): the same residual as ``rd`` [CumWong2005, sec. 7.4-7.6],
  with its own R_ref (``reference_range_m``, default the middle of the closest ranges the raw window
  images, (R_near + R_far cos(theta)) / 2).
- ``omegak`` (knobs ``stolt``, ``stolt_kernel``, ``stolt_oversample``) with ``stolt = "full"``: the
  Stolt mapping x -> sqrt((f0 + x)^2 - a^2) - f0 is exact
  for a straight track at V_ref [Cafforio1991; Bamler1992]: no residual on a linear track; on an
  orbit V varies with range, ``dPhi = -(4 pi R0 / c) [g(x, f; V(R0)) - g(x, f; V_ref)]``
  [CumWong2005, sec. 8.3.4]. The interpolation kernel adds a complex error of relative size
  ``eps_L`` (:func:`kernel_error`: RMS over the band |nu| <= 1 / (2 stolt_oversample)), a floor.
  ``stolt = "monochromatic"``: the differential Stolt replaced by its first-order term [CumWong2005,
  sec. 8.4] on RD's RCMC kernel and SRC: the residual of ``rd`` (bench_omegak measured the two
  alike to 1e-4 rad at 0-40 deg).
- ``backprojection``: exact (the sum over pulses along the true track); the linear interpolation of
  range lines upsampled U times weights the range band by sinc^2(x / (U fs)).
- ``ffbp`` [UlaHelSte2003] (knobs of ``sarcli.focus.ffbp``: ``base`` pulses per subaperture and merge,
  angular ``oversample`` beta, ``order`` / ``range_order`` interpolation taps): no systematic phase;
  each of the S merge stages and the last one interpolates once in angle and once in range, with the
  error of interpolating exp(j 2 pi nu x), |nu| <= 1/(2 beta): (pi / beta)^2 / 8 for linear, 1 /
  cosh(pi (1 - 1/beta) N / 2) for an N-tap Knab-windowed sinc; coherent at a peak, the bound
  ``(S + 1) (e_order(beta) + e_range_order(U))`` is a worst case (the whole spectrum at the band
  edge; the windows weight the edges down): the floor is ``FFBP_BOUND_FRACTION`` (5 %) of it, 5 times
  what was measured (:data:`FFBP_BOUND_FRACTION`).

A floor (a complex error of RMS eps relative to the peak, spread over the image, not a phase law)
moves the peak phase by up to asin(eps); spread over the ~10 cells of a cut's sidelobe region it
raises the largest sidelobe s (amplitude, relative to the peak) to at most s + eps / sqrt(10): PSLR
change ``20 log10(1 + eps / (sqrt(10) s))``; the IRW does not change to first order. (Floors are the
coarsest models here: they bound what an interpolation leaves, and the map checks them.)

What the models leave out is said where it matters: the hyperbolic model of an orbit (the RD's
orbit-timing correction is exact in time and phase, the residual range-history curvature is below
1e-3 rad for apertures under 5 s, ``bench_focus``), block processing (bit-exact), float32 rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from sarcli.errors import ConfigError, SarcliError
from sarcli.focus.rangecomp import C
from sarcli.focus.windows import window

#: knob settings considered per algorithm, cheapest first within an algorithm. Settings of an algorithm
#: that is not registered, or whose Options lack a knob, are skipped with a note (the report says which).
KNOB_SETTINGS: dict[str, list[dict[str, Any]]] = {
    "rd": [{}],
    "csa": [{}],
    "omegak": [{"stolt": "monochromatic"}, {"stolt": "full", "stolt_kernel": "sinc8"},
               {"stolt": "full", "stolt_kernel": "sinc16"}],
    "ffbp": [{"base": 4, "oversample": 2.0, "order": 2, "range_order": 2},
             {"base": 4, "oversample": 2.0, "order": 6, "range_order": 6},
             {"base": 4, "oversample": 3.0, "order": 8, "range_order": 8}],
    "backprojection": [{}],
}

#: predicted cost, in units of two ``scipy.fft.fft2`` of the raw block (n_lines x n_samples, complex64),
#: per algorithm. ``rd`` and ``backprojection``: measured by bench/bench_focus_family.py (see
#: docs/focusing.md); the others are operation counts relative to the RDA [CumWong2005, sec. 7.7,
#: 8.5; UlaHelSte2003, sec. IV] until the map measures them after they are registered.
COST_RD = 3.1  # whole RD focus / two fft2 (bench_focus_family, median over its 16 scenes; 1.5-6.2 on a loaded machine)
# csa and omegak: their own benchmarks' ratio to rd on the same 1536 x 2048 block in the same run
# (bench_csa: 1.28; bench_omegak: monochromatic 1.58, full Stolt 5.4 with sinc8 or sinc16: its longer
# range FFT, not the kernel, dominates), until the map measures them on its scenes
COST_CSA = 1.28 * COST_RD
COST_OMEGAK_MONO = 1.58 * COST_RD
COST_OMEGAK_FULL = 5.4 * COST_RD
#: backprojection: seconds per (pixel x aperture line) over seconds per (sample x log2 samples) of two fft2
COST_BP = 35.0  # bench_focus_family: the exact kernel over its aperture, extrapolated to the block (35-57 in 3 runs)
#: ffbp: one interpolation tap of a merge against one exact backprojection term (the float32 kernel),
#: from GOTCHA pass 1 HH in bench_gotcha (27 Nov 21:51, same run, best of 5): ffbp with the default knobs
#: 0.476 s against the float32 backprojection's 0.609 s over 469 pulses, i.e. 367 backprojection terms
#: per pixel for the model's (S + 1) base beta U taps = 5 x 4 x 2 x 2 x 36 = 2880 taps; on bench_ffbp's
#: stripmap scene (710 aperture lines) the model then predicts 1.9x and 2.3x was measured. The product of
#: the taps stands for the last stage's 2-D interpolation; the merges cost about order + range_order plus a
#: fixed part (the along-ray merge), so the model takes coarser kernels for cheaper than they are (4 x 4
#: taps: 0.80-0.85x the defaults' time in bench_ffbp, predicted 0.44x): to be re-measured by the map
COST_FFBP_TAP = 367.0 / 2880.0
#: the 2 fft2 time per (sample x log2 samples) on the bench machine (s): predicted seconds for the report
SECONDS_2FFT2 = 4.0e-9  # bench_focus_family on the shared 2-core machine (1.6e-9 unloaded, bench_focus)
#: on an ORBIT, the largest |squint| (deg) at which the map validated the hyperbolic-model focusers: beyond
#: it the orbit's range history departs from the hyperbola over the beam offset R0 tan(theta) / V (21 s at
#: 10 deg from 850 km) and the RDA showed a range offset of 0.38 pixel and 1.8 rad of peak phase at 10 deg
#: (C band) that the spectral phase models do not hold; ``auto`` does not rely on them there
#: (docs/focusing.md). At 5 deg the C-band orbit scenes met the quality but the X-band ones did not (0.15 rad
#: of peak phase against 0.004 predicted); that departure grows with the square of the beam offset, i.e. of
#: tan(theta), so 3 deg leaves (3/5)^2 x 0.15 = 0.054 rad, within the 0.1 rad bar with margin. On a straight
#: line the hyperbola is exact: no limit.
VALIDATED_SQUINT_DEG = {"rd": 3.0, "csa": 3.0, "omegak": 3.0}


@dataclass(frozen=True)
class Quality:
    """The stated quality: |IRW / ideal - 1| <= irw, |PSLR - ideal| <= pslr_db (dB), |peak phase error|
    <= phase_rad, in range and azimuth; ``max_seconds``: the predicted time beyond which a candidate
    is not "reasonable" (auto refuses rather than start it)."""

    irw: float = 0.02
    pslr_db: float = 1.0
    phase_rad: float = 0.1
    max_seconds: float = 3600.0

    @classmethod
    def parse(cls, text: str | None) -> Quality:
        """``"irw=0.02,pslr=1,phase=0.1"`` (any subset; ``time=SECONDS`` too); None or "": defaults."""
        keys = {"irw": "irw", "pslr": "pslr_db", "phase": "phase_rad", "time": "max_seconds"}
        out: dict[str, float] = {}
        for item in (text or "").split(","):
            if not item.strip():
                continue
            k, eq, v = item.partition("=")
            k = k.strip().lower()
            if not eq or k not in keys:
                raise ConfigError(f"--quality {item.strip()!r}: expected irw=, pslr=, phase= or time= "
                                  "(e.g. irw=0.02,pslr=1,phase=0.1)")
            try:
                val = float(v)
            except ValueError:
                raise ConfigError(f"--quality {k}={v.strip()!r} is not a number") from None
            if not (math.isfinite(val) and val > 0):
                raise ConfigError(f"--quality {k} must be a positive number, got {v.strip()}")
            out[keys[k]] = val
        return cls(**out)


@dataclass(frozen=True)
class Geometry:
    """What the error and cost models need of a scene (SI units; frequencies in Hz).

    carrier_hz f0; range_bandwidth_hz B (processed); range_sampling_hz fs; prf_hz; azimuth_bandwidth_hz
    Ba (processed); fdc_hz (mid-swath centroid, absolute); velocity_mps V (mid-swath effective);
    dv_dr (dV/dR0, 1/s: 0 on a linear track); r_near_m, r_far_m (closest ranges of the first and
    last column); track "orbit" | "linear"; n_lines, n_samples (raw block); aperture_lines (of the
    processed band); range_window, azimuth_window (window specs); exposure_bandwidth_hz: the Doppler
    band the echo holds at the carrier (default: the PRF).
    """

    carrier_hz: float
    range_bandwidth_hz: float
    range_sampling_hz: float
    prf_hz: float
    azimuth_bandwidth_hz: float
    fdc_hz: float
    velocity_mps: float
    dv_dr: float
    r_near_m: float
    r_far_m: float
    track: str
    n_lines: int
    n_samples: int
    aperture_lines: float
    range_window: str = "kaiser:2.5"
    azimuth_window: str = "kaiser:2.5"
    exposure_bandwidth_hz: float | None = None

    @property
    def exposure_hz(self) -> float:
        """The Doppler band the echo holds (the antenna's): given, else the PRF (the widest unaliased)."""
        return self.exposure_bandwidth_hz or self.prf_hz

    @property
    def wavelength_m(self) -> float:
        return C / self.carrier_hz

    @property
    def r_mid_m(self) -> float:
        return 0.5 * (self.r_near_m + self.r_far_m)

    @property
    def squint_deg(self) -> float:
        s = -self.fdc_hz * self.wavelength_m / (2.0 * self.velocity_mps)
        return math.degrees(math.asin(max(-1.0, min(1.0, s))))

    @property
    def relative_bandwidth(self) -> float:
        return self.range_bandwidth_hz / self.carrier_hz

    def describe(self) -> dict[str, Any]:
        """The geometry as the report gives it."""
        return {"carrier_hz": self.carrier_hz, "squint_deg": self.squint_deg, "track": self.track,
                "relative_bandwidth": self.relative_bandwidth, "range_bandwidth_hz": self.range_bandwidth_hz,
                "azimuth_bandwidth_hz": self.azimuth_bandwidth_hz, "velocity_mps": self.velocity_mps,
                "closest_range_m": [self.r_near_m, self.r_far_m], "aperture_lines": self.aperture_lines,
                "block": [self.n_lines, self.n_samples]}


def geometry_of(raw, shape: tuple[int, int], doppler, options: dict[str, Any] | None = None) -> Geometry:
    """The :class:`Geometry` of a raw product with a Doppler model, as the stripmap focusers will see it
    (the RD output grid of :func:`sarcli.focus.rda.plan_grid`, the model at the scene's centre time).
    ``options``: the user's focuser options (windows, bands) where given."""
    from sarcli.focus.rangecomp import chirp_band
    from sarcli.focus.rda import doppler_on_grid, plan_grid

    o = dict(options or {})
    grid = plan_grid(raw, shape, doppler, o.get("azimuth_bandwidth_hz"))
    tc = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
    r = grid.ranges[[0, grid.ranges.size // 2, -1]]
    fdc, _, v, _ = doppler_on_grid(doppler, r, tc, grid.wavelength)
    span = float(r[-1] - r[0])
    dv_dr = float((v[-1] - v[0]) / span) if span > 0 else 0.0
    track = "linear" if raw.orbit is None or raw.orbit.frame == "LOCAL" else "orbit"
    radar = raw.radar
    return Geometry(carrier_hz=radar.carrier_frequency_hz,
                    range_bandwidth_hz=chirp_band(radar) * float(o.get("range_bandwidth_fraction", 1.0)),
                    range_sampling_hz=radar.range_sampling_rate_hz, prf_hz=grid.prf, azimuth_bandwidth_hz=grid.ba,
                    fdc_hz=float(fdc[1]), velocity_mps=float(v[1]), dv_dr=dv_dr, r_near_m=float(r[0]),
                    r_far_m=float(r[-1]), track=track, n_lines=int(shape[0]), n_samples=int(shape[1]),
                    aperture_lines=float(grid.aperture), range_window=str(o.get("range_window", "kaiser:2.5")),
                    azimuth_window=str(o.get("azimuth_window", "kaiser:2.5")))


# ----------------------------------------------------------------------------------------- error models

def _g(x: np.ndarray, f: np.ndarray, f0: float, v: float) -> np.ndarray:
    a2 = (C * f / (2.0 * v)) ** 2
    return np.sqrt((f0 + x) ** 2 - a2)


def beyond_first_order(x: np.ndarray, f: np.ndarray, f0: float, v: float) -> np.ndarray:
    """H(x, f) = g - g0 - x f0 / g0 (Hz), written so that it does not cancel: g - g0 = (2 f0 x + x^2) /
    (g + g0)."""
    g0 = _g(np.zeros_like(x), f, f0, v)
    g = _g(x, f, f0, v)
    return (2.0 * f0 * x + x * x) / (g + g0) - x * f0 / g0


def kernel_error(name: str, band_fraction: float) -> float:
    """eps_L: the RMS of |interpolated - exact| of a unit phasor over the frequencies |nu| <=
    ``band_fraction`` cycles per sample and the fractional shifts, for the project's interpolator
    ``name`` (:func:`sarcli.focus.interp.parse_interpolator`: linear, sinc4/8/16)."""
    from sarcli.focus.interp import parse_interpolator, sinc_weights

    kind, taps = parse_interpolator(name)
    mu = np.linspace(0.0, 1.0, 33)
    if kind == 2:
        w = sinc_weights(int(taps), mu)
        k = np.arange(-(taps // 2 - 1), taps // 2 + 1)
    else:  # linear (nearest counted as linear: the coarsest the project's Stolt offers)
        w = np.stack([1.0 - mu, mu], -1)
        k = np.arange(2)
    nu = np.linspace(-band_fraction, band_fraction, 33)
    got = np.einsum("mk,mkn->mn", w, np.exp(2j * np.pi * nu[None, None, :] * (k[None, :, None] - mu[:, None, None])))
    return float(np.sqrt(np.mean(np.abs(got - 1.0) ** 2)))


def ffbp_kernel_error(taps: int, oversample: float) -> float:
    """The largest error of interpolating exp(j 2 pi nu x), |nu| <= 1 / (2 beta), with FFBP's kernels
    [UlaHelSte2003; Knab's prolate-windowed sinc]: (pi / beta)^2 / 8 for 2 taps (linear), 1 / cosh(pi v N
    / 2) with v = 1 - 1 / beta for N >= 4 taps."""
    if taps <= 2:
        return (math.pi / oversample) ** 2 / 8.0
    return 1.0 / math.cosh(math.pi * (1.0 - 1.0 / oversample) * taps / 2.0)


def ffbp_stages(n_aperture: float, base: int) -> int:
    """Merge stages S from subapertures of ``base`` pulses to the synthetic aperture of ``n_aperture``."""
    return max(1, math.ceil(math.log(max(n_aperture / max(base, 2), 2.0)) / math.log(max(base, 2))))


#: the part of the worst-case bound that FFBP's error is taken to be: the bound assumes the whole spectrum
#: at the band edge, coherent over the stages; measured with the ffbp focuser on the map's airborne X
#: band scene (10 deg, 150 MHz, default knobs) the peak phase error was 0.0022 rad against a bound of
#: 0.22 (1 %) and the PSLR change 0.26 dB: 5 % keeps a 5x margin (to be re-measured by the map)
FFBP_BOUND_FRACTION = 0.05


def ffbp_floor(n_aperture: float, knobs: dict[str, Any], range_oversample: float = 2.0) -> float:
    """FFBP_BOUND_FRACTION x the bound (S + 1) (e_order(beta) + e_range_order(U)): every merge and the
    last stage interpolate once in angle (``order`` taps at the angular oversampling beta) and in range
    (``range_order`` taps at U = ``range_oversample``), coherent at a scatterer's peak [UlaHelSte2003]
    (module docstring)."""
    base = int(knobs.get("base", 4))
    s = ffbp_stages(n_aperture, base)
    e = ffbp_kernel_error(int(knobs.get("order", 6)), float(knobs.get("oversample", 2.0)))
    e += ffbp_kernel_error(int(knobs.get("range_order", 6)), float(knobs.get("range_oversample", range_oversample)))
    return FFBP_BOUND_FRACTION * (s + 1) * e


def residual_phase(algorithm: str, knobs: dict[str, Any], geom: Geometry, r0: float, x: np.ndarray,
                   f: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(residual phase rad, amplitude weight, floor eps) of ``algorithm`` at closest range ``r0`` on the
    2-D band grid (x baseband range frequency, f absolute azimuth frequency): module docstring."""
    f0, v, r_ref = geom.carrier_hz, geom.velocity_mps, geom.r_mid_m
    zero = np.zeros(np.broadcast(x, f).shape)
    amp = np.ones_like(zero)
    v0 = v + geom.dv_dr * (r0 - r_ref)  # the target's own effective velocity
    mono = algorithm == "omegak" and knobs.get("stolt", "full") == "monochromatic"
    if algorithm in ("rd", "csa") or mono:
        if algorithm == "csa":  # its R_ref: the middle of the closest ranges the raw window images
            cos = math.cos(math.radians(geom.squint_deg))
            r_ref = float(knobs.get("reference_range_m") or 0.5 * (geom.r_near_m + geom.r_far_m * cos))
        # SRC at R_ref with the velocity there (the RDA's mid-swath V)
        g0r = _g(np.zeros_like(x), f, f0, v)
        a2r = (C * f / (2.0 * v)) ** 2
        dphi = -(4.0 * np.pi / C) * (r0 * beyond_first_order(x, f, f0, v0) + r_ref * a2r * x * x / (2.0 * g0r**3))
        return dphi + zero, amp, 0.0
    if algorithm == "omegak":
        dphi = -(4.0 * np.pi * r0 / C) * (_g(x, f, f0, v0) - _g(x, f, f0, v)) if v0 != v else zero.copy()
        eps = kernel_error(str(knobs.get("stolt_kernel", "sinc16")), 0.5 / float(knobs.get("stolt_oversample", 2.0)))
        return dphi + zero, amp, eps
    if algorithm == "backprojection":
        up = int(knobs.get("upsample", 8))
        amp = amp * np.sinc(x / (up * geom.range_sampling_hz)) ** 2
        return zero, amp, 0.0
    if algorithm == "ffbp":
        eps = ffbp_floor(geom.aperture_lines, knobs)
        return zero, amp, eps
    raise SarcliError(f"no error model for focuser {algorithm!r}")


N_BAND = 80  # band samples per axis: the model IRF repeats every 80 resolution cells, beyond its chip
CHIP = 64  # model image chip (pixels per side), as the map's backprojected windows
SPREAD_CELLS = 10  # cells per cut over which a floor's energy is spread (module docstring)


def model_chip(geom: Geometry, spec: np.ndarray, x: np.ndarray, f: np.ndarray) -> np.ndarray:
    """The image of a point target at the chip centre, on the focusers' grid (closest range step
    c / (2 fs), zero-Doppler time step 1 / PRF), of the 2-D spectrum ``spec`` (N_az x N_rg on absolute
    azimuth frequencies ``f`` and range frequencies ``x``: windows, support and residual phase):

        I(dR, dt) = sum_f exp(2 pi j f dt) sum_x spec(x, f) exp((4 pi j / c) (g(x, f) - f0) dR)

    i.e. the exact spectrum's own coordinates (the Stolt variable 2 g / c is the closest range's
    wavenumber), so that the squint's shear of the IRF (range offsets dR seen at azimuth offsets
    -dR tan(theta) / V) and the SLC's carriers are those of the focused images the map measures."""
    half = CHIP // 2
    dr = (np.arange(CHIP) - half) * C / (2.0 * geom.range_sampling_hz)
    dt = (np.arange(CHIP) - half) / geom.prf_hz
    g = _g(x[None, :], f[:, None], geom.carrier_hz, geom.velocity_mps) - geom.carrier_hz  # (N_az, N_rg)
    a = np.einsum("fx,fxr->fr", spec, np.exp((4j * np.pi / C) * g[:, :, None] * dr[None, None, :]))
    return np.exp(2j * np.pi * dt[:, None] * f[None, :]) @ a  # (CHIP az, CHIP rg)


def supports(geom: Geometry, x: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(angular, frequency) weighted supports of the 2-D band (N_az x N_rg).

    A pulse sees a target at one angle, i.e. one Doppler f_c at the carrier; at range frequency x its
    azimuth frequency is f_c (1 + x / f0). Backprojection windows the pulses by f_c (the angular
    support, the ideal): W_r(x / B) W_a((f / (1 + x / f0) - fdc) / Ba). A frequency-domain focuser
    windows f at every x: W_r W_a((f - fdc) / Ba) times the echo's exposure |f / (1 + x / f0) - fdc|
    <= exposure / 2: when the band's shear |fdc| B / (2 f0) exceeds the margin (exposure - Ba) / 2,
    part of its window sees no echo (wide relative bandwidth at squint)."""
    ang = f[:, None] / (1.0 + x[None, :] / geom.carrier_hz) - geom.fdc_hz
    wr = window(geom.range_window, x / geom.range_bandwidth_hz)[None, :]
    ideal = wr * window(geom.azimuth_window, ang / geom.azimuth_bandwidth_hz)
    exposed = np.abs(ang) <= 0.5 * geom.exposure_hz
    freq = wr * window(geom.azimuth_window, (f - geom.fdc_hz) / geom.azimuth_bandwidth_hz)[:, None] * exposed
    return ideal, freq


def chip_quality(geom: Geometry, chip: np.ndarray) -> dict[str, float]:
    """:func:`sarcli.focus.quality.point_target_metrics` of a model chip (target near its centre)."""
    from sarcli.focus.quality import point_target_metrics

    h = CHIP // 2
    return point_target_metrics(chip, h, h, half=h, azimuth_carrier=geom.fdc_hz / geom.prf_hz)


_IDEAL: dict[tuple, dict[str, float]] = {}


def _ideal(geom: Geometry, ideal: np.ndarray, x: np.ndarray, f: np.ndarray) -> dict[str, float]:
    """The error-free chip's metrics (kept per geometry: every candidate compares with it)."""
    key = (geom.range_window, geom.azimuth_window, geom.range_bandwidth_hz, geom.azimuth_bandwidth_hz,
           geom.fdc_hz, geom.carrier_hz, geom.velocity_mps, geom.range_sampling_hz, geom.prf_hz, x.size, f.size)
    if key not in _IDEAL:
        if len(_IDEAL) > 64:
            _IDEAL.clear()
        _IDEAL[key] = chip_quality(geom, model_chip(geom, ideal.astype(complex), x, f))
    return _IDEAL[key]


def irf_errors(geom: Geometry, spec: np.ndarray, eps: float, ideal: np.ndarray, x: np.ndarray,
               f: np.ndarray) -> dict[str, float]:
    """IRW/PSLR change, peak phase and position error of the model chip (:func:`model_chip`) of the
    spectrum ``spec`` with floor ``eps`` against the ideal one (the angular support without error),
    measured as the map measures focused images (:func:`chip_quality`); the floor adds asin(eps) to
    the phase and 20 log10(1 + eps / (sqrt(SPREAD_CELLS) s)) to the PSLR."""
    ref = _ideal(geom, ideal, x, f)
    m = chip_quality(geom, model_chip(geom, spec, x, f))
    s_r, s_a = (10 ** (ref[k] / 20) * math.sqrt(SPREAD_CELLS) for k in ("pslr_range_db", "pslr_azimuth_db"))
    return {"irw_range": m["irw_range_px"] / ref["irw_range_px"] - 1.0,
            "irw_azimuth": m["irw_azimuth_px"] / ref["irw_azimuth_px"] - 1.0,
            "pslr_range_db": m["pslr_range_db"] - ref["pslr_range_db"] + 20 * math.log10(1 + eps / s_r),
            "pslr_azimuth_db": m["pslr_azimuth_db"] - ref["pslr_azimuth_db"] + 20 * math.log10(1 + eps / s_a),
            "phase_rad": abs(float(np.angle(np.exp(1j * (m["peak_phase_rad"] - ref["peak_phase_rad"])))))
            + math.asin(min(eps, 1.0)),
            "range_shift_m": (m["col"] - ref["col"]) * C / (2.0 * geom.range_sampling_hz),
            "azimuth_shift_s": (m["row"] - ref["row"]) / geom.prf_hz}


TIME_DOMAIN = ("backprojection", "ffbp")  # algorithms that window by angle (the ideal support)


def predict(algorithm: str, knobs: dict[str, Any], geom: Geometry,
            ranges: tuple[float, ...] | None = None) -> dict[str, float]:
    """Predicted errors of ``algorithm`` with ``knobs`` on ``geom``: the worst over targets at the
    closest ranges ``ranges`` (default: near, middle and far of the swath; module docstring). Keys:
    irw (largest |IRW change|, fraction), pslr_db (largest |PSLR change|), phase_rad, position_m
    (largest shift, range and azimuth in m on the ground track), each the worst over the ranges; and
    the signed per-axis IRW and PSLR changes (irw_range, irw_azimuth, pslr_range_db,
    pslr_azimuth_db) at the first range."""
    # azimuth frequencies on midpoints of N_BAND cells across the processed band (its edges between
    # samples: no cell half in, half out), plus whole cells either side for the shear |fdc| B / (2 f0)
    df = geom.azimuth_bandwidth_hz / N_BAND
    extra = int(math.ceil(0.5 * abs(geom.fdc_hz) * geom.relative_bandwidth / df)) + 1
    f = geom.fdc_hz + (np.arange(-extra, N_BAND + extra) + 0.5 - 0.5 * N_BAND) * df
    x = ((np.arange(N_BAND) + 0.5) / N_BAND - 0.5) * geom.range_bandwidth_hz
    ideal, freq = supports(geom, x, f)
    support = ideal if algorithm in TIME_DOMAIN else freq
    worst: dict[str, float] = {}
    for r0 in ranges or (geom.r_near_m, geom.r_mid_m, geom.r_far_m):
        dphi, amp, eps = residual_phase(algorithm, knobs, geom, r0, x[None, :], f[:, None])
        e = irf_errors(geom, support * amp * np.exp(1j * dphi), eps, ideal, x, f)
        pos = math.hypot(e["range_shift_m"], e["azimuth_shift_s"] * geom.velocity_mps)
        cur = {"irw": float(max(abs(e["irw_range"]), abs(e["irw_azimuth"]))),
               "pslr_db": float(max(abs(e["pslr_range_db"]), abs(e["pslr_azimuth_db"]))),
               "phase_rad": float(e["phase_rad"]), "position_m": float(pos),
               "irw_range": float(e["irw_range"]), "irw_azimuth": float(e["irw_azimuth"]),
               "pslr_range_db": float(e["pslr_range_db"]), "pslr_azimuth_db": float(e["pslr_azimuth_db"])}
        if not worst:
            limit = VALIDATED_SQUINT_DEG.get(algorithm) if geom.track == "orbit" else None
            # + 0.25 deg: a nominal 5-deg scene of the map is 5.0001 deg by its mid-swath velocity
            cur["validated"] = limit is None or abs(geom.squint_deg) <= limit + 0.25
            worst = cur
        else:
            for k in ("irw", "pslr_db", "phase_rad", "position_m"):
                worst[k] = max(worst[k], cur[k])
    return worst


def meets(pred: dict[str, Any], q: Quality) -> bool:
    """The prediction meets the quality (and lies where the map validated the model)."""
    return (bool(pred.get("validated", True)) and pred["irw"] <= q.irw and pred["pslr_db"] <= q.pslr_db
            and pred["phase_rad"] <= q.phase_rad)


# ------------------------------------------------------------------------------------------- cost models

def predicted_cost(algorithm: str, knobs: dict[str, Any], geom: Geometry) -> float:
    """Predicted time in units of two ``fft2`` of the raw block (module constants; docs/focusing.md)."""
    log_n = math.log2(max(geom.n_lines * geom.n_samples, 2))
    if algorithm == "rd":
        return COST_RD
    if algorithm == "csa":
        return COST_CSA
    if algorithm == "omegak":
        return COST_OMEGAK_MONO if knobs.get("stolt", "full") == "monochromatic" else COST_OMEGAK_FULL
    if algorithm == "backprojection":
        return COST_BP * geom.aperture_lines / log_n
    if algorithm == "ffbp":
        base = int(knobs.get("base", 4))
        taps = int(knobs.get("order", 6)) * int(knobs.get("range_order", 6))
        per_pixel = (ffbp_stages(geom.aperture_lines, base) + 1) * base * float(knobs.get("oversample", 2.0)) * \
            float(knobs.get("range_oversample", 2.0)) * taps * COST_FFBP_TAP
        return COST_BP * per_pixel / log_n
    raise SarcliError(f"no cost model for focuser {algorithm!r}")


def seconds_of(units: float, geom: Geometry) -> float:
    """Predicted seconds of a cost in two-fft2 units on the bench machine (:data:`SECONDS_2FFT2`)."""
    n = geom.n_lines * geom.n_samples
    return units * SECONDS_2FFT2 * n * math.log2(max(n, 2))


# ------------------------------------------------------------------------------------------- selection

@dataclass
class Selection:
    """The choice (``algorithm`` None: nothing meets the quality in reasonable time) and every candidate."""

    algorithm: str | None
    knobs: dict[str, Any]
    quality: Quality
    geometry: Geometry
    candidates: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        chosen = next((c for c in self.candidates if c.get("chosen")), None)
        return {"algorithm": self.algorithm, "knobs": self.knobs,
                "quality": {"irw": self.quality.irw, "pslr_db": self.quality.pslr_db,
                            "phase_rad": self.quality.phase_rad, "max_seconds": self.quality.max_seconds},
                "geometry": self.geometry.describe(),
                "predicted": chosen["predicted"] if chosen else None,
                "alternatives": [c for c in self.candidates if not c.get("chosen")], "skipped": self.skipped}

    def refusal(self) -> str:
        """The one-line reason nothing was chosen: the fastest candidate that meets the quality (too
        slow), else the most accurate one."""
        g = self.geometry
        msg = (f"no registered focuser meets the quality (IRW {self.quality.irw:g}, PSLR {self.quality.pslr_db:g} dB, "
               f"phase {self.quality.phase_rad:g} rad) within {self.quality.max_seconds:g} s on this geometry "
               f"(squint {g.squint_deg:.1f} deg, {g.carrier_hz / 1e9:.2f} GHz, B/f0 {g.relative_bandwidth:.3f})")
        meeting = [c for c in self.candidates if c["meets_quality"]]
        if meeting:
            c = min(meeting, key=lambda c: c["seconds"])
            return msg + (f"; the fastest that meets it, {c['algorithm']}, is predicted to take about "
                          f"{c['seconds']:.3g} s: raise time= in --quality, or choose it with --algorithm")
        best = min(self.candidates, key=lambda c: (c["predicted"]["phase_rad"], c["cost"]), default=None)
        if best is not None:
            p = best["predicted"]
            msg += (f"; the most accurate, {best['algorithm']}, predicts phase {p['phase_rad']:.2g} rad, IRW "
                    f"{p['irw']:.2%}, PSLR {p['pslr_db']:.2g} dB in about {best['seconds']:.3g} s: choose it with "
                    "--algorithm, or relax --quality")
        return msg


def _options_fields(focuser) -> set[str]:
    return {f.name for f in fields(focuser.Options)}


def choose(geom: Geometry, quality: Quality | None = None, registered: list[str] | None = None) -> Selection:
    """The cheapest (algorithm, knobs) of :data:`KNOB_SETTINGS` among ``registered`` focusers (default:
    those of :data:`sarcli.focus.FOCUSERS`) whose predicted errors meet ``quality`` and whose predicted
    time is at most ``quality.max_seconds``."""
    from sarcli.focus import FOCUSERS

    q = quality or Quality()
    names = list(registered) if registered is not None else list(FOCUSERS.names())
    sel = Selection(None, {}, q, geom)
    for alg, settings in KNOB_SETTINGS.items():
        if alg not in names:
            sel.skipped.append(f"{alg}: not registered")
            continue
        known = None
        if registered is None:
            try:
                known = _options_fields(FOCUSERS.get(alg))
            except Exception as e:  # noqa: BLE001 - a broken plug-in is skipped, not fatal
                sel.skipped.append(f"{alg}: cannot load ({e})")
                continue
        for knobs in settings:
            if known is not None and not set(knobs) <= known:
                sel.skipped.append(f"{alg} {knobs}: its Options lack {sorted(set(knobs) - known)}")
                continue
            pred = predict(alg, knobs, geom)
            units = predicted_cost(alg, knobs, geom)
            sel.candidates.append({"algorithm": alg, "knobs": dict(knobs), "cost": units,
                                   "seconds": seconds_of(units, geom),
                                   "predicted": {k: pred[k] for k in ("irw", "pslr_db", "phase_rad", "position_m",
                                                                      "validated")},
                                   "meets_quality": meets(pred, q)})
    for other in names:
        if other not in KNOB_SETTINGS:
            sel.skipped.append(f"{other}: no error model")
    ok = [c for c in sel.candidates if c["meets_quality"] and c["seconds"] <= q.max_seconds]
    if ok:
        best = min(ok, key=lambda c: c["cost"])
        best["chosen"] = True
        sel.algorithm, sel.knobs = best["algorithm"], dict(best["knobs"])
    sel.candidates.sort(key=lambda c: c["cost"])
    return sel


def choose_for(raw, shape: tuple[int, int], doppler, options: dict[str, Any] | None = None,
               quality: Quality | None = None) -> Selection:
    """:func:`choose` on the geometry of a raw product and its Doppler model (:func:`geometry_of`)."""
    return choose(geometry_of(raw, shape, doppler, options), quality)


def window_pslr(spec: str) -> float:
    """Peak sidelobe (amplitude relative to the peak) of a window's IRF (:mod:`sarcli.focus.windows`
    spec; a spec it does not parse counts as Kaiser 2.5)."""
    from sarcli.focus.windows import parse_window

    try:
        parse_window(spec)
    except SarcliError:
        spec = "kaiser:2.5"
    n = 256
    w = window(spec, ((np.arange(n) + 0.5) / n - 0.5))
    irf = np.abs(np.fft.fft(np.r_[w, np.zeros(15 * n)]))
    irf /= irf[0]
    i = 1
    while irf[i + 1] < irf[i]:
        i += 1
    return float(irf[i:irf.size // 2].max())


def gbsar_near(n_stops: int, available: tuple[str, ...], azimuth_window: str = "kaiser:2.5",
               quality: Quality | None = None, knobs: dict[str, Any] | None = None) -> tuple[str, dict[str, Any]]:
    """GB-SAR ``auto``'s near-range algorithm (below the Deramp-FFT limit, :mod:`sarcli.gbsar.focus`):
    ``ffbp`` when ``available`` has it and the cheapest knob setting of ``KNOB_SETTINGS["ffbp"]`` whose
    floor (:func:`ffbp_floor` over ``n_stops`` stops) meets ``quality`` (phase asin(eps), PSLR change
    20 log10(1 + eps / (sqrt(10) s)) for the window's sidelobe s) is predicted cheaper than
    backprojection (per pixel F k n (p + 1) against n_stops); otherwise ``bp``. Returns (name, the
    report's entry: the knobs the GB-SAR ffbp is to use, the predicted errors, the costs). ``knobs``:
    the GB-SAR ffbp's own knobs where it has them (then only those are considered)."""
    q = quality or Quality()
    if "ffbp" not in available:
        return "bp", {"near": "bp", "why": "ffbp is not available"}
    s = window_pslr(azimuth_window)
    best = None
    for setting in [knobs] if knobs is not None else KNOB_SETTINGS["ffbp"]:
        eps = ffbp_floor(float(n_stops), setting)
        phase = math.asin(min(eps, 1.0))
        pslr = 20 * math.log10(1 + eps / (math.sqrt(SPREAD_CELLS) * s))
        base = int(setting.get("base", 4))
        cost = (ffbp_stages(n_stops, base) + 1) * base * float(setting.get("oversample", 2.0)) * \
            float(setting.get("range_oversample", 2.0)) * int(setting.get("order", 6)) * \
            int(setting.get("range_order", 6)) * COST_FFBP_TAP
        if phase <= q.phase_rad and pslr <= q.pslr_db and cost < n_stops and (best is None or cost < best[0]):
            best = (cost, dict(setting), {"phase_rad": phase, "pslr_db": pslr, "irw": 0.0})
    if best is None:
        return "bp", {"near": "bp", "why": f"no ffbp setting is predicted to meet the quality and cost less than "
                                           f"backprojection over {n_stops} stops"}
    return "ffbp", {"near": "ffbp", "ffbp_knobs": best[1], "ffbp_predicted": best[2],
                    "cost_per_pixel": {"ffbp": best[0], "bp": float(n_stops)}}
