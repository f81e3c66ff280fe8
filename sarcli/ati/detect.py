"""Mover detection on a co-registered two-channel image pair ([Ryu2017, Fig. 2], step 2).

Interferogram ``I = Z1 * conj(Z0)`` (channel 1 = the receiver ahead; stationary scatterers have
phase ``phi_c`` = the bistatic excess -(4*pi/lam)*d^2/(8*R), a mover ``phi_c`` + its ATI phase).
Two CFAR-style tests, both with a stated false-alarm probability per pixel:

1. magnitude: cell-averaging CFAR on ``(|Z0|^2 + |Z1|^2)/2`` against the mean of a training ring
   (exponential clutter: threshold ``alpha = n*(pfa**(-1/n) - 1)`` times the ring mean, n cells);
   the ring is long in azimuth (a defocused mover is smeared over tens of lines);
2. phase: ``z = |wrap(arg I - phi_c)| / sigma_phi`` with the thermal phase noise of the pixel
   ``sigma_phi^2 = N*(|Z0|^2 + |Z1|^2)/(2*|Z0|^2*|Z1|^2)`` (first order), ``N`` the image noise power
   per channel from the clutter-cancelled difference ``Z1*exp(-j*phi_c) - Z0`` (stationary scene
   cancels; its |.|^2 is exponential with mean 2N, median 2N ln 2), plus a systematic floor
   ``phase_floor_rad`` (inter-channel co-registration and focusing residuals: ~0.003-0.005 rad on
   a bright stationary point in the simulated pair; without it a 70-dB point target's residual
   phase looks like motion); pass when ``z > isf(pfa/2)``.

Pixels fainter than ``dynamic_range_db`` below the brightest pixel are not tested: the focusing's own
artefacts of bright targets (partial apertures at the scene ends, residual migration tails of a
mover) sit 45-60 dB down and differ between the channels, so at high SNR they would pass both tests.

Pixels passing both are grouped (a dilation long in azimuth joins the pieces of a smeared mover),
groups smaller than ``min_pixels`` or whose coherent phase z-score is below the threshold are
dropped. Each group gives a candidate with its coherent ATI
phase, LOS speed and ground-range speed vx (DRA factor, geometry.py), the phase z-score and a
confidence ``1 - min(1, 2*sf(z)*n_pixels_tested)`` (Bonferroni over the image), and an ambiguity
flag when the phase is near +-pi.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy import ndimage
from scipy.stats import norm

from sarcli.ati.estimate import AMBIGUITY_FRACTION
from sarcli.ati.geometry import Platform, blind_speed, ground_vx_from_los, los_rate_from_phase


@dataclass(frozen=True)
class CfarKnobs:
    """False-alarm probabilities per pixel and window sizes (lines x range samples)."""

    pfa_magnitude: float = 1e-6
    pfa_phase: float = 1e-6
    phase_floor_rad: float = 0.005
    dynamic_range_db: float = 40.0
    guard: tuple[int, int] = (48, 4)
    train: tuple[int, int] = (160, 16)
    min_pixels: int = 3
    join: tuple[int, int] = (25, 3)


@dataclass
class Candidate:
    """A detected mover (image coordinates, ATI phase and speeds; SI units)."""

    id: int
    row_start: int
    row_stop: int
    col_start: int
    col_stop: int
    peak_row: int
    peak_col: int
    azimuth_time_s: float
    slant_range_m: float
    n_pixels: int
    ati_phase_rad: float
    ati_phase_sigma_rad: float
    vr_los_mps: float
    vx_mps: float
    z_score: float
    confidence: float
    ati_ambiguous: bool

    def as_dict(self) -> dict:
        return asdict(self)


def bistatic_phase(ranges: np.ndarray, baseline_m: float, wavelength_m: float) -> np.ndarray:
    """ATI phase (rad) of a stationary scatterer: -(4*pi/lam)*d^2/(8*R)."""
    return -4.0 * np.pi / wavelength_m * baseline_m ** 2 / (8.0 * np.asarray(ranges, np.float64))


def ca_cfar(intensity: np.ndarray, guard: tuple[int, int], train: tuple[int, int], pfa: float) -> np.ndarray:
    """Cell-averaging CFAR mask: intensity > alpha * mean over the training ring (exponential)."""
    g = [2 * x + 1 for x in guard]
    t = [2 * x + 1 for x in train]
    big = ndimage.uniform_filter(intensity.astype(np.float64), size=t, mode="reflect") * (t[0] * t[1])
    small = ndimage.uniform_filter(intensity.astype(np.float64), size=g, mode="reflect") * (g[0] * g[1])
    n = t[0] * t[1] - g[0] * g[1]
    ring = (big - small) / n
    alpha = n * (pfa ** (-1.0 / n) - 1.0)
    return intensity > alpha * ring


def image_noise_power(z0: np.ndarray, z1: np.ndarray, phi_c: np.ndarray) -> float:
    """Thermal noise power per channel from the clutter-cancelled difference (median estimator)."""
    d = z1 * np.exp(-1j * phi_c)[None, :] - z0
    return float(np.median(np.abs(d) ** 2) / (2.0 * np.log(2.0)))


def detect(z0: np.ndarray, z1: np.ndarray, azimuth_time: np.ndarray, slant_range: np.ndarray,
           platform: Platform, baseline_m: float, knobs: CfarKnobs = CfarKnobs()
           ) -> tuple[list[Candidate], dict]:
    """Candidates in a co-registered pair ``z0`` (aft), ``z1`` (fore), plus a summary dict."""
    lam = platform.wavelength
    phi_c = bistatic_phase(slant_range, baseline_m, lam)
    p0 = np.abs(z0).astype(np.float64) ** 2
    p1 = np.abs(z1).astype(np.float64) ** 2
    intensity = 0.5 * (p0 + p1)
    mag = ca_cfar(intensity, knobs.guard, knobs.train, knobs.pfa_magnitude)
    mag &= intensity > float(intensity.max()) * 10.0 ** (-knobs.dynamic_range_db / 10.0)
    nse = image_noise_power(z0, z1, phi_c)
    ifg = z1.astype(np.complex128) * np.conj(z0) * np.exp(-1j * phi_c)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        sig = np.sqrt(nse * (p0 + p1) / (2.0 * p0 * p1) + knobs.phase_floor_rad ** 2)
        z = np.abs(np.angle(ifg)) / sig
    z = np.nan_to_num(z, nan=0.0, posinf=0.0)
    z_t = float(norm.isf(0.5 * knobs.pfa_phase))
    hits = mag & (z > z_t)
    joined = ndimage.binary_dilation(hits, structure=np.ones((knobs.join[0], knobs.join[1]), bool))
    labels, n_lab = ndimage.label(joined)
    n_tested = int(mag.sum())
    out: list[Candidate] = []
    for lab, sl in enumerate(ndimage.find_objects(labels), start=1):
        if sl is None:
            continue
        own = hits[sl] & (labels[sl] == lab)
        n_pix = int(own.sum())
        if n_pix < knobs.min_pixels:
            continue
        sub_i = np.where(own, ifg[sl], 0.0)
        isum = complex(sub_i.sum())
        var = nse * float(np.sum(np.where(own, p0[sl] + p1[sl], 0.0)))
        phi = math.atan2(isum.imag, isum.real)
        phi_sd = math.hypot(math.sqrt(0.5 * var) / max(abs(isum), 1e-300), knobs.phase_floor_rad)
        zc = abs(phi) / phi_sd if phi_sd > 0 else float("inf")
        if zc < z_t:
            continue
        pk = np.unravel_index(int(np.argmax(np.where(own, intensity[sl], -1.0))), own.shape)
        r, c = sl[0].start + int(pk[0]), sl[1].start + int(pk[1])
        rng = float(slant_range[c])
        vr = float(los_rate_from_phase(phi, baseline_m, platform))
        vx = ground_vx_from_los(vr, rng, platform.height)
        conf = 1.0 - min(1.0, 2.0 * float(norm.sf(zc)) * max(n_tested, 1))
        out.append(Candidate(
            id=len(out), row_start=sl[0].start, row_stop=sl[0].stop, col_start=sl[1].start,
            col_stop=sl[1].stop, peak_row=r, peak_col=c, azimuth_time_s=float(azimuth_time[r]),
            slant_range_m=rng, n_pixels=n_pix, ati_phase_rad=phi, ati_phase_sigma_rad=phi_sd,
            vr_los_mps=vr, vx_mps=vx, z_score=zc, confidence=conf,
            ati_ambiguous=bool(abs(phi) + 3.0 * phi_sd > AMBIGUITY_FRACTION * math.pi)))
    # weakest mover passing the magnitude test: intensity alpha x median ring mean (clutter level)
    ref = float(np.median(intensity))
    n_ring = (2 * knobs.train[0] + 1) * (2 * knobs.train[1] + 1) - (2 * knobs.guard[0] + 1) * (2 * knobs.guard[1] + 1)
    a_min = n_ring * (knobs.pfa_magnitude ** (-1.0 / n_ring) - 1.0) * max(ref, nse)
    sig_min = math.hypot(math.sqrt(nse / max(a_min, 1e-300)), knobs.phase_floor_rad)

    def vmin(sig_phase: float) -> float:
        return abs(float(los_rate_from_phase(z_t * sig_phase, baseline_m, platform)))

    summary = {
        "noise_power": nse, "phase_threshold_z": z_t, "n_pixels_magnitude": n_tested,
        "n_pixels_detected": int(hits.sum()), "n_candidates": len(out),
        "blind_speed_mps": blind_speed(baseline_m, platform),
        # single-pixel detection limits: a mover at the magnitude threshold, and a bright one (floor)
        "min_vr_los_at_threshold_mps": vmin(sig_min),
        "min_vr_los_bright_mps": vmin(knobs.phase_floor_rad),
    }
    return out, summary
