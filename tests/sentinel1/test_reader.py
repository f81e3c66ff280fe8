"""Level-0 streams -> raw products: grouping, SWST changes, noise/calibration kept apart, TOPS bursts,
the real packets end to end, the reader plug-in and ``sarcli ingest``; corrupted files give one line."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import FormatError
from sarcli.io.raw import read_raw
from sarcli.io.readers import find_reader
from sarcli.io.sentinel1 import encode as E
from sarcli.io.sentinel1.constants import F_REF_HZ
from sarcli.io.sentinel1.decode import decode_user_data
from sarcli.io.sentinel1.headers import decode_headers, walk_packets
from sarcli.io.sentinel1.product import NOT_FOCUSABLE_TOPS, read_level0
from tests.sentinel1.conftest import load_reference

PRI_CODE = 19499


def _stream(segments, nq=64, seed=0):
    """Packets in bypass format: ``segments`` is a list of (n_packets, {field: value}); consecutive
    datation at the PRI. Returns (bytes, list of decoded-expected lines)."""
    rng = np.random.default_rng(seed)
    n = sum(k for k, _ in segments)
    h = E.blank_headers(n)
    t = 1276273467.0 + np.arange(n) * PRI_CODE / F_REF_HZ
    h["coarse_time"] = np.floor(t)
    h["pri_count"] = np.arange(n)
    h["fine_time"] = np.floor((t - np.floor(t)) * 65536)
    h["ecc_number"], h["range_decimation"], h["polarisation"], h["swath_number"] = 13, 4, 7, 2
    h["rank"], h["pri"], h["swst"], h["swl"] = 10, PRI_CODE, 5271, 12178
    h["tx_ramp_rate"], h["tx_pulse_start_frequency"], h["tx_pulse_length"] = 34770, 12970, 1658
    h["number_of_quads"] = nq
    start = 0
    for k, fields in segments:
        for name, v in fields.items():
            h[name][start:start + k] = v
        start += k
    lines, uds = [], []
    for r in h:
        q = int(r["number_of_quads"])
        x = rng.integers(-300, 300, 2 * q) + 1j * rng.integers(-300, 300, 2 * q)
        sym, _, _ = E.quantise(x, 0)
        uds.append(E.encode_user_data(sym, 0))
        lines.append(x.astype(np.complex64))
    return E.pack_packets(h, uds), lines


def test_groups_swst_changes_noise_calibration_and_error_flag(tmp_path):
    blob, lines = _stream([(3, {"signal_type": 8, "ssb_flag": 1, "swath_number": 52}),  # Tx cal preamble
                           (2, {"signal_type": 1}),                                    # noise
                           (5, {}),                                                    # echo
                           (1, {"error_flag": 1}),                                     # dropped
                           (4, {"swst": 5300, "number_of_quads": 80}),                  # window moves
                           (2, {"signal_type": 8, "ssb_flag": 1, "swath_number": 52})])
    path = tmp_path / "sm.dat"
    path.write_bytes(blob)
    l0 = read_level0(path)
    assert list(l0.products) == ["S3_VV_1", "S3_VV_2"]
    assert {p.extra_attrs["s1_swath"] for p in l0.products.values()} == {"S3"}
    a, b = l0.products["S3_VV_1"], l0.products["S3_VV_2"]
    np.testing.assert_array_equal(a.echo, np.stack(lines[5:10]))
    np.testing.assert_array_equal(b.echo, np.stack(lines[11:15]))
    assert b.radar.window_start_s - a.radar.window_start_s == pytest.approx(29 / F_REF_HZ, rel=1e-9)
    for p in (a, b):
        np.testing.assert_array_equal(p.auxiliary["s1/noise"], np.stack(lines[3:5]))
        np.testing.assert_array_equal(p.auxiliary["s1/calibration"], np.stack(lines[0:3] + lines[15:17]))
        assert p.extra_attrs["s1_n_noise_lines"] == 2 and p.extra_attrs["s1_n_calibration_lines"] == 5
    assert any("error flag" in n for n in l0.notes) and any("2 products" in n for n in l0.notes)
    # geometry: window start = rank PRI + SWST + 320/(8 f_ref) [S1-ISP §3.2.5.11]
    assert a.radar.window_start_s == pytest.approx((10 * PRI_CODE + 5271 + 40) / F_REF_HZ, rel=1e-12)


def test_tops_bursts_are_kept_and_marked_not_focusable(tmp_path):
    iw = {"ecc_number": 8}
    segs = []
    for _burst in range(2):
        for rgdec, swath in ((8, 10), (11, 11), (9, 12)):
            segs.append((6, {**iw, "range_decimation": rgdec, "swath_number": swath}))
    blob, _ = _stream(segs)
    (tmp_path / "iw.dat").write_bytes(blob)
    l0 = read_level0(tmp_path / "iw.dat")
    assert list(l0.products) == ["IW1_VV", "IW2_VV", "IW3_VV"]
    for p in l0.products.values():
        assert p.shape == (12, 128)
        assert p.extra_attrs["focusable"] is False and p.extra_attrs["not_focusable_reason"] == NOT_FOCUSABLE_TOPS
        np.testing.assert_array_equal(p.auxiliary["s1/burst_first_line"], [0, 6])
        np.testing.assert_array_equal(p.auxiliary["s1/burst_n_lines"], [6, 6])


def test_real_packets_as_one_stream(s1_packets, tmp_path):
    """noise + TX cal + FDBAQ echo of the real data take, concatenated: one S3_VV product whose echo
    line, noise line and calibration line equal the reference decodes bit for bit."""
    names = ("000000-noise", "000008-txcal", "000408-echo")
    path = tmp_path / "real.dat"
    path.write_bytes(b"".join((s1_packets / f"{n}.dat").read_bytes() for n in names))
    refs = {n: load_reference(s1_packets / f"{n}.npz")["udf"] for n in names}
    p = read_level0(path).products["S3_VV"]
    np.testing.assert_array_equal(p.echo[0].view(np.uint32), refs["000408-echo"].view(np.uint32))
    np.testing.assert_array_equal(p.auxiliary["s1/noise"][0].view(np.uint32), refs["000000-noise"].view(np.uint32))
    cal = p.auxiliary["s1/calibration"][0]
    np.testing.assert_array_equal(cal[:refs["000008-txcal"].size].view(np.uint32),
                                  refs["000008-txcal"].view(np.uint32))
    assert not np.any(cal[refs["000008-txcal"].size:])  # zero padding to the widest calibration line
    assert p.radar.range_sampling_rate_hz == pytest.approx(4 / 9 * 4 * F_REF_HZ)
    assert p.agc_db[0] == pytest.approx(6.0)  # RXG code 12: -6 dB [S1-ISP §3.2.5.5]
    assert p.epoch_utc.startswith("2020-06-15T16:")  # S1B_S3_RAW__0SDV_20200615T162409 (data README)


def test_reader_plugin_and_cli_ingest(tmp_path, cli, s1_packets):
    path = tmp_path / "real.dat"
    path.write_bytes(b"".join((s1_packets / f"{n}.dat").read_bytes()
                              for n in ("000000-noise", "000008-txcal", "000408-echo")))
    assert find_reader([path]).name == "sentinel1-l0"
    r = cli("ingest", path, "-o", tmp_path / "out.h5", "--json")
    assert r.exit_code == 0, r.stderr
    raw = read_raw(tmp_path / "out.h5")
    direct = read_level0(path).products["S3_VV"]
    np.testing.assert_array_equal(raw.echo, direct.echo)
    assert raw.source == "sentinel1-l0" and raw.extra_attrs["s1_swath"] == "S3"
    for name in ("s1/noise", "s1/calibration", "s1/echo_headers"):
        np.testing.assert_array_equal(raw.auxiliary[name], direct.auxiliary[name])


def test_cli_ingest_several_data_sets_one_product_each(tmp_path, cli):
    """Several data sets: -o STEM.h5 gives STEM_NAME.h5 files, any other -o is a folder of NAME.h5
    (the naming of docs/ingest.md)."""
    blob, _ = _stream([(4, {}), (4, {"swst": 5300})])
    (tmp_path / "x.dat").write_bytes(blob)
    r = cli("ingest", tmp_path / "x.dat", "-o", tmp_path / "one.h5")
    assert r.exit_code == 0 and r.stderr.count("wrote") == 2, r.stderr
    assert sorted(p.name for p in tmp_path.glob("one_*.h5")) == ["one_S3_VV_1.h5", "one_S3_VV_2.h5"]
    out = tmp_path / "all"
    assert cli("ingest", tmp_path / "x.dat", "-o", out).exit_code == 0
    assert sorted(p.name for p in out.iterdir()) == ["S3_VV_1.h5", "S3_VV_2.h5"]


def test_sniff_refuses_other_files(tmp_path):
    from sarcli.io.readers.sentinel1 import READER

    (tmp_path / "text.dat").write_bytes(b"not a packet" * 10)
    blob, _ = _stream([(2, {})])
    bad = bytearray(blob)
    bad[12] ^= 0xFF  # sync marker
    (tmp_path / "nosync.dat").write_bytes(bytes(bad))
    (tmp_path / "ok.dat").write_bytes(blob)
    assert not READER.sniff([tmp_path / "text.dat"]) and not READER.sniff([tmp_path / "nosync.dat"])
    assert READER.sniff([tmp_path / "ok.dat"])


def _fdbaq_file(tmp_path):
    rng = np.random.default_rng(3)
    blob, _ = _stream([(6, {"baq_mode": 12})], nq=300)
    data = np.frombuffer(blob, np.uint8)
    h = decode_headers(data, walk_packets(data))
    uds = []
    for _ in h:
        x = (rng.normal(size=600) + 1j * rng.normal(size=600)) * 50
        sym, brc, thidx = E.quantise(x, 12, rng.integers(0, 5, 3))
        uds.append(E.encode_user_data(sym, 12, brc, thidx))
    return E.pack_packets(h, uds)


@settings(max_examples=60, deadline=None)
@given(cut=st.integers(1, 3000), flips=st.lists(st.integers(0, 10**6), min_size=1, max_size=4))
def test_corrupted_files_give_one_line_or_decode(tmp_path_factory, cut, flips):
    """Truncated, bit-flipped or length-corrupted streams: a FormatError of one line naming the file,
    or (a flip in sample bits) a clean decode -- never another exception."""
    tmp = tmp_path_factory.mktemp("fuzz")
    blob = bytearray(_fdbaq_file(tmp))
    for f in flips:
        blob[f % len(blob)] ^= 1 << (f % 8)
    for data in (bytes(blob), bytes(blob[:-cut])):
        path = tmp / "x.dat"
        path.write_bytes(data)
        try:
            read_level0(path)
        except FormatError as e:
            msg = str(e)
            assert "\n" not in msg and str(path) in msg


def test_truncated_file_is_refused_or_kept_partial(tmp_path):
    blob, lines = _stream([(5, {})])
    (tmp_path / "t.dat").write_bytes(blob[:-10])
    with pytest.raises(FormatError, match="truncated"):
        read_level0(tmp_path / "t.dat")
    l0 = read_level0(tmp_path / "t.dat", allow_truncated=True)
    np.testing.assert_array_equal(l0.products["S3_VV"].echo, np.stack(lines[:4]))
    assert any("truncated" in n for n in l0.notes)


def test_wrong_length_in_header_is_refused(tmp_path):
    """A user data field 4 octets longer than its sections: the decoder's length check refuses it."""
    data = np.frombuffer(_stream([(1, {})], nq=64)[0], np.uint8)
    h = decode_headers(data, walk_packets(data))
    ud = data[68:].tobytes() + b"\0\0\0\0"
    with pytest.raises(FormatError, match="length"):
        decode_user_data(ud, int(h["number_of_quads"][0]), 0)
    (tmp_path / "w.dat").write_bytes(E.pack_packets(h, [ud]))
    with pytest.raises(FormatError, match="does not match"):
        read_level0(tmp_path / "w.dat")


def test_safe_folder_reads_every_measurement_file(tmp_path, cli):
    """A .SAFE folder: the VV and VH measurement files become S3_VV and S3_VH; index/annotation skipped."""
    safe = tmp_path / "S1B_S3_RAW__0SDV_TEST.SAFE"
    safe.mkdir()
    for name, rx in (("s1b-s3-raw-s-vv-test.dat", 0), ("s1b-s3-raw-s-vh-test.dat", 1)):
        (safe / name).write_bytes(_stream([(4, {"rx_channel_id": rx})])[0])
    (safe / "s1b-s3-raw-s-vv-test-index.dat").write_bytes(b"\0" * 36)
    (safe / "s1b-s3-raw-s-vv-test-annot.dat").write_bytes(b"\0" * 26)
    out = tmp_path / "out"
    out.mkdir()
    r = cli("ingest", safe, "-o", out)
    assert r.exit_code == 0, r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["S3_VH.h5", "S3_VV.h5"]
    assert read_raw(out / "S3_VH.h5").extra_attrs["s1_polarisation"] == "VH"
