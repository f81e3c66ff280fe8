"""Range-compressed data and range sub-looks for the Doppler estimators (RC-CDE, MLCC, MLBF, map-drift).

The matched filter is focus's (``sarcli.focus.rangecomp.range_filter``: replica or nominal chirp,
compressed peak of a point on the sample of its two-way time 2R/c). ``range_compress_valid`` keeps only
the samples whose whole pulse lies inside the window (n_ref//2 .. n - n_ref//2: full range resolution,
for map-drift and the sub-looks). ``range_compress_extended`` keeps every sample any recorded echo
reaches (-n_ref//2 .. n + n_ref//2): a point whose echo is cut by the window edge is only partially
compressed (coarser range resolution, less energy) but its azimuth phase history is intact, so the
RC-CDE sees the same scatterers as the raw-data CDE. Range sub-looks split the
compressed range spectrum into two halves of the chirp band; their centre frequencies are the
amplitude-weighted means of a point target's compressed spectrum |REF(f)|^2.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from sarcli.errors import SarcliError
from sarcli.focus.rangecomp import chirp_band, range_filter, reference_pulse
from sarcli.model.raw import Radar, RawProduct
from sarcli.threads import budget

#: samples beyond the pulse a swath needs before range compression is worth it (RC-CDE, MLCC/MLBF, map-drift)
MIN_EXTRA_SAMPLES = 16


def can_compress(raw: RawProduct) -> bool:
    """Whether the swath is longer than the pulse (replica, else pulse length x sampling rate) by at
    least ``MIN_EXTRA_SAMPLES``: the condition of every range-compressed estimator."""
    n_ref = raw.replica.size if raw.replica is not None and raw.replica.size > 1 else int(
        round(raw.radar.pulse_length_s * raw.radar.range_sampling_rate_hz))
    return raw.echo.shape[1] > n_ref + MIN_EXTRA_SAMPLES


#: lines range-compressed at a time: a chunk's spectra (a few nfft-long complex64 rows per line) stay
#: small however many lines are compressed (a full scene's 4096 central lines: ~0.5 GB less at the peak)
CHUNK_LINES = 256


@dataclass(frozen=True)
class _Compression:
    """The matched filter of an echo's lines: FFT length, filter ``h`` (complex64) with its frequencies
    ``f`` (Hz) and values ``H``, and the fully compressed samples ``valid``."""

    nfft: int
    h: np.ndarray
    f: np.ndarray
    H: np.ndarray
    valid: slice


def _compression(echo: np.ndarray, radar: Radar, replica: np.ndarray | None) -> _Compression:
    nref = reference_pulse(radar, replica).size
    n = echo.shape[1]
    if nref >= n:
        raise SarcliError(f"range extent ({n} samples) is not longer than the pulse ({nref} samples): "
                          "cannot range-compress")
    # n + nref samples: the linear correlation (n + nref - 1) plus one, so that the partial points
    # before the window (negative samples, wrapped to the end) never meet those after it
    nfft = sfft.next_fast_len(n + nref)
    H, f = range_filter(radar, nfft, "rect", replica)
    return _Compression(nfft, H.astype(np.complex64), f, H, slice(nref // 2, n - nref // 2))


def _spectra(echo: np.ndarray, c: _Compression) -> Iterator[tuple[slice, np.ndarray]]:
    """(lines, their range spectra times the filter) chunk by chunk (:data:`CHUNK_LINES`); each line's
    FFT is the same whatever the chunk."""
    for a in range(0, echo.shape[0], CHUNK_LINES):
        rows = slice(a, min(a + CHUNK_LINES, echo.shape[0]))
        S = sfft.fft(np.asarray(echo[rows], np.complex64), c.nfft, axis=1, workers=budget())
        S *= c.h[None, :]
        yield rows, S


def _inverse(S: np.ndarray) -> np.ndarray:
    """Range IFFT of a chunk's (own) spectra, in place."""
    return sfft.ifft(S, axis=1, workers=budget(), overwrite_x=True)


def range_compress_valid(echo: np.ndarray, radar: Radar, replica: np.ndarray | None = None
                         ) -> tuple[np.ndarray, slice]:
    """Range-compressed echo restricted to fully covered samples: (array complex64, sample slice)."""
    c = _compression(echo, radar, replica)
    out = np.empty((echo.shape[0], c.valid.stop - c.valid.start), np.complex64)
    for rows, S in _spectra(echo, c):
        out[rows] = _inverse(S)[:, c.valid]
    return out, c.valid


def range_compress_extended(echo: np.ndarray, radar: Radar, replica: np.ndarray | None = None
                            ) -> tuple[np.ndarray, slice]:
    """Range-compressed echo over every sample a recorded echo reaches, including the partially
    compressed points at both window edges: (array complex64 with n + 2 (n_ref//2) samples, slice of
    their raw-sample indices, starting at -(n_ref//2))."""
    c = _compression(echo, radar, replica)
    n, half = echo.shape[1], c.valid.start
    idx = np.arange(-half, n + half) % c.nfft  # negative samples wrapped to the end of the FFT
    out = np.empty((echo.shape[0], idx.size), np.complex64)
    for rows, S in _spectra(echo, c):
        out[rows] = _inverse(S)[:, idx]
    return out, slice(-half, n + half)


#: (look_lo, look_hi, centre_hz[2]): the two range sub-looks of :func:`range_looks`
Looks = tuple[np.ndarray, np.ndarray, np.ndarray]


def range_looks(echo: np.ndarray, radar: Radar, replica: np.ndarray | None = None) -> Looks:
    """Two range sub-looks (lower / upper half of the chirp band) of the range-compressed echo.

    Returns (look_lo, look_hi, centre_hz[2]) on the valid samples. The carrier of a look is the
    amplitude-weighted mean frequency of a point target's compressed spectrum |REF(f)|^2 (real,
    positive). It is NOT taken from the data spectrum: on real data the partial echoes at the window
    edges and the range-varying backscatter tilt that spectrum (9 dB across the band on the Vancouver
    block), which would bias MLCC/MLBF by several per cent.
    """
    c = _compression(echo, radar, replica)
    ref_amp = np.abs(c.H) ** 2  # compressed spectrum of a point target
    half = 0.5 * chirp_band(radar)
    bands = ((c.f < 0) & (c.f >= -half), (c.f >= 0) & (c.f <= half))
    centres = []
    for sel in bands:
        if not np.any(ref_amp[sel] > 0):
            raise SarcliError("range sub-look has no bandwidth (pulse shorter than a sample?)")
        centres.append(float(np.sum(c.f[sel] * ref_amp[sel]) / np.sum(ref_amp[sel])))
    looks = [np.empty((echo.shape[0], c.valid.stop - c.valid.start), np.complex64) for _ in bands]
    for rows, S in _spectra(echo, c):
        for sel, look in zip(bands, looks, strict=True):
            look[rows] = _inverse(np.where(sel[None, :], S, 0))[:, c.valid]
    return looks[0], looks[1], np.array(centres)
