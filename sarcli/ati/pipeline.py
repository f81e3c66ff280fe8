"""End-to-end ATI processing of a two-channel raw product: focus, detect, estimate, compensate.

Geometry: the raw product must come from a straight, level flight in the LOCAL frame (x cross-track
ground range, +x on the right of the +y flight direction, z up), i.e. the simulator's ``linear``
platform: height H and speed Vp from its state vectors. The reference time of every estimate is the
scene centre ``t_ref`` (mid azimuth time); positions are reported in the LOCAL frame at ``t_ref``
(the platform at (x_p, y_p(t_ref), H)) and relative to it (x0, y0 of geometry.py).

Focusing reuses ``sarcli.focus.rda.focus_rd`` on each channel with the geometric broadside Doppler
model of the straight flight and the FULL azimuth band (a mover's Doppler is shifted by -2*vm/lam
and would be clipped by a narrower band). Channel 1 is co-registered by d/(2*Vp)
(:mod:`sarcli.ati.slowtime`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sarcli.ati.detect import Candidate, CfarKnobs, bistatic_phase, detect
from sarcli.ati.estimate import Estimate, SlowTime, estimate
from sarcli.ati.geometry import Mover, Platform, coefficients, range_history, stationary_history
from sarcli.ati.slowtime import choose_bin, coregister, decompress, recompress, single_bin, track_peak
from sarcli.errors import SarcliError
from sarcli.model.raw import RawProduct

BIN_MODES = ("track", "anv")
COMPENSATIONS = ("exact", "quadratic", "conventional")


@dataclass
class Pair:
    """Co-registered two-channel SLC pair with its flat geometry."""

    slc0: object
    z0: np.ndarray
    z1: np.ndarray
    platform: Platform
    baseline_m: float
    t_ref: float
    origin_xy: tuple[float, float]
    look_sign: float
    timings: dict = field(default_factory=dict)


def flat_geometry(raw: RawProduct) -> tuple[Platform, float, tuple[float, float], float]:
    """(Platform, t_ref, platform (x, y) at t_ref, look sign) of a LOCAL straight-flight product."""
    if raw.n_channels < 2:
        raise SarcliError("ATI needs a two-channel raw product (echo_channels with receiver_offsets_m)")
    o = raw.orbit
    if o is None or o.frame != "LOCAL":
        raise SarcliError("ATI needs a straight-flight product in the LOCAL frame (simulator 'linear' platform)")
    v = np.asarray(o.velocity, np.float64)
    if np.ptp(v, axis=0).max() > 1e-6 * np.abs(v).max() or abs(v[0, 0]) > 1e-9 or abs(v[0, 2]) > 1e-9:
        raise SarcliError("ATI needs a straight, level flight along +y (LOCAL frame)")
    t = raw.azimuth_time
    t_ref = 0.5 * (float(t[0]) + float(t[-1]))
    pos = np.asarray(o.position, np.float64)
    y_ref = float(pos[0, 1] + v[0, 1] * (t_ref - float(o.time[0])))
    plat = Platform(float(pos[0, 2]), float(v[0, 1]), float(raw.radar.wavelength_m))
    return plat, t_ref, (float(pos[0, 0]), y_ref), (1.0 if raw.look_side == "right" else -1.0)


def focus_pair(raw: RawProduct, **knobs) -> Pair:
    """RD-focus both channels (full azimuth band) and co-register channel 1 onto channel 0."""
    import time
    import warnings

    from sarcli.focus.rda import focus_rd
    from sarcli.model.doppler import GeometricDoppler

    plat, t_ref, origin, sign = flat_geometry(raw)
    offs = raw.radar.receiver_offsets_m
    d = float(offs[1] - offs[0])
    dop = GeometricDoppler(plat.speed, 0.0, plat.wavelength)
    kw = {"azimuth_bandwidth_hz": float(raw.radar.prf_hz), **knobs}
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*shorter than the synthetic aperture.*")
        s0 = focus_rd(raw, dop, 0, **kw)
        s1 = focus_rd(raw, dop, 1, **kw)
    t1 = time.perf_counter()
    z1 = coregister(s0, s1.image, 0.5 * d / plat.speed)
    t2 = time.perf_counter()
    return Pair(s0, s0.image, z1, plat, d, t_ref, origin, sign,
                {"focus_s": t1 - t0, "coregister_s": t2 - t1})


def detect_pair(pair: Pair, knobs: CfarKnobs = CfarKnobs()) -> tuple[list[Candidate], dict]:
    return detect(pair.z0, pair.z1, pair.slc0.azimuth_time, pair.slc0.slant_range, pair.platform,
                  pair.baseline_m, knobs)


#: sub-image margins (lines, range samples) around a detected cluster: estimation keeps few columns
#: (less clutter in the slow-time signal), compensation takes more (the smear's range sidelobes)
ESTIMATION_MARGINS = (24, 6)
COMPENSATION_MARGINS = (48, 24)


def _window(pair: Pair, c: Candidate, margins: tuple[int, int] = ESTIMATION_MARGINS) -> tuple[slice, slice]:
    n, m = pair.z0.shape
    return (slice(max(0, c.row_start - margins[0]), min(n, c.row_stop + margins[0])),
            slice(max(0, c.col_start - margins[1]), min(m, c.col_stop + margins[1])))


@dataclass
class MoverResult:
    """One mover: detection, estimate (relative and absolute LOCAL positions), sub-image window."""

    candidate: Candidate
    estimate: Estimate
    rows: slice
    cols: slice
    x_local_m: float
    y_local_m: float
    t_ref_s: float = 0.0

    def as_dict(self) -> dict:
        e = self.estimate
        out = {"id": self.candidate.id, "vx_mps": e.vx_mps, "vy_mps": e.vy_mps, "x0_m": e.x0_m, "y0_m": e.y0_m,
               "r0_m": e.r0_m, "vx_mps_sigma": e.vx_mps_sigma, "vy_mps_sigma": e.vy_mps_sigma,
               "x0_m_sigma": e.x0_m_sigma, "y0_m_sigma": e.y0_m_sigma, "r0_m_sigma": e.r0_m_sigma,
               "x_local_m": self.x_local_m, "y_local_m": self.y_local_m, "t_ref_s": self.t_ref_s,
               "vr_mps": e.vr_mps, "ar_mps2": e.ar_mps2, "route": e.route,
               "vy_degenerate": e.vy_degenerate, "ati_phase_rad": e.ati_phase_rad,
               "ati_ambiguous": e.ati_ambiguous or self.candidate.ati_ambiguous,
               "blind_speed_mps": e.blind_speed_mps, "chi2_red": e.chi2_red,
               "detection_vx_mps": self.candidate.vx_mps, "confidence": self.candidate.confidence,
               "image_azimuth_time_s": self.candidate.azimuth_time_s,
               "image_slant_range_m": self.candidate.slant_range_m}
        return out


def slow_time(pair: Pair, c: Candidate, bin_mode: str = "track") -> tuple[SlowTime, slice, slice, np.ndarray]:
    """The mover's two-channel slow-time observation (and its sub-image window and slow-time block)."""
    if bin_mode not in BIN_MODES:
        raise SarcliError(f"unknown range-bin mode {bin_mode!r}; choose one of {', '.join(BIN_MODES)}")
    rows, cols = _window(pair, c)
    s0 = decompress(pair.slc0, pair.z0, rows, cols)
    s1 = decompress(pair.slc0, pair.z1, rows, cols)
    # Range bin: the minimum ANV of [Ryu2017, eq. 12], computed on the clutter-cancelled (DPCA) signal (stationary
    # scatterers in the window also have a constant slow-time amplitude but cancel in
    # s1 - s0*exp(j*phi_c)), among the bins within +-3 of the detected peak (at low SNR the DPCA
    # signal, ~phi_ATI^2 weaker than s0, is noise-dominated away from the mover).
    ranges = np.asarray(pair.slc0.slant_range)[cols]
    phi_c = bistatic_phase(ranges, pair.baseline_m, pair.platform.wavelength)
    pk = c.peak_col - cols.start
    lo, hi = max(0, pk - 3), min(len(ranges), pk + 4)
    n0 = lo + choose_bin((s1 - s0 * np.exp(1j * phi_c)[None, :])[:, lo:hi])
    if bin_mode == "track":
        n0 = pk         # tracking starts from the detected peak and follows the mover's drift
    pick = track_peak if bin_mode == "track" else single_bin
    a0, pos = pick(s0, n0)
    a1, _ = pick(s1, n0)
    dr = float(ranges[1] - ranges[0])
    r_track = ranges[0] + pos * dr
    eta = np.asarray(pair.slc0.azimuth_time, np.float64) - pair.t_ref
    shift = int(pair.slc0.parameters.get("shift_lines", 0))
    eta = eta + shift / float(pair.slc0.parameters.get("prf_hz", pair.slc0.prf_hz))
    # 1-sigma of the mean tracked range: quantization bound dr/sqrt(12) (conservative)
    obs = SlowTime(eta, a0, a1, r_track, dr / math.sqrt(12.0), pair.platform, pair.baseline_m, pair.look_sign,
                   noise_dof=rows.stop - rows.start)
    return obs, rows, cols, s0


