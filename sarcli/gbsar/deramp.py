"""Deramp-FFT (DF) focusing of [LeeGBSAR-II-2007, eq. 4-12] and its geometric correction.

Expanding ``R(x) = sqrt(R0^2 + (x - xc)^2)`` about the rail centre (x measured from it) gives
``R ~ Rc - (xc/Rc) x + (R0^2/(2 Rc^3)) x^2`` (the printed eq. 6-7 mix R0 and Rc). DF multiplies the
range profile at range bin r by the deramp ``exp(+j 2 pi x^2/(lam r))`` (eq. 10: ``Rc ~ R0 ~ r``),
applies the azimuth window and takes one FFT over x (eq. 8):

    g(r, u) = sum_i w_i P_i(r) exp(+j 2 pi x_i^2/(lam r)) exp(-j 2 pi u x_i) / sum_i w_i

A point at (Rc, xc) peaks at ``u = 2 xc/(lam Rc)``, i.e. at ``sin(theta) = lam u/2 = xc/Rc``: the
native grid is polar (Rc, sin theta) with pixel ``lam Rc du/2`` (Table 1: 0.00445 Rc for
N_xfft = 128; the DFT bin is ``du = 1/(N_xfft dx)``, Table 1's ``1/((N_xfft-1) dx)`` differs by
0.8 %). The image phase is ``-4 pi Rc/lam`` (eq. 9). The residual error of the deramp is eq. 11;
below the range of eq. 12 the image defocuses, which is the point of :mod:`sarcli.gbsar.system`.

Geometric correction resamples the polar image bilinearly (it is baseband in r and, for a full
rail aperture, in u) at ``Rc = hypot(x, R0)``, ``sin(theta) = x/Rc`` of each Cartesian pixel and
converts the phase to the common convention ``-4 pi R0/lam`` by the factor ``exp(-j 4 pi (R0 - Rc)/lam)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft
from numba import njit, prange

from sarcli.errors import SarcliError
from sarcli.gbsar.rangecomp import RangeProfiles, stop_weights
from sarcli.gbsar.system import next_pow2


@dataclass
class PolarImage:
    """DF image on its native grid: ``data`` (n_r, n_u) over ranges Rc (m) and ``sines`` (sin theta, increasing)."""

    data: np.ndarray
    ranges_m: np.ndarray
    sines: np.ndarray
    rail_centre_m: float


def uniform_step(positions: np.ndarray) -> float:
    """Rail step of uniformly spaced stops; one-line error otherwise (DF and RD need a uniform rail)."""
    x = np.asarray(positions, np.float64)
    if x.size < 2:
        raise SarcliError("focusing needs at least 2 rail positions")
    d = np.diff(x)
    if not np.all(np.abs(d - d[0]) <= 1e-6 * max(abs(d[0]), 1e-12)):
        raise SarcliError("rail steps are not uniform: DF and RD need a uniform rail; use --algorithm bp")
    return float((x[-1] - x[0]) / (x.size - 1))


def focus_df(prof: RangeProfiles, n_xfft: int | None = None, azimuth_window: str = "hamming") -> PolarImage:
    """DF on the polar grid; ``n_xfft`` defaults to Table 1's ``2^n >= N_x``."""
    dx = uniform_step(prof.positions_m)
    n_x = prof.positions_m.size
    n = next_pow2(n_x) if n_xfft is None else int(n_xfft)
    if n < n_x:
        raise SarcliError(f"N_xfft = {n} is smaller than the {n_x} rail stops")
    centre = 0.5 * (prof.positions_m[0] + prof.positions_m[-1])
    x = prof.positions_m - centre
    lam = prof.wavelength_m
    r = prof.ranges_m
    w = stop_weights(prof, azimuth_window)
    with np.errstate(divide="ignore", invalid="ignore"):
        phase = (2 * np.pi / lam * x[:, None] ** 2 / r[None, :]).astype(np.float32)  # < 2e3 rad: float32 ok
    phase[:, r <= 0] = 0.0
    a = prof.data * np.exp(1j * phase)  # complex64 throughout: the paper's 8-byte samples
    a *= (w / w.sum()).astype(np.float32)[:, None]
    a[:, r <= 0] = 0.0  # r = 0: no deramp defined, no image
    g = scipy.fft.fft(a, n=n, axis=0)  # (n_u, n_r), kernel exp(-j 2 pi k i / n)
    u = scipy.fft.fftfreq(n, dx)
    g *= np.exp(-2j * np.pi * u * x[0])[:, None].astype(np.complex64)  # x_i = x_0 + i dx
    g = scipy.fft.fftshift(g, axes=0)
    sines = scipy.fft.fftshift(u) * lam / 2
    return PolarImage(data=np.ascontiguousarray(g.T), ranges_m=r, sines=sines, rail_centre_m=float(centre))


