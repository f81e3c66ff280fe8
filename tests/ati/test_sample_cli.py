"""The documented sample works with the defaults: simulate -> `sarcli ati detect` finds its mover."""

from __future__ import annotations

import json
from pathlib import Path

SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "ati_paper.toml"


def test_documented_sample_detects_its_mover(cli, tmp_path):
    assert cli("simulate", SAMPLE, "-o", tmp_path / "raw2ch.h5").exit_code == 0
    r = cli("ati", "detect", tmp_path / "raw2ch.h5", "--json")
    assert r.exit_code == 0, r.stderr
    movers = json.loads(r.stdout)["candidates"]
    assert len(movers) == 1
