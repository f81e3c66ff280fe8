"""Look-balance centroid (LB): the scene-contrast-robust estimator, target by target on the focused scene.

Why. The CDE phase of a block is the power-weighted mean Doppler of what the block's lines hold. A
target whose beam-centre time eta lies inside the scene contributes, on line time t, the Doppler
fdc + Ka (t - eta) with the weight G^2(t - eta) (two-way azimuth power pattern). A block shorter than
the synthetic aperture (Radarsat-1 fine beam: ~440 lines at -3 dB, ~1400 null to null) sees only part
of most apertures, so bright targets entering or leaving it pull its centroid: on a simulated coast
(bright town, land edge) 512-line CDE blocks were off by -87..+245 Hz while the 1536-line estimate was
within 10 Hz (52 Hz at the swath edge); this is what separates the 512- and 1536-line estimates of the
real Vancouver block.

What. Focus the scene in azimuth (per range column of the raw echo, spectrum X(f)), with the matched
filter referenced to a trial centroid f_ref:
    f_rel = wrap(f - f_ref),   H(f) = exp(+j pi f_rel^2 / Ka)
(stationary phase: a target s(t) = G(t-eta) exp(j 2 pi f_ref (t-eta) + j pi Ka (t-eta)^2) has the
spectrum G(f_rel/Ka) exp(-j 2 pi f eta) exp(-j pi f_rel^2/Ka), so X H peaks at its beam-centre time
eta). Two looks split the processed band B = band_fraction * PRF at f_ref: lo = [-B/2, 0), hi = [0, B/2).
For every target the look energies are the antenna pattern integrated over the two halves, equal iff
f_ref is its centroid (the pattern is symmetric), whatever the target's brightness; white noise adds the
same energy to both looks. A block OWNS the pixels (beam-centre times) inside it, and its centroid is
the root of
    D(f_ref) = (sum P_hi - sum P_lo) / (sum P_hi + sum P_lo)     over the block's pixels and columns,
a decreasing function of f_ref. Pixels closer than L = (1 + guard) B / (2 |Ka|) * PRF lines to either
end of the scene are not used: their looks lack data (and the circular FFT wraps there); the guard
(15 %) keeps the sidelobes of bright targets whose look apertures the scene ends cut (unbalanced) out
of the owned pixels (on the simulated coast, the town 66 lines before the first owned pixel moved that
block by -16 Hz without the guard, +9 Hz with it; sigma 6 Hz). So a block's estimate uses
the lines around it (each target's whole look aperture) but only the targets inside it.

How. Per range block one azimuth FFT; per azimuth block the root of D is bracketed by steps of 5 %
PRF from the start value (the pipeline passes the CDE centroid of the range block over the whole
scene) and found by Brent's method to ``tol_hz``. D decreases over tens of Hz but is rough below
~1 Hz (bins of speckled power enter and leave the looks), which defeats Newton steps; look edges weight
their cut bins by the fraction inside, so D is at least continuous. ``step_hz`` is only the
finite-difference step of the slope at the root. A block without a sign change within ``max_iter``
steps, or with a non-negative slope at its root, is invalid. The
standard error of a block comes from the scatter of -D/D' over ``n_groups`` contiguous groups of its
pixels (targets in different groups are independent; raw range columns are not, a pulse spans them
all), times the coverage factor t_{0.975, n-1} / 1.96 (1.21 for 8 groups,
``ambiguity.coverage_factor``): estimated from 8 groups, the plain standard error left 90 % of the
Vancouver 512- vs 1536-line differences within 2 sigma with an rms of difference / sigma of 1.18, which
is sqrt(7/5), the rms of Student's t with 7 degrees of freedom; 16 smaller groups (32 lines) were not
independent (85 %, rms 1.34).

Cost: one FFT per range block and two look IFFTs per evaluation of D (some 10-14 per block from the
CDE's start: bracket, Brent, slope), i.e. about 25 block-sized FFT passes per block (the CDE is one
read of the echo); it needs the Doppler rate (from the orbit or map-drift) and the CDE's first guess.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft
from scipy.optimize import brentq

from sarcli.doppler.ambiguity import coverage_factor
from sarcli.doppler.cde import wrap_frequency
from sarcli.errors import SarcliError
from sarcli.threads import budget


@dataclass
class LookBalance:
    """Per (azimuth block, range block): baseband centroid ``fbb_hz`` ([-PRF/2, PRF/2); NaN when the
    block owns too few usable pixels, no sign change of D is found within ``max_iter`` bracketing steps,
    or D has no negative slope at the root), its standard error ``sigma_hz``, ``pixels`` (owned lines
    used), ``centre_line`` (mean of those lines, where the estimate applies) and the slope
    ``slope_per_hz`` dD/df_ref; ``margin_lines`` is L per range block.

    The standard error describes the scatter of targets, not whether there is signal at all: a block of
    pure noise can keep a root with a modest sigma. The pipeline therefore keeps only blocks that the
    CDE's noise-floor test accepts (``estimate_doppler``)."""

    fbb_hz: np.ndarray
    sigma_hz: np.ndarray
    pixels: np.ndarray
    centre_line: np.ndarray
    slope_per_hz: np.ndarray
    margin_lines: np.ndarray

    def valid(self) -> np.ndarray:
        return np.isfinite(self.fbb_hz) & np.isfinite(self.sigma_hz) & (self.sigma_hz > 0)

    def phase_weight(self, prf: float) -> np.ndarray:
        """Inverse phase variance (rad^-2), the CDE's weight unit; 0 where invalid."""
        with np.errstate(divide="ignore", invalid="ignore"):
            w = (prf / (2.0 * np.pi * self.sigma_hz)) ** 2
        return np.where(self.valid(), w, 0.0)


