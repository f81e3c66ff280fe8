"""``sarcli simulate --format s1-l0``: a simulated scene written as Level-0 packets, ingested and focused,
puts its targets where the same scene written as HDF5 puts them (FDBAQ quantization and the 2^-16 s packet
datation are the only differences)."""

from __future__ import annotations

import datetime as dt
import json
import re
from pathlib import Path

import numpy as np
import pytest

from sarcli.io.sentinel1.constants import F_REF_HZ
from sarcli.model.constants import C_LIGHT

SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "s1_stripmap.toml"


def _utc(s: str) -> dt.datetime:
    return dt.datetime.fromisoformat(s.rstrip("Z"))


@pytest.mark.slow
def test_level0_scene_focuses_like_the_hdf5_scene(cli, tmp_path):
    from sarcli.io.slc import read_slc

    r = cli("simulate", SAMPLE, "--format", "s1-l0", "-o", tmp_path / "s1.dat")
    assert r.exit_code == 0, r.stderr
    assert re.search(r"in \d+\.\d\d s \(\d+\.\d\d s simulating, \d+\.\d\d s writing the s1-l0 packets\)", r.stderr)
    assert cli("simulate", SAMPLE, "-o", tmp_path / "sim.h5").exit_code == 0
    r = cli("ingest", tmp_path / "s1.dat", "-o", tmp_path / "l0.h5")
    assert r.exit_code == 0, r.stderr
    for name in ("sim", "l0"):
        r = cli("focus", tmp_path / f"{name}.h5", "-o", tmp_path / f"{name}_slc.h5")
        assert r.exit_code == 0, r.stderr
    r = cli("quality", tmp_path / "sim_slc.h5", "--json")
    assert r.exit_code == 0, r.stderr
    ref = json.loads(r.stdout)
    a, b = read_slc(tmp_path / "sim_slc.h5", load_image=False), read_slc(tmp_path / "l0_slc.h5", load_image=False)
    shift = (_utc(a.epoch_utc) - _utc(b.epoch_utc)).total_seconds()  # the Level-0 epoch is the first line's
    dr = float(a.slant_range[1] - a.slant_range[0])
    at = [f"{m['azimuth_time_s'] - m['position_error_azimuth_px'] / a.prf_hz + shift:.9f},"
          f"{m['range_m'] - m['position_error_range_px'] * dr:.6f}" for m in ref]  # the truth, in l0's epoch
    r = cli("quality", tmp_path / "l0_slc.h5", "--json", *[x for p in at for x in ("--at", p)])
    assert r.exit_code == 0, r.stderr
    got = json.loads(r.stdout)
    for m, g in zip(ref, got, strict=True):
        # the Level-0 peak vs the HDF5 scene's peak: azimuth, the datation is quantized to 2^-16 s (0.026
        # line at 1700 Hz) but the lines sit on the PRI-counter grid with a fitted offset (error ~ 0.026 /
        # sqrt(12 x 1024) line); the peak interpolation itself is good to ~0.01-0.02 px at 10 dB SNR (the
        # sample scene's window start, PRI, pulse length and ramp rate are on their packet code grids)
        assert abs(m["position_error_azimuth_px"]) < 0.02 and abs(m["position_error_range_px"]) < 0.02
        assert abs(g["azimuth_time_s"] - shift - m["azimuth_time_s"]) * a.prf_hz < 0.02
        # range: the packets code the chirp's start frequency in steps of f_ref / 2^14 (2.29 kHz), so the
        # replica's centre frequency may differ from the simulated chirp's (0) by half a step, which the
        # matched filter turns into a delay of df / K: 1.07 ns, 0.16 m, 0.071 sample here
        df = 0.5 * F_REF_HZ / 2**14
        bound = 0.02 + df / abs(a.radar.chirp_rate_hz_per_s) * C_LIGHT / 2 / dr
        assert abs(g["range_m"] - m["range_m"]) / dr < bound
        assert g["irw_range_m"] == pytest.approx(m["irw_range_m"], rel=0.02)
        assert g["irw_azimuth_m"] == pytest.approx(m["irw_azimuth_m"], rel=0.02)
    assert np.isfinite([g["pslr_range_db"] for g in got]).all()
