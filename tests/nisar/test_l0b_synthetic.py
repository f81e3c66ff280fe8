"""The L0B reader on small files written here with plain h5py (tests/nisar/synth.py): channels and
products, windows, fill values, calibration lines, the reader plug-in, and damaged files (one line)."""

from __future__ import annotations

import shutil

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from synth import FILL, T0, write_l0b

from sarcli.errors import ConfigError, FormatError, ProductError, SarcliError
from sarcli.io.nisar.l0b import read_l0b, sniff_l0b
from sarcli.io.readers import READERS, find_reader

C = 299_792_458.0


@pytest.fixture(scope="module")
def quad(tmp_path_factory):
    p = tmp_path_factory.mktemp("l0b") / "quad.h5"
    return p, write_l0b(p, tx_v=True, pols=("HH", "HV", "VH", "VV"))


def test_receive_channels_share_a_product_transmit_groups_do_not(quad):
    p, w = quad
    c = read_l0b(p)
    assert list(c.products) == ["A_HH_HV", "A_VH_VV"]  # txV pulses are interleaved: another time grid
    hh = c.products["A_HH_HV"]
    assert hh.extra_attrs["polarizations"] == "HH,HV" and hh.n_channels == 2
    lut = w["lut"]
    for k, pol in enumerate(("HH", "HV")):
        codes = w["codes"][pol]
        plain = lut[codes["r"]] + 1j * lut[codes["i"]]
        plain[(codes["r"] == FILL) | (codes["i"] == FILL)] = 0
        plain[:, :4] = 0  # valid window [4, 90)
        plain[:, 90:] = 0
        plain[w["cal"] != 0] = 0
        np.testing.assert_array_equal(hh.channel(k), plain)
    vv = c.products["A_VH_VV"]
    np.testing.assert_allclose(vv.azimuth_time - hh.azimuth_time, 0.5 / 1600.0, atol=1e-9)
    assert any("fill-value" in n for n in c.notes)


def test_calibration_lines_carry_every_channel(quad):
    p, w = quad
    hh = read_l0b(p, polarizations=("HH", "HV")).products["A_HH_HV"]
    c = hh.auxiliary
    np.testing.assert_array_equal(c["calibration/line"], np.flatnonzero(w["cal"]))
    assert c["calibration/echo"].shape == (2, 2, 96)
    lut = w["lut"]
    codes = w["codes"]["HV"][c["calibration/line"]]
    expect = lut[codes["r"]] + 1j * lut[codes["i"]]
    expect[:, :4] = expect[:, 90:] = 0
    np.testing.assert_array_equal(c["calibration/echo"][:, 1], expect)
    # + T/2 (12 us pulse)
    np.testing.assert_allclose(c["calibration/azimuth_time"], T0 + c["calibration/line"] / 1600.0 + 6e-6)


def test_timing_convention_and_quantization(quad):
    p, w = quad
    hh = read_l0b(p, frequencies=("A",), polarizations=("HH",)).products["A_HH"]
    r = hh.radar
    assert r.window_start_s == pytest.approx(2 * 850e3 / C - 6e-6, rel=1e-15)
    assert r.first_range_m == pytest.approx(850e3 - C * 12e-6 / 4, rel=1e-15)
    assert r.quantization_bits == 5  # 32 codes in use (the fill code is not a level)
    assert hh.extra_attrs["nisar_valid_samples"].tolist() == [[4, 90]]


def test_two_subswaths_and_windows_beyond_the_samples(tmp_path):
    p = tmp_path / "sub.h5"
    w = write_l0b(p, pols=("HH",), n_sub=2, window=(0, 40), fill_at=())
    hh = read_l0b(p).products["A_HH"]
    ok = hh.echo[w["cal"] == 0]
    assert np.all(ok[:, 40:42] == 0) and np.all(ok[:, :40] != 0) and np.all(ok[:, 42:] != 0)


def test_reader_plugin_sniffs_and_reads(quad, tmp_path):
    p, _ = quad
    reader = find_reader([p])
    assert reader.name == "nisar-l0b" and sniff_l0b(p)
    ing = reader.read([p], reader.Options(polarizations=("VV",)))
    assert list(ing.products) == ["A_VV"] and ing.inputs == (p,)
    assert ing.parameters == {"format": "nisar-l0b", "frequencies": [], "polarizations": ["VV"]}
    with pytest.raises(ConfigError, match="no data for"):
        reader.read([p], reader.Options(frequencies=("B",)))
    with pytest.raises(ConfigError, match="polarizations"):
        reader.Options(polarizations=("XX",))
    other = tmp_path / "plain.h5"
    with h5py.File(other, "w") as f:
        f["x"] = 1
    assert not READERS.get("nisar-l0b").sniff([other])


