"""The focus sink: blocks in any order give the multilook of the whole image bit for bit, and the
statistics of the whole image (independent numpy formulas) to float64 rounding."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import SarcliError
from sarcli.focus.geocode import multilook
from sarcli.focus.quality import line_sums
from sarcli.focus.sink import BlockSink, LookAccumulator


def _image(n, m, seed=0):
    rng = np.random.default_rng(seed)
    z = (rng.standard_normal((n, m)) + 1j * rng.standard_normal((n, m))) * rng.uniform(0, 50, (n, m))
    z[rng.random((n, m)) < 0.02] = 0  # exact zeros (0 ln 0)
    return z.astype(np.complex64)


@settings(deadline=None)  # the first example loads the kernel from the numba cache
@given(n=st.integers(1, 90), m=st.integers(1, 40), la=st.integers(1, 9), lr=st.integers(1, 5),
       cuts=st.lists(st.integers(1, 89), max_size=6), order=st.randoms(use_true_random=False))
def test_multilook_of_blocks_in_any_order_is_the_multilook_of_the_image(n, m, la, lr, cuts, order):
    img = _image(n, m, n * 100 + m)
    if n < la or m < lr:
        with pytest.raises(SarcliError):
            LookAccumulator((n, m), la, lr)
        return
    edges = sorted({0, n, *[c for c in cuts if c < n]})
    blocks = list(zip(edges[:-1], edges[1:], strict=True))
    order.shuffle(blocks)
    acc = LookAccumulator((n, m), la, lr)
    for a, b in blocks:
        acc.add(a, img[a:b])
    np.testing.assert_array_equal(acc.result(), multilook(img, la, lr))


@settings(deadline=None)
@given(n=st.integers(1, 40), m=st.integers(1, 40), la=st.integers(1, 7), lr=st.integers(1, 7),
       dtype=st.sampled_from(["c8", "c16", "f4"]))
def test_multilook_is_the_mean_intensity_of_each_cell(n, m, la, lr, dtype):
    """Against numpy's float64 cell means: the kernel sums the same float64 terms in another order
    (last float64 bits), so the float32 results agree to one float32 unit (2^-24 relative)."""
    img = _image(n, m, n * 7 + m)
    img = img.real.astype(dtype) if dtype == "f4" else img.astype(dtype)
    if n < la or m < lr:
        with pytest.raises(SarcliError):
            multilook(img, la, lr)
        return
    p = np.abs(img.astype(np.complex128)) ** 2
    r, c = n // la, m // lr
    want = p[:r * la, :c * lr].reshape(r, la, c, lr).mean(axis=(1, 3))
    got = multilook(img, la, lr)
    assert got.dtype == np.float32
    np.testing.assert_allclose(got, want.astype(np.float32), rtol=1.2e-7, atol=0)


def test_a_missing_block_is_an_error_not_a_hole():
    acc = LookAccumulator((10, 4), 2, 2)
    acc.add(0, _image(5, 4))
    with pytest.raises(SarcliError, match="never received"):
        acc.result()


def _reference_statistics(z):
    """contrast = std(I)/mean(I), entropy = -sum p ln p with p = I / sum I (the definitions, in numpy)."""
    i = np.abs(z.astype(np.complex128)).ravel() ** 2
    p = i[i > 0] / i.sum()
    return i.std() / i.mean(), float(-np.sum(p * np.log(p)))


def test_sink_statistics_and_intensities_from_blocks_in_any_order():
    img = _image(301, 57, 3)
    written = np.zeros_like(img)

    def write(first, lines):
        written[first:first + lines.shape[0]] = lines

    sink = BlockSink(write, img.shape, ((1, 1), (4, 3), (1, 1)))
    for a, b in [(200, 301), (0, 64), (120, 200), (64, 120)]:
        sink(a, img[a:b], line_sums(img[a:b]) if a == 120 else None)
    np.testing.assert_array_equal(written, img)
    contrast, entropy = _reference_statistics(img[10:291])
    s = sink.statistics(10, 290)
    assert s["n_pixels"] == 281 * 57
    # the sink's I = |z|^2 is float32 (as image_statistics'): <= 2 ulp = 2.4e-7 relative per pixel, so the
    # mean, the std and ln I move by at most that much relative (the float64 sums add ~1e-12)
    assert s["contrast"] == pytest.approx(contrast, rel=1e-6)
    assert s["entropy"] == pytest.approx(entropy, rel=1e-6)
    assert sink.statistics(5, 4)["n_pixels"] == img.size  # no fully focused line: the whole image
    np.testing.assert_array_equal(sink.intensity(4, 3), multilook(img, 4, 3))
    np.testing.assert_array_equal(sink.intensity(1, 1), multilook(img, 1, 1))


def test_statistics_of_a_zero_image_are_empty():
    sink = BlockSink(lambda a, b: None, (8, 8))
    sink(0, np.zeros((8, 8), np.complex64))
    assert sink.statistics(0, 7) == {}


def test_a_large_intensity_waits_in_an_anonymous_file(tmp_path, monkeypatch):
    """Spilled while the blocks arrive (no file left in the folder), read back whole: the same cells."""
    import sarcli.focus.sink as sink_mod

    monkeypatch.setattr(sink_mod, "SPILL_BYTES", 1000)
    img = _image(203, 61, 5)
    acc = LookAccumulator(img.shape, 2, 3, str(tmp_path))
    assert acc.out is None and acc._file is not None
    for a, b in [(100, 203), (0, 37), (37, 100)]:
        acc.add(a, img[a:b])
    assert list(tmp_path.iterdir()) == []
    np.testing.assert_array_equal(acc.result(), multilook(img, 2, 3))
    np.testing.assert_array_equal(acc.result(), multilook(img, 2, 3))  # read back once, kept
