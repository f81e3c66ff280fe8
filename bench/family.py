"""Point-target scenes and measurements of the accuracy-versus-time map (``bench/bench_focus_family.py``;
the tests of ``sarcli.focus.select`` use them on a few small scenes).

Scene (:func:`make_scene`): a platform on an ``orbit`` (circular, radius R_E + 700 km, state vectors in
the Earth-fixed frame of a non-rotating Earth, targets on the WGS-84 ellipsoid) or a ``linear`` track
(LOCAL frame, constant velocity, flat ground); targets at given zero-Doppler times and closest ranges,
placed by :func:`sarcli.focus.geolocation.zero_doppler_points` (the pixels backprojection images).
Echo of line n (antenna position P_n from the product's own state vectors, stop and go):

    sum_targets exposure_n * rect(|tau - 2 R_n / c| <= T/2) exp(j pi K (tau - 2 R_n / c)^2) exp(-j 4 pi R_n / lam),

R_n = |X - P_n| exactly (no hyperbolic model), exposure a rect in the instantaneous Doppler
f_n = (2 / lam) V_n . (X - P_n) / R_n around the centroid fdc, 1.15 times the processed band wide (the
processed band sees a flat spectrum). Only the effects the map needs: no antenna pattern, noise,
quantization or Earth rotation. The squint sets fdc = -2 V_eff sin(theta) / lam, V_eff from the
geometry's Doppler rate at zero Doppler; the Doppler model handed to the focusers is the geometric one
through (fdc, fr) at the mid target's beam centre (:class:`sarcli.model.doppler.GeometricDoppler`).

The raw range window holds every target's closest range (the focusers' output columns are the raw
range grid) and its echo at the beam centre, R0 / cos(theta) and the range walk: the window grows as
R0 (1 / cos(theta) - 1), which is what limits the squint a small scene can have. The lines hold every
target's exposure and reach its output row: the focusers' output lines are the raw lines shifted by one
beam-centre offset, the one at the window's middle range, which exceeds a target's own by
(r_mid - R0) tan(theta) / V (1200 lines for the airborne X band scene at 30 deg).

Measurement (:func:`measure`): the exact reference is backprojection of the same lines onto a
``CHIP`` x ``CHIP`` window around each target (:func:`exact_chip`, the backprojection focuser's kernel
and window, chunked over lines to bound memory); a focuser's image is cropped to the same window and
both are measured by :func:`sarcli.focus.quality.point_target_metrics`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sarcli.model.raw import Orbit, Radar, RawProduct

C = 299792458.0
MU = 3.986004418e14
R_EARTH = 6378137.0
EPOCH = "2020-01-01T00:00:00Z"
CHIP = 64  # backprojected window per target (pixels per side)
EXPOSURE = 1.15  # exposure band / processed band

#: platform presets: closest range (m), processed Doppler band (Hz), PRF (Hz), range band (Hz), pulse (s)
PLATFORMS = {
    "spaceborne": {"r0": 850e3, "ba": 1300.0, "prf": 1600.0, "band": 30e6, "pulse": 10e-6, "height": 700e3},
    "airborne": {"r0": 5e3, "ba": 400.0, "prf": 520.0, "band": 500e6, "pulse": 1e-6, "height": 3e3,
                 "velocity": 120.0},
}
CARRIERS = {"L": 1.27e9, "C": 5.3e9, "X": 9.6e9}


@dataclass(frozen=True)
class Case:
    """One map scene: band name (L, C, X), platform (spaceborne on an orbit, airborne on a line), squint
    (deg), range band (Hz; default the platform's), targets' offsets (range m, azimuth s) from the mid one."""

    band: str
    platform: str
    squint_deg: float
    range_bandwidth_hz: float | None = None
    offsets: tuple[tuple[float, float], ...] = ((0.0, 0.0),)

    @property
    def track(self) -> str:
        return "orbit" if self.platform == "spaceborne" else "linear"

    @property
    def name(self) -> str:
        b = self.range_bandwidth_hz or PLATFORMS[self.platform]["band"]
        return f"{self.band} {self.platform} {self.squint_deg:g} deg B={b / 1e6:g} MHz"


@dataclass
class Scene:
    raw: RawProduct
    doppler: object
    targets: list[tuple[float, float]]  # (zero-Doppler time s, closest range m)
    fdc: float
    aperture_lines: float
    info: dict = field(default_factory=dict)


def _track(case: Case, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, str]:
    """Positions and velocities (n, 3) at times t and the frame."""
    p = PLATFORMS[case.platform]
    if case.track == "linear":
        v = p["velocity"]
        pos = np.stack([np.zeros_like(t), v * t, np.full_like(t, p["height"])], -1)
        vel = np.broadcast_to(np.array([0.0, v, 0.0]), pos.shape).copy()
        return pos, vel, "LOCAL"
    a = R_EARTH + p["height"]
    n = math.sqrt(MU / a**3)
    u = 0.7 + n * t  # argument of latitude (rad) in a polar orbit
    pos = a * np.stack([np.cos(u), np.zeros_like(u), np.sin(u)], -1)
    vel = a * n * np.stack([-np.sin(u), np.zeros_like(u), np.cos(u)], -1)
    return pos, vel, "ECEF"


def _orbit(case: Case, t0: float, t1: float) -> Orbit:
    t = np.arange(math.floor(t0) - 4.0, math.ceil(t1) + 5.0, 1.0)
    pos, vel, frame = _track(case, t)
    return Orbit(time=t, position=pos, velocity=vel, frame=frame)


def _doppler(x: np.ndarray, pos: np.ndarray, vel: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray]:
    d = x[None, :] - pos
    r = np.linalg.norm(d, axis=1)
    return r, 2.0 * np.sum(vel * d, axis=1) / (lam * r)


def make_scene(case: Case) -> Scene:
    """The raw product, Doppler model and targets of ``case`` (module docstring)."""
    from sarcli.focus.geolocation import platform_state, zero_doppler_points
    from sarcli.model.doppler import GeometricDoppler

    p = PLATFORMS[case.platform]
    f0 = CARRIERS[case.band]
    lam = C / f0
    band = case.range_bandwidth_hz or p["band"]
    fs = 1.2 * band
    dr = C / (2 * fs)
    r0 = p["r0"]
    theta = math.radians(case.squint_deg)
    # zero-Doppler geometry of the mid target, on a generous orbit record (the beam offset R0 tan / V)
    v_guess = 7100.0 if case.track == "orbit" else p["velocity"]
    t_ap_guess = p["ba"] * lam * r0 / (2 * v_guess**2 * math.cos(theta) ** 3)
    span = r0 * math.tan(theta) / (v_guess * math.cos(theta)) + t_ap_guess + 10.0  # to the window's far range
    orbit = _orbit(case, -span - 5.0, span + 5.0)
    side = "right"

    def target(t_zd: float, rho: float) -> np.ndarray:
        return zero_doppler_points(orbit, EPOCH, np.array([t_zd]), np.array([rho]), lam, side)[0]

    x0 = target(0.0, r0)
    h = 1e-3
    pos, vel = platform_state(orbit, EPOCH, np.array([-h, 0.0, h]))
    _, f = _doppler(x0, pos, vel, lam)
    fr0 = (f[2] - f[0]) / (2 * h)
    v_eff = math.sqrt(-fr0 * lam * r0 / 2.0)
    fdc = -2.0 * v_eff * math.sin(theta) / lam
    # beam-centre time: f(eta_c) = fdc (bisection on the monotonic Doppler history)
    lo, hi = -span, span
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        _, fm = _doppler(x0, *platform_state(orbit, EPOCH, np.array([mid])), lam)
        lo, hi = (mid, hi) if fm[0] > fdc else (lo, mid)
    eta_c = 0.5 * (lo + hi)
    pos, vel = platform_state(orbit, EPOCH, eta_c + np.array([-h, 0.0, h]))
    rc, f = _doppler(x0, pos, vel, lam)
    fr_c = (f[2] - f[0]) / (2 * h)
    dop = GeometricDoppler.from_centroid_and_rate(fdc, fr_c, float(rc[1]), lam)
    t_ap = EXPOSURE * p["ba"] / abs(fr_c)
    targets = [(float(dt), float(r0 + drg)) for drg, dt in case.offsets]
    xs = [target(t, r) for t, r in targets]
    prf = p["prf"]
    pulse = p["pulse"]
    # lines: every target's exposure, plus a margin of half a chip
    t_first = min(t for t, _ in targets) + eta_c - 0.5 * t_ap - CHIP / prf
    t_last = max(t for t, _ in targets) + eta_c + 0.5 * t_ap + CHIP / prf
    for _ in range(4):
        n_lines = int(math.ceil((t_last - t_first) * prf))
        eta = t_first + np.arange(n_lines) / prf
        pos, vel = platform_state(orbit, EPOCH, eta)
        hist = []
        for x in xs:
            r, fd = _doppler(x, pos, vel, lam)
            on = np.abs(fd - fdc) <= 0.5 * EXPOSURE * p["ba"]
            hist.append((r, on))
        # the chirp of a target at R spans R +- c T / 4 in range samples: whole in the window
        r_lo = min(min(r for _, r in targets) - CHIP * dr,
                   min(float(np.min(r[on])) for r, on in hist) - 0.25 * C * pulse) - 16 * dr
        r_hi = max(float(np.max(r[on])) for r, on in hist) + 0.25 * C * pulse + 16 * dr
        n_samples = int(math.ceil((r_hi - r_lo) / dr))
        # the focusers' output line j is at zero-Doppler time t_raw[j] - shift / PRF with one shift, the
        # beam-centre offset at the window's middle range; at large squint the window spans R0 .. R0 / cos
        # and that offset exceeds the targets' own by (r_mid - R0) tan(theta) / V: the lines must reach
        # every target's output row (and half a chip beyond it)
        t_need = _lines_needed(eta, n_samples, prf, dop, orbit, _radar(f0, lam, prf, fs, band, pulse, r_lo, vel),
                               targets)
        if t_need is None:
            break
        t_first, t_last = min(t_first, t_need[0]), max(t_last, t_need[1])
    rng = r_lo + np.arange(n_samples) * dr
    radar = _radar(f0, lam, prf, fs, band, pulse, r_lo, vel)
    k = radar.chirp_rate_hz_per_s
    echo = np.zeros((n_lines, n_samples), np.complex64)
    half = int(math.ceil(0.5 * C * pulse / dr)) + 1
    for r, on in hist:
        for n in np.flatnonzero(on):
            i = int(round((r[n] - r_lo) / dr))
            a, b = max(0, i - half), min(n_samples, i + half + 1)
            d = 2.0 * (rng[a:b] - r[n]) / C
            inside = np.abs(d) <= 0.5 * pulse
            echo[n, a:b] += np.where(inside, np.exp(1j * np.pi * k * d * d - 4j * np.pi * r[n] / lam), 0)
    raw = RawProduct(echo=echo, azimuth_time=eta, epoch_utc=EPOCH, radar=radar, orbit=orbit, look_side=side,
                     source="simulated")
    return Scene(raw=raw, doppler=dop, targets=targets, fdc=fdc, aperture_lines=t_ap / EXPOSURE * prf,
                 info={"v_eff": v_eff, "fdc_hz": fdc, "fr_hz_per_s": fr_c, "beam_offset_s": eta_c,
                       "shape": [n_lines, n_samples], "pixels": n_lines * n_samples})


def _radar(f0: float, lam: float, prf: float, fs: float, band: float, pulse: float, r_lo: float,
               vel: np.ndarray) -> Radar:
    """The scene's radar: chirp of ``band`` over ``pulse``, window from ``r_lo``."""
    return Radar(carrier_frequency_hz=f0, wavelength_m=lam, prf_hz=prf, range_sampling_rate_hz=fs,
                 chirp_rate_hz_per_s=band / pulse, pulse_length_s=pulse, window_start_s=2 * r_lo / C,
                 first_range_m=r_lo, platform_velocity_mps=float(np.linalg.norm(vel[0])))


def _lines_needed(eta: np.ndarray, n_samples: int, prf: float, dop, orbit: Orbit, radar: Radar,
                  targets) -> tuple[float, float] | None:
    """None where every target's output row (:func:`sarcli.focus.rda.plan_grid` on these lines and range
    window) lies half a chip and 16 lines inside the lines; else the raw times (first, last) that would hold
    them."""
    from sarcli.focus.rda import plan_grid

    probe = RawProduct(echo=np.zeros((eta.size, 1), np.complex64), azimuth_time=eta, epoch_utc=EPOCH, radar=radar,
                       orbit=orbit, look_side="right", source="simulated")
    grid = plan_grid(probe, (eta.size, n_samples), dop, None)
    t_zd = grid.zero_doppler_times(eta)
    margin = (CHIP // 2 + 16) / prf
    lo = min(t for t, _ in targets) - margin
    hi = max(t for t, _ in targets) + margin
    if t_zd[0] <= lo and t_zd[-1] >= hi:
        return None
    return eta[0] + min(0.0, lo - t_zd[0]), eta[-1] + max(0.0, hi - t_zd[-1])


def scene_size(case: Case) -> int:
    """Samples (lines x range samples) :func:`make_scene` would make, from the flat-geometry estimate
    (the bench skips scenes beyond its budget without making them)."""
    p = PLATFORMS[case.platform]
    lam = C / CARRIERS[case.band]
    band = case.range_bandwidth_hz or p["band"]
    dr = C / (2 * 1.2 * band)
    th = math.radians(case.squint_deg)
    v = 7100.0 if case.track == "orbit" else p["velocity"]
    t_ap = EXPOSURE * p["ba"] * lam * p["r0"] / (2 * v**2 * math.cos(th) ** 3)
    walk = v * math.sin(th) * t_ap
    samples = (p["r0"] * (1 / math.cos(th) - 1) + walk + 0.5 * C * p["pulse"]) / dr + 32
    # the exposure, and the lines that reach the targets' output rows (:func:`_lines_needed`): the output's
    # one shift is the beam offset at the window's middle range, half the window beyond R0
    lines = (t_ap + 0.5 * samples * dr * math.tan(th) / v) * p["prf"] + 2 * CHIP
    return int(lines * samples)


def pixel_of(slc_times: np.ndarray, slc_ranges: np.ndarray, target: tuple[float, float]) -> tuple[float, float]:
    """(row, col) of a target (zero-Doppler time, closest range) on an image grid."""
    t, r = target
    return (t - slc_times[0]) / (slc_times[1] - slc_times[0]), (r - slc_ranges[0]) / (slc_ranges[1] - slc_ranges[0])


def exact_chip(scene: Scene, row0: int, col0: int, window: str = "kaiser:2.5", upsample: int = 8,
               chunk: int = 256) -> tuple[np.ndarray, float]:
    """Backprojection onto output lines [row0, row0 + CHIP) x columns [col0, col0 + CHIP) of the RD grid
    (:func:`sarcli.focus.rda.plan_grid`): the backprojection focuser's kernel, window and pixels, summed
    over chunks of ``chunk`` raw lines (bounded memory). Returns (chip complex128, seconds of the sum)."""
    import time

    import scipy.fft as sfft

    from sarcli.focus.backprojection import backproject_grid
    from sarcli.focus.geolocation import platform_state, zero_doppler_points
    from sarcli.focus.rangecomp import compress_lines, range_filter, reference_pulse
    from sarcli.focus.rda import doppler_on_grid, plan_grid

    raw = scene.raw
    nl, nr = raw.echo.shape
    grid = plan_grid(raw, (nl, nr), scene.doppler, None)
    t_out = grid.zero_doppler_times(raw.azimuth_time)
    tt, rr = np.meshgrid(t_out[row0:row0 + CHIP], grid.ranges[col0:col0 + CHIP], indexing="ij")
    pix = zero_doppler_points(raw.orbit, raw.epoch_utc, tt, rr, grid.wavelength, raw.look_side).reshape(-1, 3)
    tc = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
    fdc, _, _, _ = doppler_on_grid(scene.doppler, grid.ranges, tc, grid.wavelength)
    fdc_pix = np.broadcast_to(fdc[col0:col0 + CHIP][None, :], tt.shape).ravel()
    ref = reference_pulse(raw.radar)
    h, _ = range_filter(raw.radar, sfft.next_fast_len(nr + ref.size - 1), window)
    out = np.zeros(pix.shape[0], complex)
    seconds = 0.0
    for a in range(0, nl, chunk):
        b = min(nl, a + chunk)
        rc = compress_lines(raw.echo[a:b], h.astype(np.complex128), nr)
        pos, vel = platform_state(raw.orbit, raw.epoch_utc, raw.azimuth_time[a:b])
        t0 = time.perf_counter()
        out += backproject_grid(rc, raw.radar.first_range_m, C / (2 * raw.radar.range_sampling_rate_hz),
                                grid.wavelength, pos, vel, pix, rr.ravel(), fdc_pix, grid.ba, window, upsample)
        seconds += time.perf_counter() - t0
    return out.reshape(tt.shape), seconds


def chip_metrics(chip: np.ndarray, row: float, col: float, fdc: float, prf: float) -> dict:
    """:func:`sarcli.focus.quality.point_target_metrics` of a CHIP x CHIP window (row, col inside it)."""
    from sarcli.focus.quality import point_target_metrics

    return point_target_metrics(chip, row, col, half=CHIP // 2, azimuth_carrier=fdc / prf)


def window_irw(spec: str) -> float:
    """IRW of a window's continuous IRF in resolution cells 1/B (trapezoid quadrature of
    integral W(u) cos(2 pi u x) du; half-power width)."""
    from sarcli.focus.windows import window

    u = np.linspace(-0.5, 0.5, 4001)
    x = np.arange(0, 3, 1 / 2048)
    irf = np.trapezoid(window(spec, u)[None, :] * np.cos(2 * np.pi * u[None, :] * x[:, None]), u, axis=1)
    p = irf**2
    j = int(np.nonzero(p < 0.5 * p[0])[0][0])
    return 2 * (x[j - 1] + (p[j - 1] - 0.5 * p[0]) / (p[j - 1] - p[j]) * (x[j] - x[j - 1]))


def compare(image_chip: np.ndarray, ref_chip: np.ndarray, row: float, col: float, fdc: float, prf: float) -> dict:
    """A focuser's window against the exact one: IRW ratios - 1, PSLR/ISLR differences (dB), peak phase
    difference (rad, wrapped) and peak position difference (pixels) in range and azimuth."""
    m = chip_metrics(image_chip, row, col, fdc, prf)
    r = chip_metrics(ref_chip, row, col, fdc, prf)
    return {"irw_range": m["irw_range_px"] / r["irw_range_px"] - 1,
            "irw_azimuth": m["irw_azimuth_px"] / r["irw_azimuth_px"] - 1,
            "pslr_range_db": m["pslr_range_db"] - r["pslr_range_db"],
            "pslr_azimuth_db": m["pslr_azimuth_db"] - r["pslr_azimuth_db"],
            "islr_range_db": m["islr_range_db"] - r["islr_range_db"],
            "islr_azimuth_db": m["islr_azimuth_db"] - r["islr_azimuth_db"],
            "phase_rad": float(np.angle(np.exp(1j * (m["peak_phase_rad"] - r["peak_phase_rad"])))),
            "d_row": m["row"] - r["row"], "d_col": m["col"] - r["col"], "image": m, "exact": r}
