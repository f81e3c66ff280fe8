"""Point-target quality: IRW, PSLR, ISLR in range and azimuth, peak position and phase.

Procedure for one target (image coordinates: row = azimuth line, col = range sample):

1. the peak is the largest |pixel| within +-``search`` pixels of the expected position;
2. a chip of 2h x 2h pixels around it (zeros beyond the image) is demodulated by its carriers (the
   azimuth spectrum of an SLC is centred on the Doppler centroid): the carrier per axis is the phase of
   the lag-1 correlation of the central 17 x 17 pixels, in cycles per pixel;
3. Fourier interpolation (zero-padded FFT, x ``upsample``) of the central 16 x 16 pixels locates the
   peak to 1/``upsample`` pixel, refined by a parabola through the three samples around the maximum;
4. the chip is shifted (FFT phase ramp) so that the peak sits on a pixel, and the range and azimuth
   cuts through it are Fourier-interpolated x ``upsample``;
5. on each cut: IRW = width at half power (-3 dB), main lobe = between the first minima either side
   (searched beyond the half-power points, so that noise on a wide lobe is not taken for a minimum),
   PSLR = largest sidelobe / peak (dB), ISLR = sidelobe energy / main-lobe energy (dB) with the
   sidelobes counted out to ``extent`` main-lobe half-widths (null-to-peak distances) either side.

Theory (continuous IRF of the window, ``extent`` = 20): rect PSLR -13.26 dB, ISLR -10.1 dB, IRW 0.886/B.
The peak phase is that of the original (not demodulated) image at the interpolated peak.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from sarcli.errors import ProductError, SarcliError


@dataclass
class CutMetrics:
    """Metrics of a 1-D cut (widths in input pixels)."""

    irw: float
    pslr_db: float
    islr_db: float
    null_distance: float


def cut_metrics(cut: np.ndarray, step: float, extent: float = 20.0) -> CutMetrics:
    """Metrics of a finely sampled 1-D IRF ``cut`` (spacing ``step`` pixels), peak anywhere inside."""
    p = np.abs(np.asarray(cut)) ** 2
    i0 = int(np.argmax(p))
    pk = p[i0]
    if not pk > 0:
        raise SarcliError("no signal at the target position (all-zero cut)")
    half = 0.5 * pk

    def crossing(direction: int) -> float:
        i = i0
        while 0 <= i + direction < p.size and p[i + direction] > half:
            i += direction
        j = i + direction
        if not 0 <= j < p.size:
            return float(i)
        return i + direction * (p[i] - half) / (p[i] - p[j])

    irw = (crossing(1) - crossing(-1)) * step

    def first_min(direction: int) -> int:
        # start where the main lobe is 10 dB down (every usual window's lobe passes -10 dB before its
        # first null): a noise ripple on the flank of a wide, noisy main lobe is not its first minimum
        i = i0
        while 0 <= i + direction < p.size and p[i] > 0.1 * pk:
            i += direction
        while 0 <= i + direction < p.size and p[i + direction] <= p[i]:
            i += direction
        return i

    lo, hi = first_min(-1), first_min(1)
    null = 0.5 * (hi - lo)
    reach = int(round(extent * null))
    a, b = max(0, i0 - reach), min(p.size, i0 + reach + 1)
    main = p[lo:hi + 1].sum()
    side = p[a:lo].sum() + p[hi + 1:b].sum()
    sides = np.concatenate([p[a:lo], p[hi + 1:b]])
    pslr = 10.0 * np.log10(sides.max() / pk) if sides.size and sides.max() > 0 else -np.inf
    islr = 10.0 * np.log10(side / main) if side > 0 else -np.inf
    return CutMetrics(irw, float(pslr), float(islr), null * step)


def _chip(image: np.ndarray, r: int, c: int, h: int) -> np.ndarray:
    out = np.zeros((2 * h, 2 * h), np.complex128)
    r0, c0 = r - h, c - h
    a, b = max(0, r0), min(image.shape[0], r0 + 2 * h)
    d, e = max(0, c0), min(image.shape[1], c0 + 2 * h)
    if a < b and d < e:
        out[a - r0:b - r0, d - c0:e - c0] = image[a:b, d:e]
    return out


def _carrier(chip: np.ndarray, h: int, axis: int) -> float:
    core = chip[h - 8:h + 9, h - 8:h + 9]
    if axis == 0:
        cc = np.sum(core[1:] * np.conj(core[:-1]))
    else:
        cc = np.sum(core[:, 1:] * np.conj(core[:, :-1]))
    return float(np.angle(cc) / (2 * np.pi)) if abs(cc) > 0 else 0.0


def _upsample1(x: np.ndarray, u: int) -> np.ndarray:
    n = x.size
    spec = np.fft.fftshift(np.fft.fft(x))
    pad = np.zeros(n * u, complex)
    s = (n * u - n) // 2
    pad[s:s + n] = spec
    return np.fft.ifft(np.fft.ifftshift(pad)) * u


def _upsample2(x: np.ndarray, u: int) -> np.ndarray:
    n, m = x.shape
    spec = np.fft.fftshift(np.fft.fft2(x))
    pad = np.zeros((n * u, m * u), complex)
    a, b = (n * u - n) // 2, (m * u - m) // 2
    pad[a:a + n, b:b + m] = spec
    return np.fft.ifft2(np.fft.ifftshift(pad)) * u * u


def _parabola(y: np.ndarray, i: int) -> float:
    if 0 < i < y.size - 1:
        den = y[i - 1] - 2 * y[i] + y[i + 1]
        if den < 0:
            return i + 0.5 * (y[i - 1] - y[i + 1]) / den
    return float(i)


def point_target_metrics(image: np.ndarray, row: float, col: float, search: int = 3, half: int = 64,
                         upsample: int = 16, extent: float = 20.0, azimuth_carrier: float | None = None) -> dict:
    """Quality of the point target expected near (row, col); widths in pixels, dB for ratios.

    ``azimuth_carrier`` (cycles per line, = fdc / PRF with the ambiguity) replaces the estimated one
    (which is only known modulo 1): the phase at a fractional peak needs the absolute carrier.

    Returns ``row``, ``col`` (fractional peak position), ``irw_range_px``, ``irw_azimuth_px``,
    ``pslr_range_db``, ``pslr_azimuth_db``, ``islr_range_db``, ``islr_azimuth_db``, ``peak_amplitude``,
    ``peak_phase_rad``.
    """
    img = np.asarray(image)
    r, c = int(round(row)), int(round(col))
    if not (0 <= r < img.shape[0] and 0 <= c < img.shape[1]):
        raise SarcliError(f"target position ({row:.1f}, {col:.1f}) is outside the image {img.shape}")
    a, b = max(0, r - search), min(img.shape[0], r + search + 1)
    d, e = max(0, c - search), min(img.shape[1], c + search + 1)
    win = np.abs(img[a:b, d:e])
    if not np.any(win > 0):
        raise SarcliError(f"no signal near ({row:.1f}, {col:.1f})")
    ia, ir = np.unravel_index(int(np.argmax(win)), win.shape)
    r, c = a + int(ia), d + int(ir)
    chip = _chip(img, r, c, half)
    fa, fr = _carrier(chip, half, 0), _carrier(chip, half, 1)
    if azimuth_carrier is not None:
        fa = float(azimuth_carrier)
    m = np.arange(2 * half) - half
    demod = chip * np.exp(-2j * np.pi * (fa * m[:, None] + fr * m[None, :]))
    core = demod[half - 8:half + 8, half - 8:half + 8]
    up = np.abs(_upsample2(core, upsample))
    pa, pr = np.unravel_index(int(np.argmax(up)), up.shape)
    da = (_parabola(up[:, pr], int(pa)) / upsample) - 8.0
    dr = (_parabola(up[pa, :], int(pr)) / upsample) - 8.0
    # shift so that the peak falls on pixel (half, half)
    ka = np.fft.fftfreq(2 * half)[:, None]
    kr = np.fft.fftfreq(2 * half)[None, :]
    shifted = np.fft.ifft2(np.fft.fft2(demod) * np.exp(2j * np.pi * (ka * da + kr * dr)))
    peak = shifted[half, half]
    rg = cut_metrics(_upsample1(shifted[half, :], upsample), 1.0 / upsample, extent)
    az = cut_metrics(_upsample1(shifted[:, half], upsample), 1.0 / upsample, extent)
    phase = np.angle(peak) + 2 * np.pi * (fa * da + fr * dr)
    return {
        "row": r + da, "col": c + dr,
        "irw_range_px": rg.irw, "irw_azimuth_px": az.irw,
        "pslr_range_db": rg.pslr_db, "pslr_azimuth_db": az.pslr_db,
        "islr_range_db": rg.islr_db, "islr_azimuth_db": az.islr_db,
        "peak_amplitude": float(np.abs(peak)), "peak_phase_rad": float(np.angle(np.exp(1j * phase))),
    }


@dataclass(frozen=True)
class TruthDoppler:
    """A simulated product's Doppler truth as a Doppler model (:class:`sarcli.model.doppler.DopplerModel`):
    centroid (Hz) and rate (Hz/s) per slant range (m), interpolated linearly, the same at every time; for
    benchmarks and tests that must take the estimator out of a focuser's error."""

    ranges_m: np.ndarray
    centroid_hz: np.ndarray
    rate_hz_per_s: np.ndarray

    @classmethod
    def of(cls, raw) -> TruthDoppler:
        """The truth of the simulated raw product ``raw`` (its ``doppler_centroid_hz``, ``doppler_rate_hz_per_s``
        per range sample)."""
        if raw.truth is None or "doppler_centroid_hz" not in raw.truth:
            raise ProductError("the product carries no Doppler truth (not simulated by sarcli simulate)")
        return cls(raw.slant_range(), np.asarray(raw.truth["doppler_centroid_hz"], np.float64),
                   np.asarray(raw.truth["doppler_rate_hz_per_s"], np.float64))

    def fdc(self, range_m, azimuth_time_s=0.0) -> np.ndarray:
        return np.interp(range_m, self.ranges_m, self.centroid_hz)

    def fr(self, range_m, azimuth_time_s=0.0) -> np.ndarray:
        return np.interp(range_m, self.ranges_m, self.rate_hz_per_s)


