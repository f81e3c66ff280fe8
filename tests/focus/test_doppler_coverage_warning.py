"""The Doppler coverage warning of the RD focuser: a model estimated on the scene itself (its range blocks
of 128 samples leave a partial block of 24 of the ALOS cut's 2200 samples) covers the scene; a scene
reaching more than one block spacing past the outer block centre's half-spacing is extrapolated, and said;
each warning of focus is printed once."""

from __future__ import annotations

import numpy as np

from sarcli.focus.rda import _coverage_warnings


class _Model:
    def __init__(self, ranges_m, times_s):
        self.blocks = {"range_m": np.asarray(ranges_m, float), "azimuth_time_s": np.asarray(times_s, float)}


def test_the_partial_edge_block_is_covered():
    dr = 4.68  # m per range sample (ALOS: fs 32 MHz)
    r = 850e3 + dr * np.arange(2200)
    t = np.arange(1000) / 2160.0
    centres = 850e3 + dr * (64 + 128 * np.arange(17))  # 17 whole blocks of 128: the last 24 samples not estimated
    m = _Model(np.tile(centres, 1), np.full(17, t.mean()))
    assert _coverage_warnings(m, r, t) == []
    far = 850e3 + dr * np.arange(2200 + 2 * 128)  # two blocks beyond the last estimated one: extrapolated
    out = _coverage_warnings(m, far, t)
    assert len(out) == 1 and "ranges" in out[0] and "extrapolating" in out[0]


def test_each_focus_warning_is_printed_once(cli, tmp_path):
    from pathlib import Path

    scene = Path(__file__).parents[1] / "fuzz" / "scenes" / "tiny_rs1.toml"  # 256 lines, a 708-line aperture
    assert cli("simulate", scene, "-o", tmp_path / "raw.h5").exit_code == 0
    r = cli("focus", tmp_path / "raw.h5", "--fdc", "-6590", "--fr", "-1787", "-o", tmp_path / "slc.h5")
    assert r.exit_code == 0, r.stderr
    assert r.stderr.count("shorter than the synthetic aperture") == 1, r.stderr
