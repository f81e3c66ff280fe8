"""One window syntax for GB-SAR: the tapers over frequencies and stops against numpy's own windows
(the tapers GB-SAR used before, so existing images do not move), the BP aperture taper against its
closed form, and the new kaiser through the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sarcli.errors import SarcliError
from sarcli.gbsar.rangecomp import range_compress
from sarcli.gbsar.windows import parse_taper, taper, taper_at, taper_table
from tests.gbsar.helpers import scan_of

# float64 evaluation of the same cosine at the same abscissa computed in another order: a few ulp of 1
ULP_TOL = 1e-15


@given(n=st.integers(2, 2000))
def test_hamming_is_numpy_hamming(n):
    np.testing.assert_allclose(taper("hamming", n), np.hamming(n), rtol=0, atol=ULP_TOL)


@given(n=st.integers(1, 2000))
def test_hann_is_the_former_taper_without_zero_end_weights(n):
    """hann = hamming:0.5 stretched so that its zeros fall one step beyond the end samples."""
    np.testing.assert_allclose(taper("hann", n), np.hanning(n + 2)[1:-1], rtol=0, atol=ULP_TOL)
    np.testing.assert_array_equal(taper("hann", n), taper("hamming:0.5", n))
    assert np.all(taper("hann", n) > 0)


@given(n=st.integers(2, 500), beta=st.floats(0.0, 12.0))
def test_kaiser_is_numpy_kaiser(n, beta):
    # np.kaiser evaluates I0 at the same abscissae; 1e-12 covers its different I0 series summation
    np.testing.assert_allclose(taper(f"kaiser:{beta}", n), np.kaiser(n, beta), rtol=1e-12, atol=1e-12)


def test_rect_and_aliases():
    assert parse_taper("none") == ("rect", 0.0) == parse_taper("rect")
    assert parse_taper("HANN") == ("hamming", 0.5)
    assert parse_taper("kaiser") == ("kaiser", 2.5)
    np.testing.assert_array_equal(taper("none", 7), np.ones(7))
    np.testing.assert_array_equal(taper("hamming", 1), [1.0])


@pytest.mark.parametrize("spec, needle", [
    ("blackman", "unknown window 'blackman'"),
    ("hamming:0.3", "hamming coefficient must be in [0.5, 1]"),
    ("kaiser:x", "is not a number"),
])
def test_bad_specs_are_one_line_errors(spec, needle):
    with pytest.raises(SarcliError) as e:
        parse_taper(spec)
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_bp_aperture_table_is_the_former_closed_form():
    t = np.linspace(0.0, 1.0, taper_table("hamming").size)
    np.testing.assert_allclose(taper_table("hamming"), 0.54 - 0.46 * np.cos(2 * np.pi * t), rtol=0, atol=ULP_TOL)
    np.testing.assert_allclose(taper_table("hann"), 0.5 - 0.5 * np.cos(2 * np.pi * t), rtol=0, atol=ULP_TOL)
    np.testing.assert_array_equal(taper_table("none"), np.ones(t.size))
    np.testing.assert_allclose(taper_at("kaiser:3", t), np.i0(3 * np.sqrt(1 - (2 * t - 1) ** 2)) / np.i0(3),
                               rtol=1e-14)


def test_range_compression_equals_the_numpy_hamming_reference():
    """The range profile with the shared taper equals the former code path: windowed by np.hamming,
    normalized by its sum, zero-padded inverse FFT referenced to f_c (complex64 rounding)."""
    s = scan_of([(0.0, 20.0)], rail=0.1, bw=200e6, n=101)
    prof = range_compress(s, "VV", "hamming")
    x = s.pol("VV")[0].astype(np.complex64) * (np.hamming(101) / np.hamming(101).sum()).astype(np.float32)
    n_fft = 128
    ref = np.fft.ifft(x, n_fft)[:prof.data.shape[1]] * n_fft * np.exp(-2j * np.pi * 50 * np.arange(
        prof.data.shape[1]) / n_fft)
    np.testing.assert_allclose(prof.data[0], ref, rtol=0, atol=2e-6 * np.abs(ref).max())


def test_kaiser_focuses_through_the_cli(cli, tmp_path):
    """kaiser now works for GB-SAR: the report echoes the specs, the target is where it should be."""
    from sarcli.io.gbsar_image import read_gbsar_image
    from sarcli.io.scan import write_scan

    scan = tmp_path / "s.h5"
    write_scan(scan, scan_of([(0.0, 10.0)], rail=1.0, bw=200e6, n=201))
    out = tmp_path / "k.h5"
    r = cli("gbsar", "focus", scan, "-o", out, "--algorithm", "bp", "--max-range", "15",
            "--range-window", "kaiser:2.5", "--azimuth-window", "hann", "--json")
    assert r.exit_code == 0, r.stderr
    rep = json.loads(r.stdout)
    assert rep["range_window"] == "kaiser:2.5" and rep["azimuth_window"] == "hann"
    im = read_gbsar_image(out)
    i, j = np.unravel_index(np.argmax(np.abs(im.image[0])), im.image[0].shape)
    assert abs(im.range_m[i] - 10.0) <= im.range_m[1] and abs(im.azimuth_m[j]) <= im.azimuth_m[1] - im.azimuth_m[0]
    r = cli("gbsar", "focus", scan, "-o", tmp_path / "x.h5", "--range-window", "blackman")
    assert r.exit_code == 2 and r.stderr.count("\n") == 1 and "unknown window 'blackman'" in r.stderr
    assert not (tmp_path / "x.h5").exists()