def truth_targets(truth: dict | None) -> list[tuple[float, float]]:
    """(zero-Doppler time s, closest range m) of the point targets in a simulated product's truth."""
    if truth is None or "targets" not in truth:
        return []
    t = truth["targets"]
    names = getattr(getattr(t, "dtype", None), "names", None) or ()
    if getattr(t, "ndim", 0) != 1:
        raise ProductError("the product's truth table of targets is not a table (one row per target)")
    tk = next((k for k in ("zero_doppler_time_s", "zero_doppler_time") if k in names), None)
    rk = next((k for k in ("closest_range_m", "slant_range_m") if k in names), None)
    if tk is None or rk is None:
        return []
    out = [(float(a), float(b)) for a, b in zip(t[tk], t[rk], strict=True)]
    if not all(math.isfinite(a) and math.isfinite(b) for a, b in out):
        raise ProductError("the product's truth table of targets holds non-finite positions")
    return out


def azimuth_ground_spacing(slc) -> float:
    """Azimuth pixel spacing on the ground (m): geolocated with an Earth orbit, else V_eff / PRF."""
    if slc.orbit is None or slc.orbit.frame not in ("ECI", "ECEF") or slc.azimuth_time.size < 2:
        return float(slc.azimuth_spacing_m)
    from sarcli.focus.geocode import recorded_height
    from sarcli.focus.geolocation import zero_doppler_points
    from sarcli.model.terrain import ConstantHeight

    n = slc.azimuth_time.size
    a, b = max(0, n // 2 - 50), min(n - 1, n // 2 + 50)
    r = slc.slant_range[slc.slant_range.size // 2]
    p = zero_doppler_points(slc.orbit, slc.epoch_utc, slc.azimuth_time[[a, b]], r, slc.radar.wavelength_m,
                            slc.look_side, ConstantHeight(recorded_height(slc)))
    return float(np.linalg.norm(p[1] - p[0]) / (b - a))


def measure_targets(slc, positions: list[tuple[float, float]], truth_known: bool) -> list[dict]:
    """Quality of targets at (zero-Doppler time, slant range); metrics in metres, errors when truth_known."""
    t, r = slc.azimuth_time, slc.slant_range
    dt = float(t[1] - t[0])
    dr = float(r[1] - r[0])
    ds_az = azimuth_ground_spacing(slc)
    out = []
    for ti, ri in positions:
        row = (ti - t[0]) / dt
        col = (ri - r[0]) / dr
        m = point_target_metrics(slc.image, row, col)
        e_az = (m["row"] - row) * ds_az
        e_rg = (m["col"] - col) * dr
        rec = {
            "range_m": float(r[0] + m["col"] * dr), "azimuth_time_s": float(t[0] + m["row"] * dt),
            "row": float(m["row"]), "col": float(m["col"]),
            "irw_range_m": m["irw_range_px"] * dr, "irw_azimuth_m": m["irw_azimuth_px"] * ds_az,
            "pslr_range_db": m["pslr_range_db"], "pslr_azimuth_db": m["pslr_azimuth_db"],
            "islr_range_db": m["islr_range_db"], "islr_azimuth_db": m["islr_azimuth_db"],
            "peak_amplitude": m["peak_amplitude"],
        }
        if truth_known:
            rec.update({"position_error_m": float(np.hypot(e_az, e_rg)), "position_error_range_px": m["col"] - col,
                        "position_error_azimuth_px": m["row"] - row})
        out.append(rec)
    return out


def image_statistics(blocks) -> dict:
    """Focus-quality statistics of an image (no targets needed), on intensity I = |z|^2.

    ``blocks``: the image, or an iterable of row blocks (bounded memory for full scenes).
    contrast = std(I) / mean(I) (higher = sharper; 1 for fully developed speckle);
    entropy = -sum(p ln p), p = I / S, S = sum(I) (lower = sharper; the autofocus criterion),
    accumulated as ln S - sum(I ln I) / S in float64 (:func:`line_sums`, :func:`statistics_from_sums`).
    """
    if isinstance(blocks, np.ndarray):
        blocks = [blocks]
    return statistics_from_sums(sum((line_sums(b).sum(axis=0) for b in blocks), np.zeros(4)))


def line_sums(block: np.ndarray) -> np.ndarray:
    """Per line of ``block`` (lines x samples, complex): (n_pixels, sum I, sum I^2, sum I ln I), float64
    (lines, 4), I = |z|^2 = re^2 + im^2 in float64 (0 ln 0 = 0). The statistics of any set of lines are
    those of the sums of their rows (:func:`statistics_from_sums`): a focused block's sums are computed
    as it streams past, in any order. One pass (:func:`_line_sums`), every line summed by one thread in
    sample order: the sums do not depend on the thread count."""
    return _line_sums(np.asarray(block))


@njit(cache=True, parallel=True)
def _line_sums(block: np.ndarray) -> np.ndarray:
    n, m = block.shape
    out = np.empty((n, 4))
    for i in prange(n):
        s1 = 0.0
        s2 = 0.0
        sl = 0.0
        for j in range(m):
            z = block[i, j]
            x = np.float64(z.real) * np.float64(z.real) + np.float64(z.imag) * np.float64(z.imag)
            s1 += x
            s2 += x * x
            if x > 0.0:
                sl += x * np.log(x)
        out[i, 0] = m
        out[i, 1] = s1
        out[i, 2] = s2
        out[i, 3] = sl
    return out


def statistics_from_sums(sums: np.ndarray) -> dict:
    """contrast, entropy and n_pixels (:func:`image_statistics`) from summed (n, sum I, sum I^2, sum I ln I)."""
    n, s1, s2, sl = (float(v) for v in sums)
    if not s1 > 0:
        raise SarcliError("image has no signal: statistics undefined")
    mean = s1 / n
    return {"contrast": float(np.sqrt(max(s2 / n - mean * mean, 0.0)) / mean),
            "entropy": float(np.log(s1) - sl / s1), "n_pixels": int(n)}