def test_written_raw_product_keeps_the_calibration_lines(quad, tmp_path):
    from sarcli.io.raw import read_raw, write_raw

    p, w = quad
    hh = read_l0b(p).products["A_HH_HV"]
    out = tmp_path / "raw.h5"
    write_raw(out, hh, inputs=(p,))
    back = read_raw(out)
    np.testing.assert_array_equal(back.auxiliary["calibration/echo"], hh.auxiliary["calibration/echo"])
    np.testing.assert_array_equal(back.auxiliary["calibration/line"], np.flatnonzero(w["cal"]))
    assert back.extra_attrs["polarizations"] == "HH,HV"
    np.testing.assert_array_equal(back.echo_channels[0], hh.echo_channels[0])


@pytest.mark.parametrize("edit, message", [
    (lambda f: f.__delitem__("science/LSAR/RRSD/swaths/frequencyA/txH/slantRange"), "slantRange missing"),
    (lambda f: f.__delitem__("science/LSAR/RRSD/lowRateTelemetry/orbit"), "orbit missing"),
    (lambda f: f.__delitem__("science/LSAR/identification/lookDirection"), "lookDirection"),
    (lambda f: f["science/LSAR/RRSD/swaths/frequencyA/txH/UTCtime"].attrs.__setitem__("units", "days"), "units"),
    (lambda f: f["science/LSAR/RRSD/swaths/frequencyA/txH/rxH/BFPQLUT"].__setitem__(3, np.nan), "NaN"),
    (lambda f: f.__delitem__("science/LSAR/RRSD/swaths/frequencyA/txH/rxH/HH"), "HH missing"),
    (lambda f: f.__delitem__("science/LSAR/RRSD"), "not a NISAR RRSD"),
])
def test_incomplete_files_one_line(tmp_path, edit, message):
    p = tmp_path / "bad.h5"
    write_l0b(p, pols=("HH",))
    with h5py.File(p, "r+") as f:
        edit(f)
    with pytest.raises(FormatError) as e:
        read_l0b(p)
    assert message in str(e.value) and "\n" not in str(e.value) and str(p) in str(e.value)


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    p = tmp_path_factory.mktemp("fuzz") / "pristine.h5"
    write_l0b(p, pols=("HH",), n_lines=32, n_samples=48, window=(0, 48), cal_lines=(0,))
    return p


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_fuzzed_files_read_or_fail_in_one_line(pristine, tmp_path, data):
    """Truncated files and files with corrupted bytes: the reader returns products or raises one
    SarcliError line; never another exception."""
    raw = bytearray(pristine.read_bytes())
    mode = data.draw(st.sampled_from(["truncate", "flip"]))
    if mode == "truncate":
        raw = raw[:data.draw(st.integers(0, len(raw) - 1))]
    else:
        for _ in range(data.draw(st.integers(1, 8))):
            k = data.draw(st.integers(0, len(raw) - 1))
            raw[k] ^= data.draw(st.integers(1, 255))
    p = tmp_path / "fuzz.h5"
    p.write_bytes(bytes(raw))
    try:
        c = read_l0b(p)
    except SarcliError as e:
        assert str(e) and "\n" not in str(e)
    else:
        assert c.products


def test_missing_and_non_hdf5_files(tmp_path):
    with pytest.raises(ProductError, match="no such file"):
        read_l0b(tmp_path / "absent.h5")
    t = tmp_path / "text.h5"
    t.write_text("not hdf5")
    with pytest.raises(FormatError, match="not a readable HDF5"):
        read_l0b(t)
    assert not sniff_l0b(t)


def test_left_looking_file_with_right_looking_attitude_refused(tmp_path):
    p = tmp_path / "left.h5"
    write_l0b(p, pols=("HH",), look="Left")
    with pytest.raises(FormatError, match="left-looking"):
        read_l0b(p)


def test_no_attitude_is_a_note(tmp_path):
    p = tmp_path / "noatt.h5"
    write_l0b(p, pols=("HH",), with_attitude=False)
    c = read_l0b(p)
    assert c.products["A_HH"].attitude is None and any("no attitude" in n for n in c.notes)


def test_inputs_never_modified(quad, tmp_path):
    import hashlib

    p, _ = quad
    copy = tmp_path / "copy.h5"
    shutil.copy(p, copy)
    before = hashlib.sha256(copy.read_bytes()).hexdigest()
    read_l0b(copy)
    assert hashlib.sha256(copy.read_bytes()).hexdigest() == before
