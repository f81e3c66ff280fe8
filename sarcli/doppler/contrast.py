"""Standard error of a lag-1 correlation (CDE) block centroid: speckle AND scene contrast.

The CDE weight 2 N q^2 / (1 - q^2) (``sarcli.doppler.cde``) is the inverse phase variance of a
*stationary* scene: speckle and noise only. On a real scene a block's error is dominated by something
else: targets whose synthetic aperture the block cuts. A target wholly inside the block contributes a
lag-1 correlation whose phase is exactly 2 pi fdc / PRF (its Doppler history is symmetric about its
beam centre); one whose aperture sticks out at a block end contributes only part of its history and
pulls the phase towards the Doppler of the part it shows. The Vancouver blocks measured this: 512-line
blocks differ from 1536-line blocks by 8-76 Hz (median per scene) where the speckle formula says
1-3 Hz (``bench/results/bench_rs1_blocks.md``).

Derivation (notation of ``sarcli.doppler.cde``; lines m, PRF, Doppler rate fr in Hz/s, x in lines
from a target's beam centre). A target of beam-centre line eta and brightness w (energy per line at
its beam centre, over the block's range samples) has the two-way amplitude pattern a(x) and the
instantaneous Doppler fdc + fr x / PRF, so its expected share of the block's correlation sum over the
line pairs m = m0 .. m0 + P - 1 (P = L - 1 pairs of an L-line block) is w e^{j phi0} c(eta) with

    c(eta) = sum_m a(m - eta) a(m + 1 - eta) exp(j 2 pi fr (m + 1/2 - eta) / PRF^2)

(cross terms between targets have random phases: they are the speckle part, already in the weight).
For targets placed at random (Poisson, density rho per line) with independent brightness of mean mu
and second moment m2, the phase error eps = arg sum_t w_t c(eta_t) is, to first order,
sum w Im c / sum w Re c; Im c is odd about the block centre (mean 0), and by Campbell's theorem

    var(eps) = rho m2 int Im c(eta)^2 deta / (rho mu int Re c(eta) deta)^2 = K(L) / n_eff,

K(L) = int Im c^2 / (int Re c)^2 a property of the block length and the antenna, n_eff = rho mu^2 / m2
the effective number of targets per line (few when a few bright targets dominate). n_eff is read from
the same block: its line power p(m) = sum_t w_t a^2(m - eta_t) + noise has mean rho mu A2 + noise and,
between lines l0 apart (beyond the few lines over which speckle is correlated, here l0 = 8), the
covariance rho m2 A4(l0) (Campbell again; A2 = sum a^2, A4(l) = sum_x a^2(x) a^2(x + l)). The sample
autocovariance is biased low by the variance of the block's mean line power, rho m2 A4bar with
A4bar = sum_l (P - |l|) A4(l) / P^2, so

    rho m2 = gamma_p(l0) / (A4(l0) - A4bar),    rho mu = mean(p) s / A2,

s = min(1, q / rho_s) the signal fraction of the power (white noise lowers the block quality q below
the signal's own lag-1 coherence rho_s = |sum_x a(x) a(x+1) e^{j 2 pi fr (x + 1/2) / PRF^2}| / A2, and
adds power but no placement covariance). The block's standard error is then

    sigma_f = PRF / (2 pi) sqrt(var_speckle + K(L) rho m2 / (rho mu)^2).

The placement covariance is read over the block extended by one first-null distance of the pattern
on either side (within the scene): the targets that pull a block are those whose apertures its ends
cut, and a bright one just outside shows only its tail in the block's own lines (on simulated
point scenes the block's own lines gave 82 % of the errors within 2 sigma, the extended window
91-96 %).

Speckle term: the weight's (1 - q^2) / (2 N q^2) treats the N line pairs as independent; they are
not (a line is correlated with its neighbours over ~1 / (Doppler band)), which halved the variance on
the simulated scenes. Bartlett's formula for a circular Gaussian process of autocorrelation R(l)
(Isserlis: Cov(c_m, c_n) = |R(m - n)|^2 and E[(c_m - R1)(c_n - R1)] = R(m - n + 1) R(n - m + 1) for
c_m = h(m + 1) h*(m)) gives, per range column and with phi = arg R(1),

    var_speckle = [sum_l (P - |l|) |R(l)|^2 - Re(e^{-2 j phi} sum_l (P - |l|) R(l + 1) R(1 - l))]
                  / (2 P^2 |R(1)|^2 n_cols),

R(l) = s rho_s(l) for l != 0, R(0) = 1 (signal part: the pattern's autocorrelation, white noise at lag 0
only), the n_cols range samples of the block taken as independent (the chirp decorrelates adjacent raw
samples: correlation sinc(B / f_s) ~ 0.08 for Radarsat-1), summed over |l| <= 64 (the raw azimuth
signal decorrelates within a few lines). The SDE's hard limiter multiplies it by pi^2 / 4 (Van Vleck's
loss at small correlation).

Antenna: a uniformly illuminated aperture, two-way power pattern sinc^4(df / B0) in Doppler (first
null B0 = 2 V / L_antenna from the centroid), i.e. a(x) = sinc^2(fr x / (PRF B0)); B0 is fitted to the
scene's azimuth power spectrum (aliased copies every PRF included, plus a white floor)
(:func:`fit_band`). fr comes from the product's platform velocity, else the velocity guess, at
mid-swath (-2 V^2 / (lam R)): a few per cent error in it moves the aperture, and K, by as much.

What it does not hold: a scene that moves (sea surface: its own Doppler, not an error of the
estimate but of the assumption that the scene is still), and the correlation of neighbouring range
blocks (raw samples mix ranges over a pulse length: blocks within a pulse share their targets).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from sarcli.doppler.cde import BlockCorrelation, wrap_frequency

SPECKLE_LAG = 8  # lines: beyond the speckle correlation of the line power (about 1/(Doppler band))
NULLS = 6  # the pattern is summed out to this many first-null distances
SPECKLE_LAGS = 64  # lags of Bartlett's sums (the raw signal decorrelates within a few lines)
SIGN_LOSS = np.pi**2 / 4  # variance factor of hard-limited (SDE) correlations at small correlation (Van Vleck)


@dataclass(frozen=True)
class Pattern:
    """The two-way azimuth pattern as the CDE sees it: first-null Doppler offset ``band_hz`` (B0), Doppler
    rate ``fr_hz_per_s`` (maps lines to Doppler), PRF."""

    band_hz: float
    fr_hz_per_s: float
    prf_hz: float

    @property
    def null_lines(self) -> float:
        """Lines from the beam centre to the first null."""
        return self.band_hz * self.prf_hz / abs(self.fr_hz_per_s)

    def grid(self) -> np.ndarray:
        """Line offsets (float) covering the pattern out to :data:`NULLS` first nulls."""
        half = int(np.ceil(NULLS * self.null_lines)) + 1
        return np.arange(-half, half + 1, dtype=np.float64)

    def amplitude(self, x_lines: np.ndarray) -> np.ndarray:
        """Two-way amplitude a(x) = sinc^2(fr x / (PRF B0)), x in lines from the beam centre."""
        return np.sinc(self.fr_hz_per_s * np.asarray(x_lines, np.float64) / (self.prf_hz * self.band_hz)) ** 2

    def pair_terms(self, lag: int = 1) -> np.ndarray:
        """a(x) a(x + lag) exp(j 2 pi fr lag (x + lag / 2) / PRF^2) on :meth:`grid`: a target's share of the
        lag-``lag`` correlation, x lines after its beam centre (relative to the centroid's phase)."""
        x = self.grid()
        return (self.amplitude(x) * self.amplitude(x + lag)
                * np.exp(2j * np.pi * self.fr_hz_per_s * lag * (x + 0.5 * lag) / self.prf_hz**2))

    def coherence(self, max_lag: int) -> np.ndarray:
        """rho_s(l), l = 0 .. max_lag: the signal's normalized autocorrelation (rho_s(0) = 1)."""
        a2 = float(np.sum(self.amplitude(self.grid()) ** 2))
        return np.array([1.0 + 0j] + [np.sum(self.pair_terms(lag)) / a2 for lag in range(1, max_lag + 1)])


@dataclass(frozen=True)
class BlockFactors:
    """Pattern integrals for one block length (module docstring): ``k`` = K(L), ``a2`` = A2,
    ``a4_lag`` = A4(l0), ``a4_bar`` = A4bar, ``rho_s`` the signal's lag-1 coherence."""

    k: float
    a2: float
    a4_lag: float
    a4_bar: float
    rho_s: float


def fit_band(data: np.ndarray, prf: float, fbb_hz: float, max_lines: int = 4096, max_cols: int = 512) -> float:
    """First-null Doppler offset B0 (Hz) of the two-way sinc^4 azimuth pattern that best fits the mean
    azimuth power spectrum of ``data`` (lines, samples; central ``max_lines`` lines, at most
    ``max_cols`` evenly spaced columns), with its aliased copies and a white floor; least squares on a
    grid of B0 from 0.05 to 4 PRF, refined on a finer grid around the best."""
    n = data.shape[0]
    a = max(0, (n - max_lines) // 2)
    cols = np.unique(np.linspace(0, data.shape[1] - 1, min(max_cols, data.shape[1])).astype(np.int64))
    sub = np.asarray(data[a:a + max_lines][:, cols], np.complex64)
    spec = np.mean(np.abs(sfft.fft(sub, axis=0, workers=-1)) ** 2, axis=1, dtype=np.float64)
    spec /= max(spec.mean(), 1e-300)
    f = wrap_frequency(sfft.fftfreq(sub.shape[0], 1.0 / prf) - fbb_hz, prf)

    def misfit(b0: float) -> float:
        kmax = int(np.ceil(NULLS * b0 / prf)) + 1
        copies = np.arange(-kmax, kmax + 1, dtype=np.float64)[:, None] * prf  # the aliased copies, rows
        pattern = np.sinc((f[None, :] + copies) / b0)
        pattern *= pattern
        model = np.sum(pattern * pattern, axis=0)  # sinc^4 (two squarings: numpy's ** 4 is a pow)
        design = np.column_stack([model, np.ones_like(model)])
        coef, *_ = np.linalg.lstsq(design, spec, rcond=None)
        coef = np.maximum(coef, 0.0)
        return float(np.sum((design @ coef - spec) ** 2))

    grid = np.geomspace(0.05 * prf, 4.0 * prf, 120)
    best = grid[int(np.argmin([misfit(b) for b in grid]))]
    fine = np.linspace(best / 1.04, best * 1.04, 41)
    return float(fine[int(np.argmin([misfit(b) for b in fine]))])


def block_factors(n_lines: int, pattern: Pattern, lag_lines: int = SPECKLE_LAG) -> BlockFactors:
    """K(L), A2, A4(l0), A4bar and rho_s for a block (or window) of ``n_lines`` lines (module docstring)."""
    x = pattern.grid()
    a = pattern.amplitude(x)
    g = pattern.pair_terms(1)
    pairs = max(n_lines - 1, 1)
    c = np.convolve(g, np.ones(pairs))  # c at every integer beam-centre offset that reaches the block
    k = float(np.sum(c.imag**2) / np.sum(c.real) ** 2)
    a2 = float(np.sum(a**2))
    a4 = sfft.irfft(np.abs(sfft.rfft(a**2, 2 * x.size)) ** 2, 2 * x.size)  # autocorrelation of a^2
    lags = np.arange(-(pairs - 1), pairs)
    a4_at = a4[np.mod(lags, a4.size)] * (np.abs(lags) < x.size)
    a4_bar = float(np.sum((pairs - np.abs(lags)) * a4_at) / pairs**2)
    return BlockFactors(k, a2, float(a4[lag_lines]), a4_bar, float(abs(np.sum(g)) / a2))


def speckle_variance(quality: float, n_pairs: int, n_cols: int, rho: np.ndarray) -> float:
    """Phase variance (rad^2) of a block's lag-1 correlation from speckle and noise (Bartlett's formula,
    module docstring); ``rho`` = :meth:`Pattern.coherence` out to the lags that matter."""
    if not (quality > 0 and n_pairs > 0 and n_cols > 0):
        return float("inf")
    s = min(1.0, quality / abs(rho[1])) if abs(rho[1]) > 0 else 1.0
    big = rho.size - 2
    r = s * rho
    r[0] = 1.0
    lags = np.arange(-big, big + 1)

    def at(lag: np.ndarray) -> np.ndarray:
        return np.where(lag >= 0, r[np.abs(lag)], np.conj(r[np.abs(lag)]))

    w = np.clip(n_pairs - np.abs(lags), 0, None)
    t1 = float(np.sum(w * np.abs(at(lags)) ** 2))
    t2 = complex(np.sum(w * at(lags + 1) * at(1 - lags)))
    num = 0.5 * (t1 - (np.exp(-2j * np.angle(r[1])) * t2).real)
    return float(num / ((n_pairs * abs(r[1])) ** 2 * n_cols))


def scene_variance(window_energy: np.ndarray, window_valid: np.ndarray, block_mean: float, quality: float,
                   block: BlockFactors, window: BlockFactors, lag_lines: int = SPECKLE_LAG) -> float:
    """Phase variance (rad^2) of one block's centroid from the scene's contrast, K(L) rho m2 / (rho mu)^2:
    rho m2 from the line energies of the extended window (``window_valid`` marks the lines whose energy
    is known), rho mu from the block's mean line energy and quality (module docstring); 0 when the
    line power shows no placement covariance, inf when the window is too short to tell it from its mean."""
    p = np.asarray(window_energy, np.float64)
    v = np.asarray(window_valid, bool)
    both = v[:-lag_lines] & v[lag_lines:]
    if both.sum() < 2 * lag_lines or not block_mean > 0:
        return float("inf") if block_mean > 0 else 0.0
    d = p - p[v].mean()
    gamma = float(np.sum((d[:-lag_lines] * d[lag_lines:])[both]) / both.sum())
    if gamma <= 0:
        return 0.0
    denom = window.a4_lag - window.a4_bar
    if not denom > 0.05 * window.a4_lag:
        return float("inf")
    signal = min(1.0, quality / block.rho_s) if block.rho_s > 0 else 1.0
    rho_mu = block_mean * signal / block.a2
    return float(block.k * (gamma / denom) / rho_mu**2)


def block_sigmas(bc: BlockCorrelation, pattern: Pattern) -> tuple[np.ndarray, np.ndarray]:
    """(speckle, scene) phase variances (rad^2) of every block of ``bc`` (with its ``line_energy``)."""
    n_all = bc.line_energy.shape[0]
    covered = np.zeros(n_all, bool)  # lines of blocks that hold pairs (their energies are filled)
    for m0, n in zip(bc.line0, bc.n_lines, strict=True):
        covered[m0:m0 + n] = n > 1
    rho = pattern.coherence(SPECKLE_LAGS)
    ext = int(np.ceil(pattern.null_lines))
    quality = bc.quality()
    shape = bc.corr.shape
    var_speckle, var_scene = np.full(shape, np.inf), np.full(shape, np.inf)
    cache: dict[int, BlockFactors] = {}

    def factors(n: int) -> BlockFactors:
        if n not in cache:
            cache[n] = block_factors(n, pattern)
        return cache[n]

    for i, (m0, n) in enumerate(zip(bc.line0, bc.n_lines, strict=True)):
        a, b = max(0, m0 - ext), min(n_all, m0 + n + ext)
        for j in range(shape[1]):
            q = float(quality[i, j])
            var_speckle[i, j] = speckle_variance(q, int(n) - 1, int(bc.n_samples[j]), rho) * (
                SIGN_LOSS if bc.estimator == "sde" else 1.0)
            block_mean = float(np.mean(bc.line_energy[m0:m0 + n, j])) if n > 1 else 0.0
            var_scene[i, j] = scene_variance(bc.line_energy[a:b, j], covered[a:b], block_mean, q, factors(int(n)),
                                             factors(b - a))
    return var_speckle, var_scene