def _frac_index(axis: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Fractional index of v on a uniform increasing axis (NaN outside)."""
    f = (v - axis[0]) / (axis[1] - axis[0])
    return np.where((f >= 0) & (f <= axis.size - 1), f, np.nan)


def bilinear(data: np.ndarray, fi: np.ndarray, fj: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of complex ``data`` at fractional (row, col) indices; NaN -> 0 + mask."""
    ok = np.isfinite(fi) & np.isfinite(fj)
    i = np.where(ok, fi, 0.0)
    j = np.where(ok, fj, 0.0)
    i0 = np.minimum(np.floor(i).astype(np.int64), data.shape[0] - 2)
    j0 = np.minimum(np.floor(j).astype(np.int64), data.shape[1] - 2)
    ti, tj = (i - i0).astype(np.float32), (j - j0).astype(np.float32)
    v = ((data[i0, j0] * (1 - tj) + data[i0, j0 + 1] * tj) * (1 - ti)
         + (data[i0 + 1, j0] * (1 - tj) + data[i0 + 1, j0 + 1] * tj) * ti)
    return np.where(ok, v, 0).astype(np.complex64)


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy")
def polar_to_cartesian_kernel(data, r_first, dr, s_first, ds, ranges, azimuths, k4, out, covered):
    """Bilinear resampling of the polar DF image ``data`` (n_rc, n_s) onto (R0 rows, x cols), with the
    phase conversion ``exp(-j k4 (R0 - Rc))``; ``azimuths`` are relative to the rail centre."""
    n_rc, n_s = data.shape
    for i in prange(ranges.size):
        r0 = ranges[i]
        for j in range(azimuths.size):
            x = azimuths[j]
            rc = np.sqrt(x * x + r0 * r0)
            s = x / rc if rc > 0 else 0.0
            fi = (rc - r_first) / dr
            fj = (s - s_first) / ds
            if fi < 0 or fi > n_rc - 1 or fj < 0 or fj > n_s - 1:
                out[i, j] = 0
                covered[i, j] = False
                continue
            i0 = min(int(fi), n_rc - 2)
            j0 = min(int(fj), n_s - 2)
            ti = fi - i0
            tj = fj - j0
            v = ((data[i0, j0] * (1 - tj) + data[i0, j0 + 1] * tj) * (1 - ti)
                 + (data[i0 + 1, j0] * (1 - tj) + data[i0 + 1, j0 + 1] * tj) * ti)
            out[i, j] = v * np.exp(-1j * k4 * (r0 - rc))
            covered[i, j] = True


def geometric_correction(img: PolarImage, ranges: np.ndarray, azimuths: np.ndarray,
                         wavelength_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Resample the DF polar image onto the Cartesian grid (R0 rows, x columns) -> (image, covered mask)."""
    if img.ranges_m.size < 2 or img.sines.size < 2:
        raise SarcliError("the DF image is too small to resample")
    r0 = np.ascontiguousarray(ranges, np.float64)
    x = np.ascontiguousarray(np.asarray(azimuths, np.float64) - img.rail_centre_m)
    out = np.empty((r0.size, x.size), np.complex64)
    covered = np.empty((r0.size, x.size), np.bool_)
    polar_to_cartesian_kernel(np.ascontiguousarray(img.data), float(img.ranges_m[0]),
                              float(img.ranges_m[1] - img.ranges_m[0]), float(img.sines[0]),
                              float(img.sines[1] - img.sines[0]), r0, x, 4 * np.pi / wavelength_m, out, covered)
    return out, covered


def geometric_correction_reference(img: PolarImage, ranges: np.ndarray, azimuths: np.ndarray,
                                   wavelength_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Plain-numpy reference of :func:`geometric_correction`."""
    r0 = np.asarray(ranges, np.float64)[:, None]
    x = np.asarray(azimuths, np.float64)[None, :] - img.rail_centre_m
    rc = np.hypot(x, r0)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(rc > 0, x / rc, 0.0)
    fi, fj = _frac_index(img.ranges_m, rc), _frac_index(img.sines, s)
    out = bilinear(img.data, fi, fj)
    out *= np.exp(-1j * 4 * np.pi * (r0 - rc) / wavelength_m).astype(np.complex64)
    return out, np.isfinite(fi) & np.isfinite(fj)


@njit(cache=True, parallel=True)
def aperture_gain_kernel(x, cs, half_coef, ranges, azimuths, out):
    """Numba kernel of :func:`aperture_gain` (``cs`` = cumulative taper sums with a leading 0)."""
    n = x.size
    rail = x[n - 1] - x[0]
    for i in prange(ranges.size):
        half = half_coef * ranges[i]
        nominal = min(rail, 2.0 * half)
        for j in range(azimuths.size):
            a = max(x[0], azimuths[j] - half)
            b = min(x[n - 1], azimuths[j] + half)
            if b < a:
                out[i, j] = 0.0
                continue
            s = cs[np.searchsorted(x, b, "right")] - cs[np.searchsorted(x, a, "left")]
            if s <= 0:
                out[i, j] = 0.0
            else:
                out[i, j] = cs[n] / s * ((b - a) / nominal if nominal > 0 else 1.0)


def aperture_gain(prof: RangeProfiles, antenna_length_m: float, ranges: np.ndarray, azimuths: np.ndarray,
                  azimuth_window: str = "hamming") -> np.ndarray:
    """Per-pixel amplitude correction (n_r, n_x) float32 that puts DF on BP's normalization.

    DF divides by the taper sum over the whole rail, but a scatterer at (x, R0) is seen only from its
    synthetic aperture ``[a, b]`` = rail ∩ beam footprint ``|x_i - x| <= lam R0/(2 L_x)``; BP divides by
    the taper sum over [a, b] and scales by ``(b - a)/min(X, lam R0/L_x)`` where a rail end cuts it.
    The gain ``sum_rail w / sum_[a,b] w * (b - a)/min(X, lam R0/L_x)`` is 1 in region II and makes the
    stitched ``auto`` image continuous where DF takes over in region I; 0 where no stop sees the pixel.
    """
    cs = np.concatenate([[0.0], np.cumsum(stop_weights(prof, azimuth_window))])
    out = np.empty((np.size(ranges), np.size(azimuths)), np.float32)
    aperture_gain_kernel(prof.positions_m, cs, prof.wavelength_m / (2 * antenna_length_m),
                         np.ascontiguousarray(ranges, np.float64), np.ascontiguousarray(azimuths, np.float64), out)
    return out


def aperture_gain_reference(prof: RangeProfiles, antenna_length_m: float, ranges: np.ndarray,
                            azimuths: np.ndarray, azimuth_window: str = "hamming") -> np.ndarray:
    """Plain-numpy reference of :func:`aperture_gain`."""
    x = prof.positions_m
    cs = np.concatenate([[0.0], np.cumsum(stop_weights(prof, azimuth_window))])
    half = prof.wavelength_m / (2 * antenna_length_m) * np.asarray(ranges, np.float64)[:, None]
    px = np.asarray(azimuths, np.float64)[None, :]
    a, b = np.maximum(x[0], px - half), np.minimum(x[-1], px + half)
    s = cs[np.searchsorted(x, b, "right")] - cs[np.searchsorted(x, a, "left")]
    nominal = np.minimum(x[-1] - x[0], 2 * half)
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.where((s > 0) & (b >= a), cs[-1] / s * np.where(nominal > 0, (b - a) / nominal, 1.0), 0.0)
    return g.astype(np.float32)
