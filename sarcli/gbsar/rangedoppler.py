"""Range-Doppler (RD) focusing of [LeeGBSAR-II-2007, eq. 13-21] with the N_xfft rule of Table 1.

About the target's own azimuth xc the phase history is the azimuth chirp of eq. 18
(``u_Dc = 0``, ``u_R = -2/(lam R0)``); it is shift-invariant in x at fixed R0, so RD correlates each
range row with the reference of eq. 19, limited to the beam footprint ``|x| <= lam R0/(2 L_x)``
(``reference="rect"``, the paper's ideal beam) or, by default, weighted by the two-way sinc^2 pattern
of the L_x aperture over its main lobe (``reference="sinc"``, a real antenna):

    h_R0(x) = [pattern] * exp(-j 4 pi (sqrt(R0^2 + x^2) - R0)/lam)   (exact hyperbola, not its chirp expansion)
    g(x, R0) = IFFT_u[ FFT_x(P)(u) * conj(H)/|H|^p (u) * W(u) ] / gain,   H = FFT_x h_R0

i.e. the correlation with h_R0 whose spectrum is flattened: in region I a regularized inverse filter
(p = 2, ``|H|^2`` floored at 1 % of its in-band median), because the finite-aperture chirp has
Fresnel ripples in ``|H|`` (time-bandwidth product ~10 at near range) which a plain matched filter
would square into the response (measured: 14 % wider, PSLR -20 dB instead of -43 dB); in region II
a phase-only filter (p = 1), since there each target fills only part of the band;
with the azimuth taper W applied where the synthetic aperture is: over the beam's band ``|u| <= 1/L_x``
(the paper's azimuth Hamming filter) in region I (beam footprint shorter than the rail,
``R0 < X L_x/lam``) and over the rail stops in region II (rail-limited aperture; a taper in u there
would weight off-boresight targets like an antenna pattern). ``gain`` is the response to a unit scatterer at the rail
centre's azimuth (whose data are ``h_R0`` restricted to the rail), so that it focuses to 1 as in BP.

The exact sampled reference is transformed instead of the stationary-phase chirp spectrum, because
the azimuth time-bandwidth product ``2 X^2/(lam R0)`` is ~1 at far range (the stationary-phase
formula, with its pi/4, would not hold). Range cell migration ``R_i - R0`` is corrected in the
azimuth-wavenumber domain with the stationary-phase map ``u = -2 sin(theta)/lam``,
``R = R0/cos(theta)`` (linear interpolation of the baseband range spectrum, oversampled 2x by
default). Pixels: ``dx`` in azimuth at every range (no geometric correction), phase ``-4 pi R0/lam``.
To cover DF's azimuth width ``lam Rc/(2 dx)`` at range Rc the FFT needs ``N_xfft = 2^m >= lam Rc/(2 dx^2) + 1``
samples (zero padding): memory ``N_Rfft x N_xfft x 8`` bytes, the paper's 128 MB outdoors. Here the
azimuth FFTs are done in blocks of range rows (each FFT over x is independent per range bin), so the
peak working memory is a block of ``N_xfft`` x ``block_rows`` plus the output image.

Implementation (:func:`focus_rd`, :func:`focus_rd_pols`): complex64 throughout, rows of the image
contiguous (every FFT runs along contiguous memory, in place in buffers reused from block to block, on
the ``workers`` threads of the budget), the reference rows synthesized by a numba kernel (phase in
float64, ``R - R0 = x^2 / (R + R0)`` without cancellation, its cos/sin by an inline reduction and
Taylor kernels so that the loop vectorizes) and FFT'd with the rail-limited reference of the gain in
one call; a numba pass per row forms the filter over the band (median of ``|H|^p`` by selection)
divided by the gain. The filter depends on the geometry only (rail stops, range bins, wavelength),
so :func:`focus_rd_pols` builds it once per row block for all the polarizations of a scan, and per
polarization a second numba pass forms the RCMC interpolation times the filter, so the block's
output rows need only their IFFT. The exact sampled reference spectrum is kept (see above: no
closed form). The arithmetic is that of the plain numpy :func:`focus_rd_reference` (complex128
reference, ``nanmedian`` per column, one polarization at a time; the test's yardstick and the
benchmark's) up to the order of the float32 roundings, so the images agree within float32 rounding
(tests/gbsar).
"""

