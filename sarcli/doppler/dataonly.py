"""Data-only ambiguity resolution: MLCC and MLBF (Wong & Cumming 1996), with an honest confidence.

Both use two range sub-looks centred at range frequencies f_lo < f_hi (``rangecomp.range_looks``).
A scatterer's azimuth phase at range frequency f is -4*pi*(f0 + f)*R(eta)/c, so its Doppler frequency
scales with the RF frequency: fdc(f) = fdc * (1 + f/f0), fdc the ABSOLUTE centroid at the carrier f0.

MLCC (multilook cross correlation): the lag-1 azimuth correlation phase of look l is
phi_l = 2*pi*fdc*(1 + f_l/f0)/PRF (mod 2*pi), hence
    fdc = arg(rho_hi * conj(rho_lo)) * f0 * PRF / (2*pi*(f_hi - f_lo)),
unambiguous for |fdc| < f0*PRF / (2*(f_hi - f_lo)). The looks are formed AFTER range compression:
in uncompressed data the chirp maps range frequency to range position, so the two half-bands at one
range sample come from different scatterers and their phases do not share the scene-content error
(measured on the Vancouver block: block-to-block scatter grows ~50x without compression).

MLBF (multilook beat frequency): after range compression a look is exp(-j*4*pi*f0*R/c) times its
compressed pulse carrying exp(j*2*pi*f_l*(tau - 2R/c)); the beat b = look_lo * conj(look_hi) at a fixed
range bin therefore varies as exp(j*4*pi*(f_hi - f_lo)*R(eta)/c), a tone at
    f_beat = 2*(f_hi - f_lo)*(dR/deta)/c = -fdc * (f_hi - f_lo) / f0.
f_beat is measured as the mean frequency of b from its azimuth correlation (the CDE kernel applied to
b), not as the peak of its FFT: at one range bin a scatterer is present only while it walks through
the bin (~25 ms on Radarsat-1), about half a beat cycle, so the beat spectrum is a ~40 Hz wide lobe
around a ~20 Hz tone and peak-picking on 1.2 s of data is poorly conditioned (on the Vancouver block
the FFT peak gave block values spread over 1.5 kHz of fdc). The lag-1 phase alone is biased towards
0 Hz in clutter: cross terms between different scatterers of one range bin form a broad spectrum
around 0 Hz (measured: -5250 Hz for a true -6580 Hz on the simulated clutter scene). Their
correlation dies within a few lines while the tone stays coherent over its ~30-line burst, so the
phase at lag L = 16 lines (unwrapped around the lag-1 value; unambiguous for |f_beat| < PRF/(2L),
i.e. |fdc| up to ~14 kHz at C band with 15 MHz between the looks) is used: -6590 Hz on that scene.
Then fdc = -f_beat * f0 / (f_hi - f_lo).

Confidence: both estimators are run per range block; the standard error of the scene estimate is the
weighted block scatter / sqrt(N_eff - 1) (N_eff = (sum w)^2 / sum w^2), with N_eff - 1 degrees of
freedom. With y = (fdc_est - fdc_bb)/PRF the ambiguity is n = floor(y + 1/2) and the confidence is
P(round(Y) = n), Y ~ N(y, sigma_y^2) or Student-t with those degrees of freedom
(``ambiguity.rounding_confidence``). This covers random error only: a scene-contrast bias (MLCC is
biased by strong contrast; MLBF towards 0 Hz where many scatterers share a range bin, ~5 % of the
centroid on the Vancouver blocks) is not in it.

Combination (:func:`combine_estimates`): MLCC and MLBF estimate the same absolute centroid with
independent errors (different statistics of the looks: the lag-1 phase difference of the two looks,
the lag-16 beat of their product), so the maximum-likelihood scene value is the inverse-variance mean
F = sum f_i / s_i^2 / sum 1 / s_i^2 with s_F^2 = 1 / sum 1 / s_i^2, scaled by the Birge ratio
sqrt(chi2 / (k - 1)) when the k estimates disagree beyond their errors (chi2 = sum (f_i - F)^2 / s_i^2
> k - 1: their stated errors cannot both be right, and the combination must not claim more than the
scatter shows), with Welch-Satterthwaite degrees of freedom nu = (sum 1/s_i^2)^2 / sum 1/(s_i^4 nu_i).
The ambiguity and its confidence are then the rounding of (F - fdc_bb)/PRF as above. (The previous rule,
"the more confident method wins, its confidence times one minus the other's when they disagree",
threw away the information that two estimates on either side of an integer both support it: on the
Squamish block MLCC said -7823 +- 1082 Hz (-7) and MLBF -6287 +- 791 Hz (-5); together -6823 Hz,
ambiguity -6 like the five other blocks of the pass.)
"""

from __future__ import annotations

import numpy as np

from sarcli.doppler.ambiguity import rounding_confidence
from sarcli.doppler.cde import block_correlation
from sarcli.doppler.rangecomp import Looks, range_looks
from sarcli.model.doppler_summary import DataOnlyEstimate
from sarcli.model.raw import Radar


def _scatter_stats(vals: np.ndarray, w: np.ndarray) -> tuple[float, float, float]:
    """Weighted mean, its standard error and the degrees of freedom (N_eff - 1)."""
    ok = np.isfinite(vals) & (w > 0)
    if ok.sum() < 2:
        return (float(np.sum(vals[ok] * w[ok]) / np.sum(w[ok])) if ok.any() else np.nan), np.inf, 0.0
    v, ww = vals[ok], w[ok]
    mean = float(np.sum(ww * v) / np.sum(ww))
    var = float(np.sum(ww * (v - mean) ** 2) / np.sum(ww))
    dof = max(float(np.sum(ww) ** 2 / np.sum(ww**2)) - 1.0, 1e-9)
    return mean, float(np.sqrt(var / dof)), dof


