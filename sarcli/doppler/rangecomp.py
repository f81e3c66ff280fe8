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


def _spectrum(echo: np.ndarray, radar: Radar, replica: np.ndarray | None):
    nref = reference_pulse(radar, replica).size
    n = echo.shape[1]
    if nref >= n:
        raise SarcliError(f"range extent ({n} samples) is not longer than the pulse ({nref} samples): "
                          "cannot range-compress")
    # n + nref samples: the linear correlation (n + nref - 1) plus one, so that the partial points
    # before the window (negative samples, wrapped to the end) never meet those after it
    nfft = sfft.next_fast_len(n + nref)
    H, f = range_filter(radar, nfft, "rect", replica)
    S = sfft.fft(np.asarray(echo, np.complex64), nfft, axis=1, workers=budget())
    S *= H.astype(np.complex64)[None, :]
    valid = slice(nref // 2, n - nref // 2)
    return S, f, H, valid


def range_compress_valid(echo: np.ndarray, radar: Radar, replica: np.ndarray | None = None
                         ) -> tuple[np.ndarray, slice]:
    """Range-compressed echo restricted to fully covered samples: (array complex64, sample slice)."""
    S, _, _, valid = _spectrum(echo, radar, replica)
    out = sfft.ifft(S, axis=1, workers=budget())[:, valid]
    return out.astype(np.complex64), valid


def range_compress_extended(echo: np.ndarray, radar: Radar, replica: np.ndarray | None = None
                            ) -> tuple[np.ndarray, slice]:
    """Range-compressed echo over every sample a recorded echo reaches, including the partially
    compressed points at both window edges: (array complex64 with n + 2 (n_ref//2) samples, slice of
    their raw-sample indices, starting at -(n_ref//2))."""
    S, _, _, valid = _spectrum(echo, radar, replica)
    n, half = echo.shape[1], valid.start
    out = sfft.ifft(S, axis=1, workers=budget())
    idx = np.arange(-half, n + half) % out.shape[1]  # negative samples wrapped to the end of the FFT
    return out[:, idx].astype(np.complex64), slice(-half, n + half)


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
    S, f, H, valid = _spectrum(echo, radar, replica)
    ref_amp = np.abs(H) ** 2  # compressed spectrum of a point target
    half = 0.5 * chirp_band(radar)
    looks, centres = [], []
    for sel in ((f < 0) & (f >= -half), (f >= 0) & (f <= half)):
        if not np.any(ref_amp[sel] > 0):
            raise SarcliError("range sub-look has no bandwidth (pulse shorter than a sample?)")
        centres.append(float(np.sum(f[sel] * ref_amp[sel]) / np.sum(ref_amp[sel])))
        looks.append(sfft.ifft(np.where(sel[None, :], S, 0), axis=1, workers=budget())[:, valid].astype(np.complex64))
    return looks[0], looks[1], np.array(centres)