from __future__ import annotations

import queue
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import scipy.fft
from numba import njit

from sarcli.errors import SarcliError
from sarcli.gbsar.deramp import uniform_step
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.system import next_pow2
from sarcli.gbsar.windows import taper
from sarcli.threads import fft_workers


@dataclass
class RDImage:
    """RD image ``data`` (n_r, N_xfft) on ranges R0 (m) and azimuths ``x0 + m dx`` (scene frame)."""

    data: np.ndarray
    ranges_m: np.ndarray
    azimuth_first_m: float
    dx_m: float
    n_xfft: int

    @property
    def azimuths_m(self) -> np.ndarray:
        return self.azimuth_first_m + self.dx_m * np.arange(self.n_xfft)


def rd_n_xfft(wavelength_m: float, rc_m: float, dx_m: float, n_x: int) -> int:
    """Table 1: ``N_xfft = 2^m >= max(N_x, lam Rc/(2 dx^2) + 1)``."""
    return next_pow2(max(n_x, wavelength_m * rc_m / (2 * dx_m ** 2) + 1))


_INVERSE_FLOOR = 1e-2  # regularization of the inverse filter, relative to the in-band median |H|^2


def _blocks(r0: np.ndarray, size: int, boundary: float) -> list[np.ndarray]:
    """Row blocks of at most ``size`` rows that do not straddle the region I/II boundary range."""
    cut = int(np.searchsorted(r0, boundary))
    out = []
    for a, b in ((0, cut), (cut, r0.size)):
        out += [np.arange(k, min(k + size, b)) for k in range(a, b, size)]
    return out


@dataclass
class _Plan:
    """What every row block shares: sizes, wavenumber grid, tapers, the rail's lag weights."""

    dx: float
    n_x: int
    n_rows: int
    n: int
    pad: int
    band: np.ndarray  # |u| <= 1/L_x
    w_beam: np.ndarray  # the azimuth taper over the band (region I)
    w_rail: np.ndarray  # the azimuth taper over the rail stops (region II)
    cos_t: np.ndarray
    stretch: float
    offs: np.ndarray  # circular lags x (m)
    w_rail_lag: np.ndarray  # the rail taper at lag x from the rail centre (0 off the rail)
    boundary: float  # region I/II boundary range (m)


