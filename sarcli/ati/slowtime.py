"""Between RD-focused images and a mover's slow-time signal ([Ryu2017, Fig. 2, steps 3-4, and eq. 21]).

The RDA (``sarcli.focus.rda``) forms, per range bin i with closest range R0_i, effective velocity
V_i, centroid fdc_i and integer line shift ``shift``, the SLC ``Z = IFFT_az[ W * P * RCMC(S) ]`` with
the azimuth reference phase (see ``sarcli.focus.rcmc``)

    P_i(f) = exp(+j*4*pi*R0_i*(D_i(f) - 1)/lam + j*pi/4 - j*2*pi*f_bin*shift/PRF),
    D_i(f) = sqrt(1 - (lam*f/(2*V_i))**2),  f = fdc_i + wrap(f_bin - fdc_i)

and the window W. Hence the RCMC'd, range-compressed slow-time signal of a sub-image ([Ryu2017]'s
s_RDA) is ``IFFT_az[ FFT_az(Z_sub) * conj(P) ]`` (the window stays as a taper), and a corrected
slow-time signal is re-compressed with ``IFFT_az[ FFT_az(s) * P ]``. Both transforms run on a
zero-padded grid (the image at offset ``n_lines//2``) so that nothing wraps around.

Channel co-registration (DRA): receiver k at along-track offset d_k has its effective phase centre
d_k/2 ahead, so its image shows every scatterer d_k/(2*Vp) s EARLIER; it is delayed by that much in
the azimuth-frequency domain (``exp(-j*2*pi*f*delay)``).

ANV ([Ryu2017, eq. 12]): ``1 - mean(|s_n|)**2 / mean(|s_n|**2)``: 0 for a constant-amplitude signal,
1 - pi/4 = 0.215 for Gaussian noise; the bin with the smallest value holds the mover.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft
from scipy import ndimage

from sarcli.errors import SarcliError
from sarcli.focus.kinematics import migration_factor


def _grid(n_lines: int) -> tuple[int, int]:
    """(FFT length, offset of the image in it)."""
    return sfft.next_fast_len(2 * n_lines), n_lines // 2


def reference_phase(slc, cols: slice, n_fft: int) -> np.ndarray:
    """The RDA's azimuth reference ``P`` (n_fft, n_cols) for the columns ``cols`` of ``slc``."""
    d = slc.doppler
    if np.asarray(d.fdc_hz).shape[0] != 1:
        raise SarcliError("ATI sub-images need a single-block RD focusing (raise block_lines)")
    prf = float(slc.parameters.get("prf_hz", slc.prf_hz))
    shift = int(slc.parameters.get("shift_lines", 0))
    lam = float(slc.radar.wavelength_m)
    fdc = np.asarray(d.fdc_hz)[0, cols]
    v = np.asarray(d.velocity_mps)[0, cols]
    r0 = np.asarray(slc.slant_range)[cols]
    f_bin = sfft.fftfreq(n_fft, 1.0 / prf)[:, None]
    off = f_bin - fdc
    f = fdc + off - prf * np.floor(off / prf + 0.5)
    dm1 = migration_factor(f, v, lam) - 1.0
    ph = 4.0 * np.pi * r0 * dm1 / lam + np.pi / 4.0 - 2.0 * np.pi * f_bin * shift / prf
    return np.exp(1j * ph)


def _az_filter(block: np.ndarray, mult: np.ndarray) -> np.ndarray:
    n_lines = block.shape[0]
    n_fft, off = _grid(n_lines)
    buf = np.zeros((n_fft, block.shape[1]), np.complex128)
    buf[off:off + n_lines] = block
    out = sfft.ifft(sfft.fft(buf, axis=0) * mult, axis=0)
    return out[off:off + n_lines]


def decompress(slc, image: np.ndarray, rows: slice, cols: slice, delay_s: float = 0.0) -> np.ndarray:
    """Slow-time signals (n_lines, n_cols) of the sub-image ``image[rows, cols]`` (zero elsewhere),
    delayed by ``delay_s`` (co-registration); time axis = the raw pulse times."""
    n_lines = image.shape[0]
    sub = np.zeros((n_lines, image[:, cols].shape[1]), np.complex128)
    sub[rows] = image[rows, cols]
    n_fft, _ = _grid(n_lines)
    p = reference_phase(slc, cols, n_fft)
    prf = float(slc.parameters.get("prf_hz", slc.prf_hz))
    delay = np.exp(-2j * np.pi * sfft.fftfreq(n_fft, 1.0 / prf) * delay_s)[:, None]
    return _az_filter(sub, np.conj(p) * delay)


