"""``sarcli info``: an unquantized raw product says so (not "0 bit"); SLC and GB-SAR scan products get
their key parameters (shape, spacings, algorithm, time span; polarizations, stops, sweep, status)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from sarcli.io.raw import write_raw
from tests.gbsar.test_cli import SCENE as GBSAR_SCENE

C = 299792458.0
FOCUS_SCENE = Path(__file__).resolve().parents[1] / "focus" / "scenes" / "batch.toml"


def test_unquantized_raw_says_not_quantized(cli, make_raw, tmp_path):
    raw = make_raw(n_lines=20)
    raw.radar = dataclasses.replace(raw.radar, quantization_bits=0)
    raw.echo = raw.echo.astype(np.complex64) * np.float32(0.3)
    write_raw(tmp_path / "r.h5", raw)
    human = cli("info", tmp_path / "r.h5").stdout
    assert "not quantized" in human and "0 bit" not in human
    write_raw(tmp_path / "q.h5", make_raw(n_lines=20))
    assert "4-bit quantized" in cli("info", tmp_path / "q.h5").stdout


def test_slc_summary_has_key_parameters(cli, tmp_path):
    raw, slc = tmp_path / "raw.h5", tmp_path / "slc.h5"
    assert cli("simulate", FOCUS_SCENE, "-o", raw).exit_code == 0
    assert cli("focus", raw, "-o", slc, "--fdc", "-6558", "--fr", "-1781").exit_code == 0
    s = json.loads(cli("info", slc, "--json").stdout)
    assert s["shape"] == [512, 300] and s["main_dataset"] == "/image" and s["algorithm"] == "rd"
    # slant-range pixel c / (2 fs) of the scene's 32.317075 MHz ADC
    assert s["range_spacing_m"] == pytest.approx(C / (2 * 32317075.0), rel=1e-9)
    assert 4.0 < s["azimuth_spacing_m"] < 7.0  # ~ V_ground / PRF = 6.6e3 / 1257
    assert s["azimuth_span_s"] == pytest.approx(511 / 1256.9846363282768, rel=1e-6)
    assert s["last_range_m"] - s["first_range_m"] == pytest.approx(299 * C / (2 * 32317075.0), rel=1e-9)
    # 512 lines at 1257 Hz are shorter than the 15 m antenna's aperture: no line has the full aperture
    assert s["first_full_line"] > s["last_full_line"] and "no line has the full aperture" in cli("info", slc).stdout
    human = cli("info", slc).stdout
    assert "512 lines x 300 samples, algorithm rd, spacing range 4.638 m" in human
    assert "zero-Doppler time 2002-06-16T" in human


def test_scan_summary_has_key_parameters(cli, tmp_path):
    toml = tmp_path / "g.toml"
    toml.write_text(GBSAR_SCENE.format(seed=1, minute=0, extra=""))
    assert cli("gbsar", "simulate", toml, "-o", tmp_path / "scan.h5").exit_code == 0
    s = json.loads(cli("info", tmp_path / "scan.h5", "--json").stdout)
    assert s["polarizations"] == ["VV", "HH"] and s["status"] == "simulated"
    assert s["n_stops_complete"] == s["n_stops_planned"] == 21  # 1 m rail, 0.05 m step
    assert s["n_frequencies"] == 201
    assert s["frequency_start_hz"] == pytest.approx(5.2e9) and s["frequency_stop_hz"] == pytest.approx(5.4e9)
    assert s["frequency_step_hz"] == pytest.approx(1e6)
    assert s["rail_start_m"] == pytest.approx(-0.5) and s["rail_stop_m"] == pytest.approx(0.5)
    human = cli("info", tmp_path / "scan.h5").stdout
    assert "status simulated: 21 of 21 stops, polarizations VV, HH" in human
    assert "sweep 5.2 .. 5.4 GHz, 201 points, step 1 MHz" in human