def _overlap(f_rel: np.ndarray, width: float, lo: float, hi: float) -> np.ndarray:
    """Fraction of each frequency bin [f - width/2, f + width/2) inside [lo, hi)."""
    return np.clip((np.minimum(hi, f_rel + 0.5 * width) - np.maximum(lo, f_rel - 0.5 * width)) / width, 0.0, 1.0)


def look_powers(spectrum: np.ndarray, prf: float, f_ref: float, ka: float, band: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """(P_lo, P_hi) per line (beam-centre time): the look images' power summed over the columns of
    ``spectrum`` (azimuth spectrum, (n_lines, n_cols)). A bin cut by a look edge enters with the
    fraction of its width inside the look (amplitude sqrt(fraction)), so the powers, and D, change
    continuously with f_ref instead of jumping by one bin's energy (0.8 Hz bins on 1536 lines)."""
    n = spectrum.shape[0]
    f_rel = wrap_frequency(sfft.fftfreq(n, 1.0 / prf) - f_ref, prf)
    h = np.exp(1j * np.pi * f_rel**2 / ka)
    out = []
    for a, b in ((-0.5 * band, 0.0), (0.0, 0.5 * band)):
        g = (h * np.sqrt(_overlap(f_rel, prf / n, a, b))).astype(np.complex64)
        y = sfft.ifft(spectrum * g[:, None], axis=0, workers=budget())
        out.append(np.sum(y.real**2 + y.imag**2, axis=1, dtype=np.float64))
    return out[0], out[1]


def _balance(p_lo: np.ndarray, p_hi: np.ndarray, segs: list[np.ndarray]) -> np.ndarray:
    lo = np.array([p_lo[s].sum() for s in segs])
    hi = np.array([p_hi[s].sum() for s in segs])
    with np.errstate(invalid="ignore", divide="ignore"):
        return (hi - lo) / (hi + lo)


def _root(d_of, f0: float, max_step: float, tol_hz: float, max_iter: int) -> float | None:
    """Root of the decreasing function D: bracket by steps of ``max_step`` from f0, then Brent's method.
    None when no sign change is found within ``max_iter`` steps (a noise block)."""
    d0 = d_of(f0)
    if d0 == 0:
        return f0
    direction = 1.0 if d0 > 0 else -1.0
    a, da = f0, d0
    for _ in range(max_iter):
        b = a + direction * max_step
        db = d_of(b)
        if not (np.isfinite(da) and np.isfinite(db)):
            return None
        if np.sign(db) != np.sign(da):
            lo, hi = (a, b) if a < b else (b, a)
            return float(brentq(d_of, lo, hi, xtol=tol_hz))
        a, da = b, db
    return None


def look_balance(echo: np.ndarray, prf: float, line0: np.ndarray, n_lines: np.ndarray, sample0: np.ndarray,
                 n_samples: np.ndarray, f_start: np.ndarray, ka: np.ndarray, band_fraction: float = 0.6,
                 step_hz: float = 10.0, n_groups: int = 8, min_pixels: int = 32, tol_hz: float = 0.1,
                 max_iter: int = 8, guard: float = 0.15) -> LookBalance:
    """Look-balance centroid on the block grid (``line0``/``n_lines`` azimuth, ``sample0``/``n_samples``
    range), starting per range block from ``f_start`` (Hz, baseband) with the Doppler rate ``ka``
    (Hz/s, per range block, negative). Module docstring."""
    if not 0.1 <= band_fraction <= 0.9:
        raise SarcliError(f"look-balance band fraction must be in [0.1, 0.9], got {band_fraction}")
    if np.any(~np.isfinite(ka)) or np.any(ka == 0):
        raise SarcliError("look balance needs a finite, non-zero Doppler rate in every range block")
    n = echo.shape[0]
    band = band_fraction * prf
    max_step = 0.05 * prf  # bracketing step (D is monotonic on this scale, speckle-rough below 1 Hz)
    shape = (line0.size, sample0.size)
    fbb, sig, slope, centre = (np.full(shape, np.nan) for _ in range(4))
    pix = np.zeros(shape, np.int64)
    margin = np.zeros(sample0.size, np.int64)
    for j in range(sample0.size):
        big_l = int(np.ceil((1.0 + guard) * 0.5 * band / abs(ka[j]) * prf))
        margin[j] = big_l
        owned = [np.arange(max(a, big_l), min(a + m, n - big_l)) for a, m in zip(line0, n_lines, strict=True)]
        ok = np.array([o.size >= max(min_pixels, 2 * n_groups) for o in owned])
        pix[:, j] = [o.size for o in owned]
        centre[:, j] = [o.mean() if o.size else np.nan for o in owned]
        if not np.any(ok):
            continue
        spec = sfft.fft(np.asarray(echo[:, sample0[j]:sample0[j] + n_samples[j]], np.complex64), axis=0,
                        workers=budget())
        for i in np.flatnonzero(ok):
            def d_of(f, seg=owned[i], spec=spec, ka_j=ka[j]):
                return float(_balance(*look_powers(spec, prf, f, ka_j, band), [seg])[0])

            root = _root(d_of, float(f_start[j]), max_step, tol_hz, max_iter)
            if root is None:
                continue
            s_i = (d_of(root + step_hz) - d_of(root - step_hz)) / (2.0 * step_hz)
            if not s_i < 0:
                continue
            p_lo, p_hi = look_powers(spec, prf, root, ka[j], band)
            steps = -_balance(p_lo, p_hi, np.array_split(owned[i], n_groups)) / s_i
            fbb[i, j] = wrap_frequency(root, prf)
            sig[i, j] = np.std(steps, ddof=1) / np.sqrt(steps.size) * coverage_factor(steps.size - 1)
            slope[i, j] = s_i
    return LookBalance(fbb, sig, pix, centre, slope, margin)