def recompress(slc, slow: np.ndarray, cols: slice) -> np.ndarray:
    """Azimuth-compress slow-time signals (n_lines, n_cols) with the RDA's reference phase."""
    n_fft, _ = _grid(slow.shape[0])
    return _az_filter(slow, reference_phase(slc, cols, n_fft))


def coregister(slc, image: np.ndarray, delay_s: float) -> np.ndarray:
    """Delay a whole image by ``delay_s`` in azimuth (frequency-domain shift), complex64."""
    n_lines = image.shape[0]
    n_fft, _ = _grid(n_lines)
    prf = float(slc.parameters.get("prf_hz", slc.prf_hz))
    mult = np.exp(-2j * np.pi * sfft.fftfreq(n_fft, 1.0 / prf) * delay_s)[:, None]
    return _az_filter(image, mult).astype(np.complex64)


def anv(slow: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """Amplitude-normalized variance per column ([Ryu2017, eq. 12]), over rows with weight > 0."""
    a = np.abs(slow)
    w = np.ones(a.shape[0]) if weights is None else np.asarray(weights, np.float64)
    m1 = np.average(a, axis=0, weights=w)
    m2 = np.average(a * a, axis=0, weights=w)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(m2 > 0, 1.0 - m1 * m1 / m2, 1.0)


def choose_bin(slow: np.ndarray, min_power_fraction: float = 0.1) -> int:
    """Column with the smallest ANV among those holding at least ``min_power_fraction`` of the
    strongest column's power (noise-only bins can have a small ANV by chance)."""
    p = np.sum(np.abs(slow) ** 2, axis=0)
    if not np.any(p > 0):
        raise SarcliError("the mover's sub-image is empty")
    v = anv(slow)
    v[p < min_power_fraction * p.max()] = np.inf
    return int(np.argmin(v))


def track_peak(slow: np.ndarray, col: int, halfwidth: int = 4, smooth: int = 63) -> tuple[np.ndarray, np.ndarray]:
    """Range tracking: per row, the sample nearest a smooth track of the magnitude peak within
    ``col +- halfwidth``, and that track (fractional column).

    A mover's range history differs from the stationary one the RCMC assumes, so it drifts by a
    few range bins over a long aperture (R'^2*R*(1/V^2 - 1/Vp^2)/2, ~2.4 m at the start of the
    paper's CPI); a single bin (the ANV choice of [Ryu2017, eq. 12]) then loses it and picks up the phase of
    the compressed pulse's sidelobes. Within the mainlobe the phase of the compressed pulse is
    flat, so the sample at the track carries the mover's phase. The per-row peaks (parabolic
    interpolation of the magnitude) are median-filtered over ``smooth`` rows so that noise peaks
    at low SNR do not make the track jump to noise bins.
    """
    a, b = max(0, col - halfwidth), min(slow.shape[1], col + halfwidth + 1)
    blk = slow[:, a:b]
    mag = np.abs(blk)
    k = np.argmax(mag, axis=1)
    rows = np.arange(blk.shape[0])
    km, kp = np.clip(k - 1, 0, blk.shape[1] - 1), np.clip(k + 1, 0, blk.shape[1] - 1)
    y0, y1, y2 = mag[rows, km], mag[rows, k], mag[rows, kp]
    den = y0 - 2.0 * y1 + y2
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.where((den < 0) & (km != k) & (kp != k), 0.5 * (y0 - y2) / den, 0.0)
    track = ndimage.median_filter(k + off, size=min(smooth, 2 * (blk.shape[0] // 2) - 1 or 1), mode="nearest")
    kk = np.clip(np.rint(track).astype(int), 0, blk.shape[1] - 1)
    return blk[rows, kk], a + track


def single_bin(slow: np.ndarray, col: int) -> tuple[np.ndarray, np.ndarray]:
    """The choice of [Ryu2017, eq. 12]: one range bin for all rows (signal and its constant column)."""
    return slow[:, col], np.full(slow.shape[0], float(col))