def estimate_mover(pair: Pair, c: Candidate, route: str = "exact", unwrap_method: str = "dechirp",
                   bin_mode: str = "track", degree: int = 4) -> MoverResult:
    obs, rows, cols, _ = slow_time(pair, c, bin_mode)
    e = estimate(obs, route, unwrap_method, degree)
    return MoverResult(c, e, rows, cols, pair.origin_xy[0] + e.x0_m, pair.origin_xy[1] + e.y0_m, pair.t_ref)


def compensation_phase(eta: np.ndarray, e: Estimate, platform: Platform, method: str = "exact") -> np.ndarray:
    """Phase (rad) of H_ph(eta) ([Ryu2017, eq. 20], our sign convention: multiply to remove Rm).

    exact:        +(4*pi/lam)*(R(eta) - Rs(eta)) with the estimated mover and the stationary point
                  at its estimated (x0, y0) (removes Rm to all orders);
    quadratic:    +(4*pi/lam)*(vm*eta + am*eta^2/2) (eq. 20 with the 1/2 of eq. 6 restored; exact vm, am);
    conventional: as quadratic with vm -> vx*x0/R0 (neglects vy*y0/R0, refs [3]-[7] of [Ryu2017]).
    """
    if method not in COMPENSATIONS:
        raise SarcliError(f"unknown compensation {method!r}; choose one of {', '.join(COMPENSATIONS)}")
    k = 4.0 * np.pi / platform.wavelength
    m = Mover(e.x0_m, e.y0_m, e.vx_mps, e.vy_mps)
    if method == "exact":
        return k * (range_history(eta, m, platform) - stationary_history(eta, e.x0_m, e.y0_m, platform))
    c = coefficients(m, platform)
    vm = c.vm if method == "quadratic" else e.vx_mps * e.x0_m / c.r0
    return k * (vm * eta + 0.5 * c.am * eta * eta)


