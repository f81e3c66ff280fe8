"""Encoders are the decoders' inverse: property round trips over sample values, block sizes and
modes; whole products written as Level-0 and read back; the real echo re-encodes byte for byte."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.io.sentinel1 import encode as E
from sarcli.io.sentinel1.constants import F_REF_HZ, HUFFMAN_CODES, RANGE_DECIMATION
from sarcli.io.sentinel1.decode import BAQ_VALUES, FDBAQ_VALUES, decode_user_data
from sarcli.io.sentinel1.product import read_level0, write_level0
from sarcli.io.sentinel1.reference import reference_baq, reference_bypass, reference_fdbaq
from sarcli.model.raw import Orbit, Radar, RawProduct

FS_S3 = 4 / 9 * 4 * F_REF_HZ


@st.composite
def coded_line(draw, kind):
    """Random symbols of a valid line (NQ 1..300: partial last blocks included), with BRC/THIDX."""
    nq = draw(st.integers(1, 300))
    nb = -(-nq // 128)
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    thidx = rng.integers(0, 256, nb)
    brc = rng.integers(0, 5, nb)
    if kind == 0:
        sym = rng.integers(0, 1024, (4, nq))
    else:
        k = [2 ** (kind - 1) if kind <= 5 else len(HUFFMAN_CODES[b]) for b in brc]
        mags = np.concatenate([rng.integers(0, k[b], (4, min(128, nq - 128 * b))) for b in range(nb)], axis=1)
        sym = rng.integers(0, 2, (4, nq)) * 16 + mags
    return sym, brc, thidx


def _reference(ud, nq, kind):
    if kind == 0:
        return reference_bypass(ud, nq)
    if kind <= 5:
        return reference_baq(ud, nq, kind)
    return reference_fdbaq(ud, nq)[0]


@pytest.mark.parametrize("kind", [0, 3, 4, 5, 12])
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_encoded_symbols_decode_to_the_reference_values(kind, data):
    """numba decoder == plain-Python reference on any encoded line (the reference reads the bits its
    own way), and re-quantising the decoded values gives the same bytes back."""
    sym, brc, thidx = data.draw(coded_line(kind))
    nq = sym.shape[1]
    ud = E.encode_user_data(sym, kind, brc, thidx)
    assert len(ud) % 4 == 0
    got = decode_user_data(ud, nq, kind, 0)
    np.testing.assert_array_equal(got.view(np.uint32), _reference(ud, nq, kind).view(np.uint32))
    sym2, brc2, th2 = E.quantise(got, kind, brc, thidx if kind else None)
    again = E.encode_user_data(sym2, kind, brc2, th2)
    np.testing.assert_array_equal(decode_user_data(again, nq, kind, 0).view(np.uint32), got.view(np.uint32))
    assert again == ud or _ambiguous(kind, brc, thidx, sym)


def _ambiguous(kind, brc, thidx, sym):
    """Two codes of one value (the two zeros; A or B equal to the largest MCode in simple
    reconstruction): then the bytes may differ although the values agree."""
    if kind == 0:
        return bool(np.any(sym == 512))
    for b, t in enumerate(thidx):
        k = 2 ** (kind - 1) if kind <= 5 else len(HUFFMAN_CODES[brc[b]])
        row = (BAQ_VALUES[kind - 3] if kind <= 5 else FDBAQ_VALUES[brc[b]])[t]
        levels = row[np.r_[np.arange(k), 16 + np.arange(k)]]
        if np.unique(levels).size < levels.size:
            return True
    return False


@pytest.mark.parametrize("kind", [3, 4, 5, 12, 13, 14])
def test_quantisation_error_is_that_of_the_quantiser(kind):
    """Gaussian I/Q, 8192 values: the relative RMS error is that of the quantiser, within 10 %.
    BAQ N bit has 2^N levels normalised to sigma = 1 (NRL): the Lloyd-Max errors for a Gaussian are
    sqrt(0.03455) = 0.186 (8 levels), sqrt(0.009497) = 0.0975 (16), sqrt(0.002499) = 0.050 (32). FDBAQ
    BRC 4 is a uniform quantiser (entropy-coded) of step 0.2259 sigma: Delta / sqrt(12) = 0.0652."""
    rng = np.random.default_rng(7)
    x = (rng.normal(size=4096) + 1j * rng.normal(size=4096)) * 60
    sym, brc, thidx = E.quantise(x, kind, 4)
    y = decode_user_data(E.encode_user_data(sym, kind, brc, thidx), x.size // 2, kind, 0)
    rel = np.sqrt(np.mean(np.abs(y - x) ** 2) / np.mean(np.abs(x) ** 2))
    theory = {3: 0.186, 4: 0.0975, 5: 0.050}.get(kind, 0.2259 / np.sqrt(12))
    assert 0.9 * theory < rel < 1.1 * theory


def test_real_echo_reencodes_byte_for_byte(s1_packets):
    data = np.fromfile(s1_packets / "000408-echo.dat", np.uint8)
    ud = data[68:].tobytes()
    nq = int.from_bytes(data[65:67].tobytes(), "big")
    values, brc, thidx = reference_fdbaq(ud, nq)
    sym, brc2, th2 = E.quantise(values, 12, np.array(brc), np.array(thidx))
    assert E.encode_user_data(sym, 12, brc2, th2) == ud


def _product(n_lines=192, n_samples=512, seed=0, orbit=True):
    rng = np.random.default_rng(seed)
    pri = 19499 / F_REF_HZ
    radar = Radar(carrier_frequency_hz=5.405e9, wavelength_m=299792458.0 / 5.405e9, prf_hz=1 / pri,
                  range_sampling_rate_hz=FS_S3, chirp_rate_hz_per_s=1.3449e12, pulse_length_s=1658 / F_REF_HZ,
                  window_start_s=10 * pri + 5271 / F_REF_HZ + 320 / (8 * F_REF_HZ), first_range_m=0.0)
    radar.first_range_m = 299792458.0 / 2 * radar.window_start_s
    echo = np.rint(rng.normal(size=(n_lines, n_samples)) * 20 + 1j * rng.normal(size=(n_lines, n_samples)) * 20)
    t = np.arange(n_lines) * pri
    o = None
    if orbit:
        ot = np.array([-1.0, 0.0, 1.0])
        o = Orbit(ot, np.array([[7.0e6 + k, 1.0e5 * k, 2.0e5] for k in ot]),
                  np.array([[1.0, 7500.0 + k, -10.0] for k in ot]), "ECEF")
    return RawProduct(echo=echo.astype(np.complex64), azimuth_time=t, epoch_utc="2020-06-15T16:24:09.250000Z",
                      radar=radar, agc_db=np.full(n_lines, 6.0, np.float32), orbit=o)


def test_product_round_trip_bypass_is_exact(tmp_path):
    raw = _product()
    path = tmp_path / "s3.dat"
    summary = write_level0(raw, path, compression="bypass")
    assert summary["packets"] == 192 and summary["quantisation_snr_db"] == float("inf")
    l0 = read_level0(path)
    assert list(l0.products) == ["S3_VV"]
    back = l0.products["S3_VV"]
    np.testing.assert_array_equal(back.echo, raw.echo)
    r, b = raw.radar, back.radar
    assert b.range_sampling_rate_hz == pytest.approx(FS_S3, rel=1e-15)
    assert b.prf_hz == pytest.approx(r.prf_hz, rel=1e-12)  # PRI on the clock grid: exact
    assert b.window_start_s == pytest.approx(r.window_start_s, abs=1e-12)
    step = (F_REF_HZ * 1e-6) ** 2 / 2**21 * 1e12  # ramp-rate code step, Hz/s
    assert abs(b.chirp_rate_hz_per_s - r.chirp_rate_hz_per_s) <= step / 2
    # times: each rounded to the fine-time step 2^-16 s (half a step), so differences within one step;
    # plus a few ulps of float64 GPS seconds (~1.3e9 s: 2.4e-7 s)
    np.testing.assert_allclose(back.azimuth_time - back.azimuth_time[0], raw.azimuth_time - raw.azimuth_time[0],
                               atol=2**-16 + 1e-6)
    np.testing.assert_allclose(back.agc_db, raw.agc_db)
    assert back.orbit is not None and back.orbit.frame == "ECEF"
    np.testing.assert_array_equal(back.orbit.position, raw.orbit.position)  # float64 words: exact
    np.testing.assert_allclose(back.orbit.velocity, raw.orbit.velocity, rtol=2**-24)  # float32 words
    t0 = (np.datetime64(back.epoch_utc[:-1]) - np.datetime64(raw.epoch_utc[:-1])) / np.timedelta64(1, "s")
    np.testing.assert_allclose(back.orbit.time + t0, raw.orbit.time, atol=1e-6)
    assert back.replica is not None and back.replica.size == int(np.ceil(1658 / F_REF_HZ * FS_S3))
    assert back.extra_attrs.get("focusable", True) is True


@pytest.mark.parametrize("compression, min_snr_db", [("baq3", 12), ("baq4", 18), ("baq5", 24), ("fdbaq", 18)])
def test_product_round_trip_compressed(tmp_path, compression, min_snr_db):
    raw = _product(n_lines=64, orbit=False)
    summary = write_level0(raw, tmp_path / "x.dat", compression=compression, brc=4)
    back = read_level0(tmp_path / "x.dat").products["S3_VV"]
    e, x = back.echo.astype(np.complex128), raw.echo.astype(np.complex128)
    err = np.mean(np.abs(e - x) ** 2) / np.mean(np.abs(x) ** 2)
    assert -10 * np.log10(err) == pytest.approx(summary["quantisation_snr_db"], abs=1e-6)
    assert summary["quantisation_snr_db"] > min_snr_db


def test_writer_refuses_a_foreign_sampling_rate(tmp_path):
    from sarcli.errors import ConfigError

    raw = _product(n_lines=4, orbit=False)
    raw.radar.range_sampling_rate_hz = 32.317e6
    with pytest.raises(ConfigError, match="not a Sentinel-1 rate"):
        write_level0(raw, tmp_path / "x.dat")
    assert not (tmp_path / "x.dat").exists()


def test_sampling_rates_are_those_of_the_filters():
    """f_dec = L/M * 4 f_ref: S3 59.44 MHz filter -> 66.73 MHz sampling [S1-ISP, §3.2.5.4]."""
    num, den, _, names = RANGE_DECIMATION[4]
    assert names == ("S3",) and num / den * 4 * F_REF_HZ == pytest.approx(66.7284e6, rel=1e-5)