def _decide(method: str, mean: float, sigma: float, dof: float | None, fdc_bb: float, prf: float,
            vals: np.ndarray) -> DataOnlyEstimate:
    """The estimate with its ambiguity (rounding of (mean - fdc_bb) / PRF) and rounding confidence
    (Student-t with ``dof`` degrees of freedom, Gaussian for None)."""
    y = (mean - fdc_bb) / prf
    n = int(np.floor(y + 0.5)) if np.isfinite(y) else 0
    conf = rounding_confidence(y, sigma / prf, dof) if np.isfinite(sigma) and np.isfinite(y) else 0.0
    return DataOnlyEstimate(method, mean, sigma, n, conf, vals, dof)


def _finish(method: str, vals: np.ndarray, w: np.ndarray, fdc_bb: float, prf: float) -> DataOnlyEstimate:
    mean, sigma, dof = _scatter_stats(vals, w)
    return _decide(method, mean, sigma, dof, fdc_bb, prf, vals)


def _auto_block(rg_block: int | None, n_valid: int) -> int:
    """Range block of the data-only estimators: given, or n_valid/8 clipped to 16..128 (the block
    scatter needs several blocks to say anything about the confidence)."""
    return int(rg_block) if rg_block else max(16, min(128, n_valid // 8))


def mlcc(echo: np.ndarray, radar: Radar, fdc_bb: float, rg_block: int | None = None,
         replica: np.ndarray | None = None, looks: Looks | None = None) -> DataOnlyEstimate:
    """MLCC absolute centroid (Hz) and ambiguity relative to the scene baseband centroid ``fdc_bb``.
    ``looks``: the range sub-looks of ``echo`` (``range_looks``) when the caller has them already."""
    lo, hi, fc = looks if looks is not None else range_looks(echo, radar, replica)
    n_lines = echo.shape[0]
    rg_block = _auto_block(rg_block, lo.shape[1])
    b_lo = block_correlation(lo, n_lines, rg_block)
    b_hi = block_correlation(hi, n_lines, rg_block)
    dphi = np.angle(b_hi.phase_rho() * np.conj(b_lo.phase_rho()))[0]
    vals = dphi * radar.carrier_frequency_hz * radar.prf_hz / (2 * np.pi * (fc[1] - fc[0]))
    w = np.minimum(b_lo.weight(), b_hi.weight())[0]
    return _finish("mlcc", vals, w, fdc_bb, radar.prf_hz)


def mlbf(echo: np.ndarray, radar: Radar, fdc_bb: float, rg_block: int | None = None,
         replica: np.ndarray | None = None, lag: int = 16, looks: Looks | None = None) -> DataOnlyEstimate:
    """MLBF absolute centroid (Hz) and ambiguity relative to the scene baseband centroid ``fdc_bb``.

    The beat frequency of each range block is read from the lag-1 phase (coarse, unambiguous to
    PRF/2) and refined by the lag-``lag`` phase unwrapped around it (module docstring). ``looks`` as
    for :func:`mlcc`."""
    lo, hi, fc = looks if looks is not None else range_looks(echo, radar, replica)
    beat = lo * np.conj(hi)
    blk = _auto_block(rg_block, beat.shape[1])
    prf = radar.prf_hz
    coarse = block_correlation(beat, echo.shape[0], blk)
    f_beat = coarse.baseband(prf)[0]
    w = coarse.weight()[0]
    lag = min(int(lag), max(echo.shape[0] // 8, 1))
    if lag > 1:
        fine = block_correlation(beat, echo.shape[0], blk, lag=lag)
        dphi = np.angle(fine.corr[0] * np.exp(-2j * np.pi * f_beat * lag / prf))
        f_beat = f_beat + dphi * prf / (2 * np.pi * lag)
        w = np.where(w > 0, fine.weight()[0], 0.0)
    vals = -f_beat * radar.carrier_frequency_hz / (fc[1] - fc[0])
    return _finish("mlbf", vals, w, fdc_bb, prf)


def combine_estimates(ests: list[DataOnlyEstimate], fdc_bb: float, prf: float) -> DataOnlyEstimate | None:
    """The combined data-only estimate (method ``combined``) of several estimates of the same absolute
    centroid (module docstring: inverse-variance mean, Birge-ratio scaling, Welch-Satterthwaite degrees
    of freedom), with its ambiguity relative to ``fdc_bb`` and its confidence; None when no estimate
    has a finite value and standard error."""
    ok = [e for e in ests if np.isfinite(e.fdc_hz) and np.isfinite(e.sigma_hz) and e.sigma_hz > 0]
    if not ok:
        return None
    f = np.array([e.fdc_hz for e in ok])
    w = np.array([1.0 / e.sigma_hz**2 for e in ok])
    nu = np.array([np.inf if e.dof is None else max(float(e.dof), 1e-9) for e in ok])
    mean = float(np.sum(w * f) / np.sum(w))
    sigma = float(1.0 / np.sqrt(np.sum(w)))
    if len(ok) > 1:
        chi2 = float(np.sum(w * (f - mean) ** 2))
        sigma *= max(1.0, np.sqrt(chi2 / (len(ok) - 1)))
    dof = float(np.sum(w) ** 2 / np.sum(w**2 / nu)) if np.all(np.isfinite(nu)) else None
    return _decide("combined", mean, sigma, dof, fdc_bb, prf,
                   np.array([e.fdc_hz for e in ok]))
