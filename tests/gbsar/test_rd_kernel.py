"""The GB-SAR RD core (numba kernels, complex64, rows contiguous) against its plain-numpy reference
(complex128 reference chirps, ``nanmedian`` per column): same image within float32 rounding.

Tolerance (normwise, ||a - b|| <= tol ||b||): both run the same linear chain in complex64: the data's
azimuth FFT, the reference's FFT and the inverse FFT, each with a normwise relative error of at most
about ``5 eps log2(n)`` (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., sec. 24.1,
eps = 2^-24), plus a float32 sum over the band for the gain (``eps log2(n)``, pairwise) and a few
elementwise roundings. Two implementations: ``tol = 2 (3 x 5 + 1) eps log2(n) + 10 eps``, 2.1e-5 at
n = 512. Every mask (footprint, main lobe, RCMC rows) is decided by the same float64 comparisons in
both, so no pixel can differ by more than rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import SarcliError
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.rangedoppler import (
    _cos_sin,
    _median_inplace,
    _references,
    focus_rd,
    focus_rd_pols,
    focus_rd_reference,
)
from sarcli.model.constants import C_LIGHT

EPS32 = 2.0 ** -24
F0 = 5.3e9
LAM = C_LIGHT / F0


def _tolerance(n: int) -> float:
    return 2 * (3 * 5 + 1) * EPS32 * np.log2(n) + 10 * EPS32


def _profiles(seed: int, n_x: int = 21, n_r: int = 120, dr: float = 0.1, dx: float = 0.05,
              skipped: tuple[int, ...] = ()) -> RangeProfiles:
    rng = np.random.default_rng(seed)
    data = (rng.standard_normal((n_x, n_r)) + 1j * rng.standard_normal((n_x, n_r))).astype(np.complex64)
    weights = np.ones(n_x)
    weights[list(skipped)] = 0.0
    return RangeProfiles(data=data, dr_m=dr, center_frequency_hz=F0, frequency_step_hz=C_LIGHT / (4 * n_r * dr),
                         n_freq=n_r, positions_m=(np.arange(n_x) - n_x // 2) * dx, heights_m=np.zeros(n_x),
                         weights=weights, skipped=list(skipped))


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**31), reference=st.sampled_from(["sinc", "rect"]),
       window=st.sampled_from(["hamming", "rect", "kaiser:3"]), block_rows=st.sampled_from([7, 32, 256]),
       skipped=st.sampled_from([(), (0, 5), (20,)]))
def test_rd_matches_numpy_reference(seed, reference, window, block_rows, skipped):
    """Both regions (I below, II beyond rail L_x/lam = 4.4 m: rows up to 11.9 m), row blocks that do or
    do not straddle the boundary, skipped stops, every taper and reference weighting."""
    prof = _profiles(seed, skipped=skipped)
    kw = dict(antenna_length_m=0.25, azimuth_window=window, block_rows=block_rows, reference=reference)
    a = focus_rd(prof, **kw)
    b = focus_rd_reference(prof, **kw)
    assert a.data.dtype == np.complex64 and a.data.shape == b.data.shape
    assert (a.azimuth_first_m, a.dx_m, a.n_xfft) == (b.azimuth_first_m, b.dx_m, b.n_xfft)
    np.testing.assert_array_equal(a.ranges_m, b.ranges_m)
    err = np.linalg.norm(a.data - b.data) / np.linalg.norm(b.data)
    assert err <= _tolerance(a.n_xfft), err


@pytest.mark.parametrize("workers", [1, 3])
def test_rd_matches_reference_with_a_given_fft_size_and_range_limit(workers):
    """Serially and with the row blocks on a pool of three threads (whatever the cores)."""
    prof = _profiles(3, n_r=200)
    a = focus_rd(prof, 0.25, n_xfft=1024, max_range_m=15.0, block_rows=16, workers=workers)
    b = focus_rd_reference(prof, 0.25, n_xfft=1024, max_range_m=15.0)
    assert a.data.shape == (151, 1024)
    assert np.linalg.norm(a.data - b.data) <= _tolerance(1024) * np.linalg.norm(b.data)


@settings(max_examples=8, deadline=None)
@given(seeds=st.lists(st.integers(0, 2**31), min_size=2, max_size=3),
       skipped=st.lists(st.sampled_from([(), (0, 5), (20,)]), min_size=3, max_size=3),
       reference=st.sampled_from(["sinc", "rect"]), block_rows=st.sampled_from([7, 256]))
def test_rd_of_several_profiles_matches_each_numpy_reference(seeds, skipped, reference, block_rows):
    """The polarizations of a scan share the filters, not their data or their skipped stops: each image
    is the numpy reference's of its own profile."""
    profs = [_profiles(s, skipped=k) for s, k in zip(seeds, skipped, strict=False)]
    kw = dict(antenna_length_m=0.25, block_rows=block_rows, reference=reference)
    for prof, a in zip(profs, focus_rd_pols(profs, **kw), strict=True):
        b = focus_rd_reference(prof, **kw)
        assert np.linalg.norm(a.data - b.data) <= _tolerance(a.n_xfft) * np.linalg.norm(b.data)


