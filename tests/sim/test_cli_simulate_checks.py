"""`sarcli simulate`: output folder and CEOS representability are checked BEFORE simulating (one stderr
line, nothing left behind), and the CEOS summary lists every file written."""

from __future__ import annotations

import json
from pathlib import Path

SCENE = Path(__file__).resolve().parents[1] / "focus" / "scenes" / "batch.toml"


def _one_line_error(r, needle: str) -> None:
    # one line only: the "simulating ..." line would show that the check came after the work
    assert r.exit_code != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: ") and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr + r.stdout


def test_missing_output_folder_refused_before_simulating(cli, tmp_path):
    for fmt in ("hdf5", "ceos"):
        r = cli("simulate", SCENE, "--format", fmt, "-o", tmp_path / "nope" / "dir" / "x.h5")
        _one_line_error(r, "does not exist")
    assert not (tmp_path / "nope").exists()


def test_two_channel_scene_refused_for_ceos_before_simulating(cli, tmp_path):
    scene = tmp_path / "two.toml"
    text = SCENE.read_text().replace('"quantization"]', '"quantization", "second_channel"]', 1)
    assert "second_channel" in text
    scene.write_text(text + "\n[second_channel]\nreceiver_offset_m = 2.0\n")
    r = cli("simulate", scene, "--format", "ceos", "-o", tmp_path / "ceos")
    _one_line_error(r, "one receive channel")
    assert not (tmp_path / "ceos").exists()  # no empty folder left behind
    # an ADC rate Radarsat-1 does not have is also known from the scene alone
    scene.write_text(SCENE.read_text().replace("range_sampling_rate_hz = 32317075.0",
                                               "range_sampling_rate_hz = 30000000.0", 1))
    _one_line_error(cli("simulate", scene, "--format", "ceos", "-o", tmp_path / "ceos"), "ADC rate")
    assert not (tmp_path / "ceos").exists()


def test_ceos_summary_lists_every_file(cli, tmp_path):
    out = tmp_path / "ceos"
    r = cli("simulate", SCENE, "--format", "ceos", "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    listed = json.loads(r.stdout)["output"]
    assert sorted(Path(p).name for p in listed) == sorted(p.name for p in out.iterdir()) == [
        "DAT_01.001", "LEA_01.001", "TRA_01.001", "VDF_DAT.001"]
    assert all(p in r.stderr for p in listed)
