"""Range compression for the Doppler estimators: the extended output (partially recorded echoes at the
window edges kept) against a plain-numpy full linear correlation."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.doppler.rangecomp import range_compress_extended, range_compress_valid
from sarcli.model.raw import Radar
from tests.doppler.synth import C

FS, F0 = 32e6, 5.3e9
TP = 61 / FS  # 61-sample pulse: odd, so a pulse centred on a sample is symmetric about it
K = -FS / TP  # band K T = fs: the matched filter's band window passes every bin (plain correlation)
RADAR = Radar(F0, C / F0, 1000.0, FS, K, TP, 2 * 900e3 / C, 900e3)
N = 200


def _chirp() -> np.ndarray:
    t = (np.arange(61) - 30) / FS
    return np.exp(1j * np.pi * K * t * t)


def _echo(centres: list[int]) -> np.ndarray:
    """One line with a unit point echo centred on each (possibly outside the window) sample."""
    x = np.zeros(N + 200, complex)
    for k in centres:
        x[100 + k - 30:100 + k + 31] += _chirp()
    return x[100:100 + N][None, :]


@pytest.mark.parametrize("centre", [-25, -5, 3, 100, 190, 224])
def test_extended_compression_matches_numpy_full_correlation(centre):
    x = _echo([centre])
    ext, extent = range_compress_extended(x.astype(np.complex64), RADAR)
    assert (extent.start, extent.stop) == (-30, N + 30) and ext.shape == (1, N + 60)
    # plain numpy: full linear correlation with the reference; its index i is sample i - 30
    ref = np.convolve(x[0], np.conj(_chirp()[::-1])) / 61  # the filter is scaled to a unit full peak
    # (the filter's band window drops the Nyquist bin: an alternating residue of -52 dB of the peak)
    np.testing.assert_allclose(ext[0], ref[:N + 60], atol=4e-3)
    # the point is compressed on its own sample, with the energy of the recorded part of its echo
    peak = int(np.argmax(np.abs(ext[0]))) + extent.start
    recorded = min(N, centre + 31) - max(0, centre - 30)
    assert peak == centre
    assert abs(ext[0, centre - extent.start]) == pytest.approx(recorded / 61, abs=4e-3)


def test_extended_keeps_the_valid_samples_and_never_wraps():
    x = _echo([-20, 60, 215]).astype(np.complex64)
    ext, extent = range_compress_extended(x, RADAR)
    val, valid = range_compress_valid(x, RADAR)
    np.testing.assert_allclose(ext[:, valid.start - extent.start:valid.stop - extent.start], val, atol=1e-3)
    # points cut by both edges at once: a circular wrap would put one onto the other's samples
    ref = np.convolve(x[0], np.conj(_chirp()[::-1])) / 61
    np.testing.assert_allclose(ext[0], ref[:N + 60], atol=4e-3)


def test_compression_in_line_chunks_is_the_whole_array_compression(monkeypatch):
    """The lines are compressed CHUNK_LINES at a time; each line's FFTs are the same whatever its chunk,
    so chunks of 3 lines (the last one short) give the single-chunk result bit for bit."""
    from sarcli.doppler import rangecomp

    rng = np.random.default_rng(3)
    x = (rng.standard_normal((11, N)) + 1j * rng.standard_normal((11, N))).astype(np.complex64)
    calls = (lambda: rangecomp.range_compress_valid(x, RADAR), lambda: rangecomp.range_compress_extended(x, RADAR),
             lambda: rangecomp.range_looks(x, RADAR))
    whole = [c() for c in calls]
    monkeypatch.setattr(rangecomp, "CHUNK_LINES", 3)
    for c, w in zip(calls, whole, strict=True):
        for a, b in zip(c(), w, strict=True):
            assert a == b if isinstance(a, slice) else np.array_equal(a, b)