def test_rd_of_several_profiles_refuses_other_geometries():
    a = _profiles(1)
    with pytest.raises(SarcliError, match="same rail stops"):
        focus_rd_pols([a, _profiles(2, dx=0.04)], 0.25)
    with pytest.raises(SarcliError, match="same rail stops"):
        focus_rd_pols([a, _profiles(2, n_r=121)], 0.25)
    with pytest.raises(SarcliError, match="no range profiles"):
        focus_rd_pols([], 0.25)


@pytest.mark.parametrize("sinc", [True, False])
@pytest.mark.parametrize("far", [True, False])
def test_reference_rows_match_numpy(sinc, far):
    """The synthesized reference and rail-centre rows against the formulas of eq. 19 in numpy."""
    n, dx, lx = 512, 0.05, 0.25
    offs = np.where(np.arange(n) < n - n // 2, np.arange(n), np.arange(n) - n) * dx
    r0 = np.array([0.0, 0.3, 2.0, 7.5, 40.0])
    w_rail_lag = np.interp(offs, np.linspace(-1.0, 1.0, 41), np.hanning(41), left=0.0, right=0.0)
    refs = np.empty((r0.size, 2, n), np.complex64)
    _references(r0, offs, LAM, lx, sinc, far, w_rail_lag, refs)
    h, h_rail = refs[:, 0], refs[:, 1]
    rr = np.sqrt(r0[:, None] ** 2 + offs[None, :] ** 2)
    chirp = np.exp(-4j * np.pi * (rr - r0[:, None]) / LAM)
    foot = np.abs(offs[None, :]) <= LAM * r0[:, None] / (2 * lx)
    if sinc:
        sin_a = offs[None, :] / np.where(rr > 0, rr, 1.0)
        ref = np.where(np.abs(sin_a) < LAM / lx, np.sinc(lx * sin_a / LAM) ** 2 * chirp, 0)
    else:
        ref = np.where(foot, chirp, 0)
    rail = np.where(foot, chirp, 0) * (w_rail_lag if far else (w_rail_lag > 0))[None, :]
    # float64 phases of up to 4 pi x^2/(2 R lam) ~ 1e4 rad, rounded to complex64: 1e-12 + 2 eps32
    np.testing.assert_allclose(h, ref, rtol=0, atol=4 * EPS32)
    np.testing.assert_allclose(h_rail, rail, rtol=0, atol=4 * EPS32)


@settings(max_examples=60, deadline=None)
@given(values=st.lists(st.integers(-3, 3), min_size=1, max_size=40), dtype=st.sampled_from([np.float32, np.float64]))
def test_median_selection_matches_numpy(values, dtype):
    a = np.asarray(values, dtype)
    assert _median_inplace(a.copy()) == np.median(a)


@settings(max_examples=300, deadline=None)
@given(ph=st.one_of(st.floats(-10.0, 10.0), st.floats(-1.6e6, 1.6e6), st.floats(-1e12, 1e12),
                    st.integers(-4000, 4000).map(lambda q: q * np.pi / 4)))
def test_inline_cos_sin_matches_numpy(ph):
    """Reduction by q pi/2 with pi/2 in three parts (exact products while |q| < 2^20) and Taylor kernels
    with remainders < 5e-17 on |t| <= pi/4: a few units of 2^-53, plus about the rounding |ph| 2^-53
    of the argument itself beyond |q| = 2^20 (where the head product is no longer exact)."""
    c, s = _cos_sin(ph)
    tol = 8 * 2.0 ** -53 + (abs(ph) * 2.0 ** -52 if abs(ph) >= 1.6e6 else 0.0)
    assert abs(c - np.cos(ph)) <= tol and abs(s - np.sin(ph)) <= tol