def _range_shift(block: np.ndarray, shift_m: np.ndarray, spacing_m: float) -> np.ndarray:
    """Shift each row of ``block`` by ``shift_m[row]`` (positive = to larger range) with a
    zero-padded FFT along range."""
    n = block.shape[1]
    f = np.fft.fftfreq(2 * n)
    buf = np.zeros((block.shape[0], 2 * n), np.complex128)
    buf[:, :n] = block
    ramp = np.exp(-2j * np.pi * f[None, :] * (np.asarray(shift_m, np.float64)[:, None] / spacing_m))
    return np.fft.ifft(np.fft.fft(buf, axis=1) * ramp, axis=1)[:, :n]


def compensate(pair: Pair, res: MoverResult, method: str = "exact") -> np.ndarray:
    """Channel-0 image with the mover's smear replaced by its compensated, re-compressed image at its
    true position (azimuth y0, range sqrt(x0^2 + H^2)).

    Before the phase correction each slow-time row is moved in range from where the RCMC left the
    mover, R*sqrt(1 - R'^2/Vp^2) (estimate.py), to the stationary equivalent's closest range, so
    the re-compressed mover is one column wide like a stationary point (no residual migration).
    """
    rows, cols = _window(pair, res.candidate, COMPENSATION_MARGINS)
    s0 = decompress(pair.slc0, pair.z0, rows, cols)
    eta = np.asarray(pair.slc0.azimuth_time, np.float64) - pair.t_ref
    shift = int(pair.slc0.parameters.get("shift_lines", 0))
    eta = eta + shift / float(pair.slc0.parameters.get("prf_hz", pair.slc0.prf_hz))
    e = res.estimate
    p = pair.platform
    m = Mover(e.x0_m, e.y0_m, e.vx_mps, e.vy_mps)
    r = range_history(eta, m, p)
    rdot = ((m.x0 + m.vx * eta) * m.vx + (m.y0 + (m.vy - p.speed) * eta) * (m.vy - p.speed)) / r
    r_img = r * np.sqrt(np.maximum(1.0 - (rdot / p.speed) ** 2, 0.0))
    r_stat = math.sqrt(e.x0_m ** 2 + p.height ** 2)
    ranges = np.asarray(pair.slc0.slant_range)
    s0 = _range_shift(s0, r_stat - r_img, float(ranges[1] - ranges[0]))
    h = np.exp(1j * compensation_phase(eta, e, p, method))
    sub = recompress(pair.slc0, s0 * h[:, None], cols)
    out = pair.z0.astype(np.complex64, copy=True)
    out[rows, cols] = 0.0
    out[:, cols] += sub.astype(np.complex64)
    return out