def _plan(prof: RangeProfiles, antenna_length_m: float, n_xfft: int | None, azimuth_window: str,
          max_range_m: float | None, reference: str) -> _Plan:
    if reference not in ("rect", "sinc"):
        raise SarcliError(f"unknown RD reference '{reference}' (use rect or sinc)")
    dx = uniform_step(prof.positions_m)
    n_x = prof.positions_m.size
    lam = prof.wavelength_m
    r = prof.ranges_m
    n_rows = r.size if max_range_m is None else int(np.searchsorted(r, max_range_m, side="right"))
    if n_rows < 1:
        raise SarcliError("no range rows to focus with RD")
    n = rd_n_xfft(lam, r[n_rows - 1], dx, n_x) if n_xfft is None else int(n_xfft)
    if n < n_x:
        raise SarcliError(f"N_xfft = {n} is smaller than the {n_x} rail stops")
    centre = 0.5 * (prof.positions_m[0] + prof.positions_m[-1])
    u = scipy.fft.fftfreq(n, dx)
    band = np.abs(u) <= 1.0 / antenna_length_m  # the beam's wavenumbers, |sin(theta)| <= lam/(2 L_x)
    w_beam = np.zeros(n)
    w_beam[np.flatnonzero(band)[np.argsort(u[band])]] = taper(azimuth_window, int(band.sum()))
    w_rail = taper(azimuth_window, n_x)
    sin_t = -lam * u / 2
    cos_t = np.sqrt(np.clip(1.0 - sin_t ** 2, 0.0, None))
    stretch = 1.0 / np.min(cos_t[band]) if band.any() else 1.0
    offs = np.where(np.arange(n) < n - n // 2, np.arange(n), np.arange(n) - n) * dx  # circular lags
    w_rail_lag = np.interp(offs, prof.positions_m - centre, w_rail, left=0.0, right=0.0)
    boundary = (prof.positions_m[-1] - prof.positions_m[0]) * antenna_length_m / lam  # footprint = rail
    return _Plan(dx, n_x, n_rows, n, (n - n_x) // 2, band, w_beam, w_rail, cos_t, stretch, offs, w_rail_lag,
                 boundary)


def _result(prof: RangeProfiles, pl: _Plan, out: np.ndarray) -> RDImage:
    x_first = prof.positions_m[0] - pl.pad * pl.dx
    return RDImage(data=out, ranges_m=prof.ranges_m[:pl.n_rows].copy(), azimuth_first_m=float(x_first),
                   dx_m=pl.dx, n_xfft=pl.n)


# pi/2 = _PIO2_HI + _PIO2_MID + _PIO2_LO: a head with its low 20 mantissa bits cleared (33 significant bits,
# so q * _PIO2_HI is exact for |q| < 2^20), the rest of the double pi/2, and pi/2 - double(pi/2) (which is
# cos(double(pi/2)) to double precision).
_PIO2_HI = float(np.array(np.array(np.pi / 2).view(np.int64) & ~np.int64((1 << 20) - 1)).view(np.float64))
_PIO2_MID = np.pi / 2 - _PIO2_HI
_PIO2_LO = float(np.cos(np.pi / 2))


@njit(cache=True, inline="always", error_model="numpy")
def _cos_sin(ph):
    """(cos ph, sin ph) of a float64 ``ph`` without a library call, so that loops over it vectorize:
    ``ph = q pi/2 + t`` with ``q = rint(2 ph/pi)``, ``|t| <= pi/4`` (pi/2 in three parts: t exact to
    ~1e-16 |q| 2^-53 while ``|q| < 2^20``, else to about the rounding ``|ph| 2^-53`` that ph itself
    carries), the Taylor series of sin t to t^15 and of cos t to t^16 (remainders below
    ``(pi/4)^17/17! = 5e-17``), and the quadrant ``q mod 4`` by selection. Error ~ 1e-15 where
    ``|ph| < 1.6e6``."""
    q = np.rint(ph * (2.0 / np.pi))
    t = ((ph - q * _PIO2_HI) - q * _PIO2_MID) - q * _PIO2_LO
    z = t * t
    s = t * (1.0 + z * (-1.0 / 6 + z * (1.0 / 120 + z * (-1.0 / 5040 + z * (1.0 / 362880 + z * (
        -1.0 / 39916800 + z * (1.0 / 6227020800 + z * (-1.0 / 1307674368000))))))))
    c = 1.0 + z * (-0.5 + z * (1.0 / 24 + z * (-1.0 / 720 + z * (1.0 / 40320 + z * (-1.0 / 3628800 + z * (
        1.0 / 479001600 + z * (-1.0 / 87178291200 + z * (1.0 / 20922789888000))))))))
    m = q - 4.0 * np.floor(0.25 * q)  # q mod 4, exactly
    odd = m == 1.0 or m == 3.0
    cq = s if odd else c
    sq = c if odd else s
    return (-cq if m == 1.0 or m == 2.0 else cq), (-sq if m >= 2.0 else sq)


@njit(cache=True, nogil=True, error_model="numpy")
def _references(r0, offs, lam, lx, sinc, far, w_rail_lag, refs):
    """Row ``j`` of the reference ``refs[j, 0]`` (the chirp of eq. 19 over the footprint ``|x| <= lam R0/(2 L_x)``,
    or weighted by the two-way pattern ``sinc^2(L_x sin(a)/lam)`` over its main lobe ``|sin(a)| < lam/L_x``)
    and of the unit scatterer at the rail centre ``refs[j, 1]`` (the footprint chirp on the rail: rail
    taper in region II, rail support in region I), at the circular lags ``offs`` (``k dx`` at index k,
    ``-k dx`` at index n - k). complex64; the phase ``-4 pi (R - R0)/lam`` in float64 with
    ``R - R0 = x^2/(R + R0)``. Both are even in x: each |x| is evaluated once (a loop without branches
    or library calls, that vectorizes), and only up to the reach of the footprint or of the main lobe
    ``|x| < s0 R0/sqrt(1 - s0^2)``, ``s0 = lam/L_x`` (zero beyond); the rail-centre row only over the
    lags where the rail taper is not 0."""
    n = offs.size
    n_pos = n - n // 2  # indices 0 .. n_pos-1 hold the lags 0, dx, ...; n_pos .. n-1 the negative ones
    dx = offs[1]
    k4 = 4.0 * np.pi / lam
    s0 = lam / lx
    k_rail = 0  # the rail taper is 0 at lags >= k_rail dx on both sides
    for k in range(n // 2 + 1):
        if w_rail_lag[k % n] != 0.0 or w_rail_lag[(n - k) % n] != 0.0:
            k_rail = k + 1
    for j in range(r0.size):
        r = r0[j]
        half = lam * r / (2.0 * lx)
        reach = half
        if sinc:
            reach = max(half, s0 * r / np.sqrt(1.0 - s0 * s0)) if s0 < 1.0 else np.inf
        k_end = n // 2 + 1
        if reach / dx < k_end:
            k_end = min(k_end, int(reach / dx) + 2)
        c = np.empty(k_end)
        s = np.empty(k_end)
        p = np.empty(k_end)
        for k in range(k_end):
            x = k * dx  # = |offs| at index k and n - k, exactly (the lag grid is an integer times dx)
            rr = np.sqrt(r * r + x * x)
            pos = rr > 0
            c[k], s[k] = _cos_sin(-k4 * (x * x / (rr + r)) if pos else 0.0)
            if sinc:
                sin_a = x / rr if pos else x
                w = np.pi * lx * sin_a / lam
                sw = _cos_sin(w)[1] / w
                p[k] = (sw * sw if w != 0.0 else 1.0) if sin_a < s0 else 0.0
            else:
                p[k] = 1.0 if x <= half else 0.0
        refs[j, :, :] = 0
        for k in range(k_end):
            v = np.complex64(complex(p[k] * c[k], p[k] * s[k]))
            if k < n_pos:
                refs[j, 0, k] = v
            if 0 < k <= n // 2:
                refs[j, 0, n - k] = v
        for k in range(min(k_end, k_rail)):
            if k * dx <= half:  # the footprint
                for i in (k, (n - k) % n):
                    wr = w_rail_lag[i] if far else (1.0 if w_rail_lag[i] > 0 else 0.0)
                    refs[j, 1, i] = np.complex64(complex(wr * c[k], wr * s[k]))


@njit(cache=True, nogil=True, error_model="numpy")
def _median_inplace(a):
    """Median of the float array ``a`` (reordered in place): the mean of the two middle values for an even
    size, as ``numpy.median``; Hoare's selection for the upper middle, the maximum of the part below it
    for the lower. The pivots are drawn by a fixed 64-bit linear congruential generator, not
    taken from the middle: expected linear time whatever the order of the values (a
    smooth, even spectrum made the middle pivots ~4x slower); the result does not depend on them."""
    n = a.size
    k = n // 2
    lo, hi = 0, n - 1
    state = np.uint64(0x9E3779B97F4A7C15)
    while lo < hi:
        state = state * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
        piv = a[lo + int((state >> np.uint64(33)) % np.uint64(hi - lo + 1))]
        i, j = lo, hi
        while i <= j:
            while a[i] < piv:
                i += 1
            while a[j] > piv:
                j -= 1
            if i <= j:
                a[i], a[j] = a[j], a[i]
                i += 1
                j -= 1
        if j < k:
            lo = i
        if k < i:
            hi = j
    upper = np.float64(a[k])
    if n % 2:
        return upper
    lower = a[0]
    for i in range(1, k):  # after the selection a[:k] <= a[k]: the lower middle is their maximum
        lower = max(lower, a[i])
    return 0.5 * (np.float64(lower) + upper)


@njit(cache=True, nogil=True, error_model="numpy")
def _filters(refs, band_idx, wu, power, floor_rel, filt):
    """Per row ``j`` (``refs[j]`` = the spectra H of the reference and of the rail-centre scatterer): the
    filter ``conj(H)/max(|H|^p, floor) * W`` over the band (floor: ``floor_rel`` x the median of ``|H|^p``
    over the band), divided by the gain ``Re sum_u FFT(h_rail) filter / n`` into ``filt[j]`` (band
    order; all 0 where the gain is not positive)."""
    n = refs.shape[2]
    nb = band_idx.size
    for j in range(refs.shape[0]):
        mag = np.empty(nb, np.float32)
        for q in range(nb):
            v = refs[j, 0, band_idx[q]]
            m2 = v.real * v.real + v.imag * v.imag
            mag[q] = np.sqrt(m2) if power == 1 else m2
        floor = np.float32(floor_rel * _median_inplace(mag.copy()) + 1e-30)
        gain = 0.0
        for q in range(nb):
            u = band_idx[q]
            f = np.conj(refs[j, 0, u]) * np.float32(wu[u] / max(mag[q], floor))
            filt[j, q] = f
            gain += (refs[j, 1, u] * f).real
        gain /= n
        g = np.float32(1.0 / gain) if gain > 0 else np.float32(0.0)
        for q in range(nb):
            filt[j, q] *= g


@njit(cache=True, nogil=True, error_model="numpy")
def _apply(spec, lo, r0, dr, cos_t, band_idx, filt, out):
    """Per row ``j``: into ``out[j]`` the RCMC'd data spectrum (row ``R0/cos(theta(u))``, linear
    interpolation between the rows of ``spec``, which start at row ``lo``) times ``filt[j]`` over the
    band, 0 elsewhere. ``out[j]`` is then the spectrum of the image row."""
    n_spec = spec.shape[0]
    for j in range(r0.size):
        out[j, :] = 0
        for q in range(band_idx.size):
            u = band_idx[q]
            if cos_t[u] <= 0:
                continue
            fr = r0[j] / cos_t[u] / dr - lo
            i0 = np.floor(fr)
            if i0 < n_spec - 1:
                t = np.float32(fr - i0)
                i = int(i0)
                out[j, u] = (spec[i, u] * (np.float32(1) - t) + spec[i + 1, u] * t) * filt[j, q]


def _fft_rows(a: np.ndarray, workers: int, inverse: bool = False) -> None:
    """FFT (or inverse FFT) of ``a`` along its last axis, into ``a`` (scipy.fft transforms in place when
    allowed to overwrite; copied back otherwise)."""
    res = (scipy.fft.ifft if inverse else scipy.fft.fft)(a, axis=-1, overwrite_x=True, workers=workers)
    if not np.may_share_memory(res, a):
        a[...] = res


def focus_rd(prof: RangeProfiles, antenna_length_m: float, n_xfft: int | None = None,
             azimuth_window: str = "hamming", max_range_m: float | None = None,
             block_rows: int = 128, reference: str = "sinc", workers: int = -1) -> RDImage:
    """RD image of the range rows up to ``max_range_m`` (default: all), processed in row blocks.

    ``reference``: ``rect`` = the paper's chirp over the beam footprint (matches the ideal beam);
    ``sinc`` = the chirp weighted by the two-way sinc^2 pattern over its main lobe (matches a real
    aperture antenna; the rect reference's Fresnel ripples, inverted, would leave a -27 dB azimuth
    sidelobe plateau on data seen through a sinc beam). ``workers``: threads, as in
    :func:`focus_rd_pols`."""
    return focus_rd_pols([prof], antenna_length_m, n_xfft, azimuth_window, max_range_m, block_rows, reference,
                         workers)[0]


def focus_rd_pols(profs: Sequence[RangeProfiles], antenna_length_m: float, n_xfft: int | None = None,
                  azimuth_window: str = "hamming", max_range_m: float | None = None,
                  block_rows: int = 128, reference: str = "sinc", workers: int = -1) -> list[RDImage]:
    """:func:`focus_rd` of several profiles on the same rail stops and range bins (the polarizations of
    one scan): the filters depend on the geometry only, so each row block's reference spectra, median
    and gain are computed once and applied to every profile.

    The row blocks go to a pool of ``workers`` threads (scipy's convention, counted from the thread
    budget of :mod:`sarcli.threads`), each with its own buffers, serial GIL-free kernels and
    single-threaded FFTs: no synchronization inside a block, so a busy machine slows it gracefully."""
    if not profs:
        raise SarcliError("no range profiles to focus with RD")
    p0 = profs[0]
    for p in profs[1:]:
        if (p.dr_m != p0.dr_m or p.wavelength_m != p0.wavelength_m or p.data.shape[1] != p0.data.shape[1]
                or p.first_range_m != p0.first_range_m or not np.array_equal(p.positions_m, p0.positions_m)):
            raise SarcliError("RD of several profiles needs the same rail stops, range bins and wavelength in each")
    pl = _plan(p0, antenna_length_m, n_xfft, azimuth_window, max_range_m, reference)
    n, r, lam, dr = pl.n, p0.ranges_m, p0.wavelength_m, p0.dr_m
    band_idx = np.flatnonzero(pl.band)
    blocks = _blocks(r[:pl.n_rows], block_rows, pl.boundary)
    his = [min(r.size, int(np.ceil(r[b[-1]] * pl.stretch / dr)) + 2) for b in blocks]
    m_max = max(b.size for b in blocks)
    spec_rows = max(hi - b[0] for b, hi in zip(blocks, his, strict=True))
    outs = [np.empty((pl.n_rows, n), np.complex64) for _ in profs]
    n_threads = min(fft_workers(workers), len(blocks))
    buffers: queue.SimpleQueue = queue.SimpleQueue()
    for _ in range(n_threads):
        buffers.put((np.empty((m_max, 2, n), np.complex64), np.empty((m_max, band_idx.size), np.complex64),
                     np.empty((spec_rows, n), np.complex64)))

    def run(rows: np.ndarray, hi: int) -> None:
        buf = buffers.get()
        try:
            r0, m, lo = r[rows], rows.size, int(rows[0])
            far = bool(r0[0] >= pl.boundary)
            refs, filt, spec = buf[0][:m], buf[1][:m], buf[2][:hi - lo]
            _references(r0, pl.offs, lam, float(antenna_length_m), reference == "sinc", far, pl.w_rail_lag, refs)
            _fft_rows(refs, 1)
            _filters(refs, band_idx, pl.band.astype(np.float64) if far else pl.w_beam, 1 if far else 2,
                     _INVERSE_FLOOR, filt)
            for prof, out in zip(profs, outs, strict=True):
                wx = (prof.weights * (pl.w_rail if far else 1.0)).astype(np.float32)
                spec[...] = 0
                spec[:, pl.pad:pl.pad + pl.n_x] = (prof.data[:, lo:hi] * wx[:, None]).T
                _fft_rows(spec, 1)
                block = out[lo:lo + m]
                _apply(spec, lo, r0, dr, pl.cos_t, band_idx, filt, block)
                _fft_rows(block, 1, inverse=True)
        finally:
            buffers.put(buf)

    if n_threads == 1:
        for rows, hi in zip(blocks, his, strict=True):
            run(rows, hi)
    else:
        with ThreadPoolExecutor(n_threads) as pool:
            for f in [pool.submit(run, rows, hi) for rows, hi in zip(blocks, his, strict=True)]:
                f.result()
    return [_result(prof, pl, out) for prof, out in zip(profs, outs, strict=True)]


def focus_rd_reference(prof: RangeProfiles, antenna_length_m: float, n_xfft: int | None = None,
                       azimuth_window: str = "hamming", max_range_m: float | None = None,
                       block_rows: int = 256, reference: str = "sinc") -> RDImage:
    """Plain-numpy reference of :func:`focus_rd` (the tests' yardstick and the benchmark's naive RD):
    complex128 reference chirp per block, ``nanmedian`` per column, azimuth along axis 0."""
    pl = _plan(prof, antenna_length_m, n_xfft, azimuth_window, max_range_m, reference)
    n_x, n_rows, n, pad = pl.n_x, pl.n_rows, pl.n, pl.pad
    band, w_beam, w_rail, cos_t, stretch = pl.band, pl.w_beam, pl.w_rail, pl.cos_t, pl.stretch
    offs, w_rail_lag, boundary = pl.offs, pl.w_rail_lag, pl.boundary
    lam, r = prof.wavelength_m, prof.ranges_m
    out = np.zeros((n_rows, n), np.complex64)
    for rows in _blocks(r[:n_rows], block_rows, boundary):
        r0 = r[rows]
        far = r0[0] >= boundary  # region II: aperture = rail -> taper over the rail; else over the beam
        lo, hi = rows[0], min(r.size, int(np.ceil(r0[-1] * stretch / prof.dr_m)) + 2)
        a = np.zeros((n, hi - lo), np.complex64)
        wx = prof.weights * (w_rail if far else 1.0)
        a[pad:pad + n_x] = prof.data[:, lo:hi] * wx[:, None].astype(np.float32)
        spec = scipy.fft.fft(a, axis=0, overwrite_x=True)  # the N_Rfft x N_xfft array of Table 1, by blocks
        wu = band.astype(np.float64) if far else w_beam
        # range cell migration correction: take row R0/cos(theta(u)) of the spectrum
        with np.errstate(divide="ignore"):
            fr = np.where(cos_t[:, None] > 0, r0[None, :] / cos_t[:, None], np.inf) / prof.dr_m - lo
        i0 = np.floor(fr)
        ok = (i0 < hi - lo - 1) & band[:, None]
        i0 = np.where(ok, i0, 0).astype(np.int64)
        t = np.where(ok, fr - i0, 0.0).astype(np.float32)
        cols = np.arange(n)[:, None]
        blk = np.where(ok, spec[cols, i0] * (1 - t) + spec[cols, i0 + 1] * t, 0).astype(np.complex64)
        # exact reference of eq. 19 over the beam footprint, transformed per row
        half = lam * r0 / (2 * antenna_length_m)
        rr = np.sqrt(r0[None, :] ** 2 + offs[:, None] ** 2)
        chirp = np.exp(-4j * np.pi * (rr - r0[None, :]) / lam)
        h = np.where(np.abs(offs[:, None]) <= half[None, :], chirp, 0)  # the paper's footprint
        if reference == "sinc":  # two-way pattern over its main lobe: no Fresnel ripple to invert
            sin_a = offs[:, None] / np.where(rr > 0, rr, 1.0)
            hs = scipy.fft.fft(np.where(np.abs(sin_a) < lam / antenna_length_m,
                                        np.sinc(antenna_length_m * sin_a / lam) ** 2 * chirp, 0).astype(np.complex64),
                               axis=0)
        else:
            hs = scipy.fft.fft(h.astype(np.complex64), axis=0)
        # region I: inverse filter (flat spectrum over the band); region II: phase-only filter (each
        # target fills a narrow part of the band, an inverse filter would undo the antenna pattern there)
        mag = np.abs(hs) ** (1 if far else 2)
        floor = _INVERSE_FLOOR * np.nanmedian(np.where(band[:, None], mag, np.nan), axis=0) + 1e-30
        filt = (np.conj(hs) / np.maximum(mag, floor[None, :]) * wu[:, None]).astype(np.complex64)
        # normalize so that a unit scatterer at the rail centre's azimuth focuses to 1 (as in BP): its
        # data are the footprint chirp over the rail, with the rail taper in region II
        h_rail = (h * (w_rail_lag if far else (w_rail_lag > 0))[:, None]).astype(np.complex64)
        gain = np.real(np.sum(scipy.fft.fft(h_rail, axis=0) * filt, axis=0)) / n
        g = scipy.fft.ifft(blk * filt, axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[rows] = np.where(gain > 0, g / gain, 0).T
    return _result(prof, pl, out)
