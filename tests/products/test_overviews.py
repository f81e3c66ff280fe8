"""The overview kernels against a plain-numpy reduction, and the streamed pyramid against the whole raster.

Tolerances: kernel and reference sum the same float64 terms in the same order; only the terms may differ
in their last bits (cos, sin from another libm; the kernel's 10^(x/10) is exp(x ln(10) / 10), which
differs from pow by |x ln(10) / 10| 2^-53 relative, < 3e-15 for |x| <= 100 dB), which can move the
float32 result by at most one of its own units (2^-24 relative): rel 2.4e-7 covers it. The phase of
a cell whose phasors nearly cancel is ill-conditioned (any last-bit change moves it), so phases are
compared where the resultant holds at least 1e-3 of the cell's count.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest
import rasterio
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.io.overviews import KIND_CODES, Pyramid, first_cells, levels_of_window, overview_factors


def _reference_terms(a: np.ndarray, kind: str) -> tuple[np.ndarray, np.ndarray]:
    ok = np.isfinite(a)
    x = np.where(ok, a.astype(np.float64), 0.0)
    val = {"power": x * x, "power_db": np.where(ok, 10.0 ** (x / 10.0), 0.0),
           "phase": np.where(ok, np.exp(1j * x), 0.0), "mean": x}[kind]
    return val, ok.astype(np.float64)


def _reference_pool(x: np.ndarray) -> np.ndarray:
    x = np.pad(x, ((0, x.shape[0] % 2), (0, x.shape[1] % 2)))
    return x[0::2, 0::2] + x[1::2, 0::2] + x[0::2, 1::2] + x[1::2, 1::2]


def _reference_levels(a: np.ndarray, kind: str, n_levels: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(pixels float64, |resultant| / count) of levels 2 .. 2^n_levels: plain numpy."""
    val, cnt = _reference_terms(a, kind)
    out = []
    for _ in range(n_levels):
        val, cnt = _reference_pool(val), _reference_pool(cnt)
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = val / cnt
            px = {"power": np.sqrt(mean.real), "power_db": 10 * np.log10(mean.real), "phase": np.angle(val),
                  "mean": mean.real}[kind]
            out.append((np.where(cnt > 0, px, np.nan), np.abs(val) / cnt))
    return out


@st.composite
def windows(draw):
    n, m = draw(st.integers(1, 40)), draw(st.integers(1, 40))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    a = (rng.standard_normal((n, m)) * draw(st.sampled_from([0.5, 3.0, 20.0]))).astype(np.float32)
    a[rng.random((n, m)) < draw(st.sampled_from([0.0, 0.3, 0.9]))] = np.nan
    a[rng.random((n, m)) < 0.05] = np.inf
    return a


@settings(max_examples=120, deadline=None)
@given(windows(), st.sampled_from(sorted(KIND_CODES)), st.integers(1, 4))
def test_levels_match_a_plain_numpy_reduction(a, kind, n_levels):
    if kind == "power":
        a = np.abs(a)
    got = levels_of_window(a, kind, n_levels)
    for g, (want, resultant) in zip(got, _reference_levels(a, kind, n_levels), strict=True):
        assert g.dtype == np.float32 and g.shape == want.shape
        np.testing.assert_array_equal(np.isnan(g), np.isnan(want))
        ok = np.isfinite(want) & ((resultant >= 1e-3) if kind == "phase" else True)
        np.testing.assert_allclose(g[ok], want[ok].astype(np.float32), rtol=2.4e-7, atol=0 if kind != "phase"
                                   else 1e-6)


def test_cells_do_not_depend_on_the_thread_count():
    a = np.random.default_rng(3).standard_normal((301, 257)).astype(np.float32)
    runs = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        numba.set_num_threads(threads)
        runs.append(first_cells(a, KIND_CODES["phase"]))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    for x, y in zip(*runs, strict=True):
        np.testing.assert_array_equal(x, y)


def _pyramid_levels(tmp, a: np.ndarray, cuts: list[int]) -> list[np.ndarray]:
    shape = a.shape
    factors = overview_factors(shape, 4)
    with Pyramid(tmp, shape, factors, ["power", "phase"], 4) as p:
        for lo, hi in zip([0, *cuts], [*cuts, shape[0]], strict=True):
            p.add([np.abs(a[lo:hi]), a[lo:hi]])
    out = []
    for name in p.names:
        with rasterio.open(tmp / name) as ds:
            out.append(ds.read())
    return out


@settings(max_examples=15, deadline=None)
@given(st.lists(st.integers(1, 36), max_size=6, unique=True))
def test_rows_fed_in_any_strips_give_the_levels_of_the_whole(tmp_path_factory, cuts):
    a = np.random.default_rng(4).standard_normal((37, 29)).astype(np.float32)
    a[5:9, 3:20] = np.nan
    whole = _pyramid_levels(tmp_path_factory.mktemp("whole"), a, [])
    strips = _pyramid_levels(tmp_path_factory.mktemp("strips"), a, sorted(cuts))
    assert len(whole) == 4  # factors 2 .. 16 until 37 rows fit one 4-pixel tile (37 / 8 > 4)
    for w, s in zip(whole, strips, strict=True):
        np.testing.assert_array_equal(w, s)


def test_missing_rows_and_unknown_reductions_are_refused(tmp_path):
    from sarcli.errors import ProductError

    with pytest.raises(ProductError, match="unknown overview reduction"):
        Pyramid(tmp_path, (8, 8), [2], ["median"], 4)
    with pytest.raises(ProductError, match="3 of 8 rows"):
        with Pyramid(tmp_path, (8, 8), [2], ["mean"], 4) as p:
            p.add([np.zeros((3, 8), np.float32)])


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([None, -300.0, -20.0]), st.sampled_from(["f4", "f8", "c8", "i4"]))
def test_amplitude_db_matches_numpy(seed, floor_db, dtype):
    """The one-pass dB kernel against numpy's 20 log10|x| with the floor / NaN rules (same float64 log:
    equal after the float32 rounding)."""
    from sarcli.io.images import amplitude_db

    rng = np.random.default_rng(seed)
    x = rng.standard_normal((17, 23)) * 10.0 ** rng.uniform(-20, 3, (17, 23))
    x[rng.random(x.shape) < 0.1] = 0.0
    if dtype[0] == "c":
        x = x + 1j * rng.standard_normal(x.shape)
    elif dtype[0] == "f":
        x[rng.random(x.shape) < 0.1] = np.nan
    x = x.astype(dtype)
    a = np.abs(x).astype(np.float64)
    with np.errstate(divide="ignore"):
        want = 20.0 * np.log10(a)
    want[a == 0] = np.nan if floor_db is None else floor_db
    if floor_db is not None:
        want = np.where(np.isnan(want), want, np.maximum(want, floor_db))
    np.testing.assert_array_equal(amplitude_db(x, floor_db=floor_db), want.astype(np.float32))
