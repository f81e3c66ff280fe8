"""A resolved ambiguity of confidence below AMBIGUITY_CONFIDENCE_LEVEL (0.90) is used with a
warning that gives the confidence and what the user can do; none at or above it, none when unresolved
(focus refuses those), and focus prints it."""

from __future__ import annotations

import dataclasses

import h5py
import pytest

from sarcli.io.doppler_product import read_doppler
from sarcli.model.doppler_summary import AMBIGUITY_CONFIDENCE_LEVEL, low_confidence_note


@pytest.mark.parametrize("conf, resolved, warned", [(0.52, True, True), (0.64, True, True),
                                                    (AMBIGUITY_CONFIDENCE_LEVEL, True, False), (0.998, True, False),
                                                    (0.52, False, False)])
def test_low_confidence_note(conf, resolved, warned, doppler_product):
    s = dataclasses.replace(read_doppler(doppler_product).summary, ambiguity_confidence=conf,
                            ambiguity_resolved=resolved)
    note = low_confidence_note(s)
    assert (note is not None) == warned
    if warned:
        assert f"{conf:.2f}" in note and "--fdc" in note and "--accept-unresolved-ambiguity" in note


@pytest.fixture
def doppler_product(cli, tmp_path_factory):
    from pathlib import Path

    d = tmp_path_factory.mktemp("amb")
    scene = Path(__file__).parents[1] / "fuzz" / "scenes" / "tiny_rs1.toml"
    assert cli("simulate", scene, "-o", d / "raw.h5").exit_code == 0
    assert cli("doppler", d / "raw.h5", "-o", d / "dop.h5").exit_code == 0
    return d / "dop.h5"


def test_focus_warns_on_low_confidence(cli, doppler_product, tmp_path):
    import json

    low = tmp_path / "low.h5"
    low.write_bytes(doppler_product.read_bytes())
    with h5py.File(low, "r+") as f:
        s = json.loads(f.attrs["summary_json"])
        s["ambiguity_confidence"] = 0.58
        f.attrs["summary_json"] = json.dumps(s)
        f.attrs["ambiguity_confidence"] = 0.58
    raw = doppler_product.parent / "raw.h5"
    r = cli("focus", raw, "--doppler", low, "-o", tmp_path / "slc.h5")
    assert r.exit_code == 0, r.stderr
    assert r.stderr.count("confidence 0.58") == 1 and "--accept-unresolved-ambiguity" in r.stderr
    r = cli("focus", raw, "--doppler", doppler_product, "-o", tmp_path / "slc2.h5")
    assert r.exit_code == 0 and "confidence" not in r.stderr, r.stderr
