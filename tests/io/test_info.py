"""``sarcli info``: pinned JSON keys for raw products, a generic summary for any other product type."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sarcli.io.h5common import atomic_h5, dataset
from sarcli.io.raw import write_raw

RAW_KEYS = {  # released keys: tests pin them (the "Machine-readable output" of `sarcli info --json`, plus the spans)
    "product_type", "shape", "prf_hz", "range_sampling_rate_hz", "wavelength_m", "first_range_m",
    "azimuth_start_utc", "n_state_vectors", "orbit_frame", "schema_version", "file", "source",
    "epoch_utc", "provenance", "attributes", "datasets", "main_dataset", "n_lines", "n_samples",
    "azimuth_stop_utc", "azimuth_span_s", "carrier_frequency_hz", "chirp_rate_hz_per_s", "pulse_length_s",
    "last_range_m", "quantization_bits", "n_channels", "has_replica", "has_agc", "has_attitude", "has_truth",
    "radar", "orbit_start_utc", "orbit_stop_utc", "orbit_span_s", "time_spans", "look_side",
}
GENERIC_KEYS = {"file", "product_type", "schema_version", "shape", "main_dataset", "epoch_utc", "source",
                "provenance", "attributes", "datasets", "time_spans"}


def test_raw_info_keys_and_values(cli, make_raw, tmp_path):
    raw = make_raw(n_lines=20)
    write_raw(tmp_path / "r.h5", raw)
    r = cli("info", tmp_path / "r.h5", "--json")
    assert r.exit_code == 0
    s = json.loads(r.stdout)
    assert set(s) == RAW_KEYS
    assert s["product_type"] == "raw" and s["shape"] == [20, 96] and isinstance(s["shape"], list)
    assert s["prf_hz"] == raw.radar.prf_hz and s["range_sampling_rate_hz"] == raw.radar.range_sampling_rate_hz
    assert s["wavelength_m"] == raw.radar.wavelength_m and s["first_range_m"] == raw.radar.first_range_m
    assert s["azimuth_start_utc"] == "2002-06-16T15:41:07.250125Z"
    assert s["azimuth_span_s"] == pytest.approx(19 / raw.radar.prf_hz)
    assert s["last_range_m"] == pytest.approx(raw.radar.first_range_m + 95 * 299792458 / 2 / 32.317075e6)
    assert s["n_state_vectors"] == 15 and s["orbit_frame"] == "ECI" and s["orbit_span_s"] == 14 * 480
    assert s["orbit_start_utc"] == "2002-06-16T14:45:07.250125Z"
    assert s["has_replica"] and s["has_agc"] and not s["has_truth"]
    assert s["provenance"]["product_type"] == "raw"
    human = cli("info", tmp_path / "r.h5")
    assert human.exit_code == 0 and "raw product" in human.stdout and "15 state vectors (ECI)" in human.stdout


def test_generic_product_summary(cli, tmp_path):
    # A product type this command does not know (e.g. added later by another module): described from its
    # layout (a known type is read, and validated, by its own reader first).
    with atomic_h5(tmp_path / "s.h5", "widget", "3", parameters={"algorithm": "rd"}) as f:
        f.attrs["epoch_utc"] = "2002-06-16T15:41:00.000000Z"
        dataset(f, "image", np.zeros((12, 34), np.complex64), units="1")
        dataset(f, "range_m", np.arange(34.0), units="m")
        dataset(f, "azimuth_time", 10.0 + np.arange(12) * 0.5, units="s")
    s = json.loads(cli("info", tmp_path / "s.h5", "--json").stdout)
    assert GENERIC_KEYS <= set(s)
    assert s["product_type"] == "widget" and s["schema_version"] == "3" and s["shape"] == [12, 34]
    assert s["main_dataset"] == "/image" and s["provenance"]["parameters"] == {"algorithm": "rd"}
    assert {d["path"]: d["units"] for d in s["datasets"]} == {"/image": "1", "/range_m": "m", "/azimuth_time": "s"}
    assert s["time_spans"] == {"/azimuth_time": {"start_utc": "2002-06-16T15:41:10.000000Z",
                                                 "stop_utc": "2002-06-16T15:41:15.500000Z", "span_s": 5.5}}
    human = cli("info", tmp_path / "s.h5")
    assert "widget product" in human.stdout and "/range_m: float64 [34] [m]" in human.stdout


def test_info_refuses_non_products(cli, tmp_path):
    p = tmp_path / "x.txt"
    p.write_text("hello")
    r = cli("info", p)
    assert r.exit_code != 0 and r.stderr.startswith("sarcli: error: ") and len(r.stderr.splitlines()) == 1
    r = cli("info", tmp_path / "missing.h5")
    assert r.exit_code != 0 and "no such file" in r.stderr
