"""Real Sentinel-1 packets (noise: BAQ 5-bit; TX calibration: decimation only; echo: FDBAQ): every
header field and every decoded sample equals the independent reference decode, bit for bit."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from sarcli.io.sentinel1 import headers as H
from sarcli.io.sentinel1.decode import decode_user_data
from sarcli.io.sentinel1.reference import reference_baq, reference_bypass, reference_fdbaq
from tests.sentinel1.conftest import PACKETS, load_reference

#: our field name -> path of the field in the reference's secondary header records.
SECONDARY = {
    "coarse_time": "datation.coarse_time",
    "fine_time": "datation.fine_time",
    "sync_marker": "fixed_ancillary_data.sync_marker",
    "data_take_id": "fixed_ancillary_data.data_take_id",
    "ecc_number": "fixed_ancillary_data.ecc_num",
    "test_mode": "fixed_ancillary_data.test_mode",
    "rx_channel_id": "fixed_ancillary_data.rx_channel_id",
    "instrument_configuration_id": "fixed_ancillary_data.instrument_configuration_id",
    "subcom_word_index": "subcom_ancillary_data.data_word_index",
    "space_packet_count": "counters.space_packet_count",
    "pri_count": "counters.pri_count",
    "error_flag": "radar_configuration_support.error_flag",
    "baq_mode": "radar_configuration_support.baq_mode",
    "baq_block_length": "radar_configuration_support.baq_block_length",
    "range_decimation": "radar_configuration_support.range_decimation",
    "rx_gain": "radar_configuration_support.rx_gain",
    "tx_ramp_rate": "radar_configuration_support.tx_ramp_rate",
    "tx_pulse_start_frequency": "radar_configuration_support.tx_pulse_start_freq",
    "tx_pulse_length": "radar_configuration_support.tx_pulse_length",
    "rank": "radar_configuration_support.rank",
    "pri": "radar_configuration_support.pri",
    "swst": "radar_configuration_support.swst",
    "swl": "radar_configuration_support.swl",
    "ssb_flag": "radar_configuration_support.sas.ssb_flag",
    "polarisation": "radar_configuration_support.sas.polarization",
    "temperature_compensation": "radar_configuration_support.sas.temperature_compensation",
    "sas_beam_or_cal": "radar_configuration_support.sas._dynamic_data",
    "beam_address": "radar_configuration_support.sas._beam_address",
    "cal_mode": "radar_configuration_support.ses.cal_mode",
    "tx_pulse_number": "radar_configuration_support.ses.tx_pulse_number",
    "signal_type": "radar_configuration_support.ses.signal_type",
    "swap": "radar_configuration_support.ses.swap",
    "swath_number": "radar_configuration_support.ses.swath_number",
    "number_of_quads": "radar_sample_count.number_of_quads",
}
PRIMARY = ("packet_version_number", "packet_type", "secondary_header_flag", "pid", "pcat", "sequence_flags",
           "packet_sequence_count", "packet_data_length")


def _get(record, path):
    for part in path.split("."):
        record = getattr(record, part)
    return int(record)


def _load(d, name):
    data = np.fromfile(d / f"{name}.dat", np.uint8)
    offsets = H.walk_packets(data)
    h = H.decode_headers(data, offsets)
    H.check_headers(h)
    return data, h, load_reference(d / f"{name}.npz")


@pytest.mark.parametrize("name", PACKETS)
def test_every_header_field_matches(s1_packets, name):
    data, h, ref = _load(s1_packets, name)
    assert h.size == 1 and int(h["packet_data_length"][0]) + 7 == data.size
    got = {k: int(h[k][0]) for k in h.dtype.names if k != "offset"}
    expected = {k: _get(ref["primary_header"], k) for k in PRIMARY}
    expected |= {k: _get(ref["secondary_header"], path) for k, path in SECONDARY.items()}
    expected["subcom_word"] = int.from_bytes(ref["secondary_header"].subcom_ancillary_data.data_word, "big")
    assert got == expected


@pytest.mark.parametrize("name", PACKETS)
def test_every_sample_matches_bit_for_bit(s1_packets, name):
    data, h, ref = _load(s1_packets, name)
    r = h[0]
    got = decode_user_data(data[68:].tobytes(), int(r["number_of_quads"]), int(r["baq_mode"]), int(r["test_mode"]))
    assert got.dtype == np.complex64 and got.shape == ref["udf"].shape
    np.testing.assert_array_equal(got.view(np.uint32), ref["udf"].view(np.uint32))


@pytest.mark.parametrize("name", PACKETS)
def test_reference_decoder_matches_too(s1_packets, name):
    """The plain-Python reference (the oracle of the property tests) is itself right on real data."""
    data, h, ref = _load(s1_packets, name)
    ud, nq, mode = data[68:].tobytes(), int(h["number_of_quads"][0]), int(h["baq_mode"][0])
    got = {0: lambda: reference_bypass(ud, nq), 5: lambda: reference_baq(ud, nq, 5),
           12: lambda: reference_fdbaq(ud, nq)[0]}[mode]()
    np.testing.assert_array_equal(got.view(np.uint32), ref["udf"].view(np.uint32))


def test_echo_second_decode_is_the_correctly_rounded_product(s1_packets):
    """The echo's ``.npz`` holds a second decode (``decoded_udf``) that rounds NRL*SF once from float64;
    ours (like ``udf``) multiplies the float32 table values. The two differ by at most 1 ulp, and only
    in normal reconstruction -- which pins down the convention (docs/sentinel1.md)."""
    data, h, ref = _load(s1_packets, "000408-echo")
    ours = decode_user_data(data[68:].tobytes(), int(h["number_of_quads"][0]), 12).view(np.float32)
    other = ref["decoded_udf"].view(np.float32)
    ulp = np.abs(ours.view(np.int32).astype(np.int64) - other.view(np.int32).astype(np.int64))
    assert ulp.max() == 1 and 0 < np.count_nonzero(ulp) < ulp.size


def test_echo_packet_physics(s1_packets):
    """Stripmap S3 echo: the chirp is centred at baseband (start + K T / 2 = 0 to a code step of
    f_ref/2^14 = 2.3 kHz), its bandwidth fits in the decimated sampling rate, and the swath's filter
    is the S3 one [S1-ISP, §3.2.5.4, §3.2.5.6-8]."""
    _, h, _ = _load(s1_packets, "000408-echo")
    p = H.physical(h)
    k, t, f0 = p["tx_ramp_rate_hz_per_s"][0], p["tx_pulse_length_s"][0], p["tx_start_frequency_hz"][0]
    assert abs(f0 + k * t / 2) < 37.53472224e6 / 2**14
    assert 0 < k * t < H.range_sampling_rate_hz(int(h["range_decimation"][0]))
    assert int(h["range_decimation"][0]) == 4 and int(h["ecc_number"][0]) == 13  # S3


def test_the_packet_folder_ingests_its_echo_file(cli, s1_packets, tmp_path):
    """Ingesting the folder takes the echo file beside the noise and calibration files (each with only
    noise or calibration packets: named as skipped), not stop at the first one; the product is the echo
    file's own."""
    r = cli("ingest", s1_packets, "-o", tmp_path / "folder.h5", "--json")
    assert r.exit_code == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["shape"] == [1, 21558] and doc["source"] == "sentinel1-l0"
    skipped = [n for n in doc["notes"] if "no echo packets" in n]
    assert len(skipped) == 2 and any("000000-noise.dat" in n for n in skipped)
    assert any("000008-txcal.dat" in n for n in skipped)
    r = cli("ingest", s1_packets / "000408-echo.dat", "-o", tmp_path / "file.h5")
    assert r.exit_code == 0, r.stderr
    with h5py.File(tmp_path / "folder.h5") as a, h5py.File(tmp_path / "file.h5") as b:
        assert np.array_equal(a["echo"][...], b["echo"][...])
    r = cli("ingest", s1_packets / "000000-noise.dat", "-o", tmp_path / "noise.h5")  # one file: still refused
    assert r.exit_code == 1 and "no echo packets" in r.stderr
