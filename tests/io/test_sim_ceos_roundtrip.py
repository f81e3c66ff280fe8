"""simulate -> CEOS -> ingest round trip through the CLI (the demo chain, on a shrunken rs1_point scene)."""

from __future__ import annotations

import dataclasses
import datetime as _dt
from pathlib import Path

import numpy as np
import pytest

from orbit.timeutil import parse_utc
from sarcli.io.raw import read_raw

SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "rs1_point.toml"


def _abs(p) -> np.ndarray:
    return (parse_utc(p.epoch_utc) - _dt.datetime(2002, 1, 1, tzinfo=_dt.UTC)).total_seconds() + p.azimuth_time


def test_simulate_ceos_ingest_roundtrip(cli, tmp_path):
    src = SAMPLE
    if not src.is_file():
        pytest.skip("sample scene not available")
    text = src.read_text().replace("n_lines = 2048", "n_lines = 128").replace("n_samples = 2400", "n_samples = 600")
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    assert cli("simulate", scene, "-o", tmp_path / "sim.h5").exit_code == 0
    r = cli("simulate", scene, "--format", "ceos", "-o", tmp_path / "ceos")
    assert r.exit_code == 0, r.stderr
    r = cli("ingest", tmp_path / "ceos", "-o", tmp_path / "ing.h5")
    assert r.exit_code == 0, r.stderr
    a, b = read_raw(tmp_path / "sim.h5"), read_raw(tmp_path / "ing.h5")
    assert a.shape == b.shape == (128, 600)
    assert np.array_equal(a.echo, b.echo)  # quantized samples bit for bit
    assert np.max(np.abs(_abs(a) - _abs(b))) <= 0.5e-6
    # CEOS RAW carries no antenna description or receiver noise level (radiometry): the reader states none
    not_in_ceos = ("antenna_length_m", "antenna_height_m", "antenna_look_angle_rad", "noise_power")
    assert all(getattr(b.radar, k) is None for k in not_in_ceos)
    for f in dataclasses.fields(a.radar):
        if f.name in not_in_ceos:
            continue
        x, y = getattr(a.radar, f.name), getattr(b.radar, f.name)
        assert (x == y) if not isinstance(x, float) else y == pytest.approx(x, rel=1e-12), f.name
    assert np.array_equal(a.agc_db, b.agc_db) and a.look_side == b.look_side
    assert b.orbit.frame == a.orbit.frame == "ECI" and np.max(np.abs(a.orbit.position - b.orbit.position)) < 1e-6