def process(raw: RawProduct, route: str = "exact", unwrap_method: str = "dechirp", bin_mode: str = "track",
            knobs: CfarKnobs = CfarKnobs(), degree: int = 4) -> tuple[Pair, dict, list[MoverResult]]:
    """Focus, detect and estimate every candidate; candidates whose estimation fails are reported in
    the summary (``estimation_failures``) instead of aborting the others."""
    pair = focus_pair(raw)
    cands, summary = detect_pair(pair, knobs)
    results, failures = [], []
    for c in cands:
        try:
            results.append(estimate_mover(pair, c, route, unwrap_method, bin_mode, degree))
        except SarcliError as e:
            failures.append({"id": c.id, "error": str(e)})
    summary["estimation_failures"] = failures
    return pair, summary, results


def psf_cut(image: np.ndarray, rows: slice, cols: slice) -> tuple[int, int, np.ndarray]:
    """(peak row, peak col, azimuth cut through the peak over all rows) of ``image[rows, cols]``."""
    a = np.abs(image[rows, cols])
    i, j = np.unravel_index(int(np.argmax(a)), a.shape)
    r, c = rows.start + int(i), cols.start + int(j)
    return r, c, image[:, c]


def peak_position(cut: np.ndarray, row: int) -> float:
    """Sub-line peak position (fractional row) by parabolic interpolation of |cut|^2 (in dB)."""
    if 0 < row < cut.size - 1:
        y = 10.0 * np.log10(np.abs(cut[row - 1:row + 2]) ** 2 + 1e-300)
        den = y[0] - 2.0 * y[1] + y[2]
        if den < 0:
            return row + 0.5 * (y[0] - y[2]) / den
    return float(row)


def width_3db(cut: np.ndarray, row: int) -> float:
    """-3 dB width (lines, linear interpolation) of the peak of |cut| at ``row``."""
    a = np.abs(cut) / np.abs(cut[row])
    lo = row
    while lo > 0 and a[lo] > 0.7071:
        lo -= 1
    hi = row
    while hi < a.size - 1 and a[hi] > 0.7071:
        hi += 1
    left = lo + (0.7071 - a[lo]) / (a[lo + 1] - a[lo]) if a[lo + 1] != a[lo] else lo
    right = hi - (0.7071 - a[hi]) / (a[hi - 1] - a[hi]) if a[hi - 1] != a[hi] else hi
    return float(right - left)


def centroid_row(image: np.ndarray, rows: slice, cols: slice, floor_db: float = -20.0) -> float:
    """Intensity-weighted centre row (fractional, image coordinates) of the pixels of
    ``image[rows, cols]`` within ``floor_db`` of its peak: where a smeared mover's energy sits
    (its smear also bends across range columns, so a single-column cut would be biased)."""
    p = np.abs(image[rows, cols]).astype(np.float64) ** 2
    p[p < p.max() * 10.0 ** (floor_db / 10.0)] = 0.0
    idx = np.arange(rows.start, rows.start + p.shape[0])
    return float(np.sum(idx[:, None] * p) / np.sum(p))
