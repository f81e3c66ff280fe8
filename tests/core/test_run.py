"""``sarcli run STEPS.toml``: the steps of a file run in order, each table being its workflow's Config.

The pipeline tested here is simulate -> info -> orbit_info -> ingest (of a CEOS export) -> info: the
workflows on this branch (focus and doppler are other branches' workflows and run the same way)."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np

from sarcli.io.raw import read_raw

SCENE = Path(__file__).resolve().parents[2] / "tests" / "focus" / "scenes" / "batch.toml"

def _steps(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "steps.toml"
    p.write_text(text.replace("OUT", str(tmp_path)))
    return p


def test_a_small_pipeline_runs_in_file_order(cli, tmp_path):
    text = f"""
[simulate]
scene = "{SCENE}"
output = "OUT/ceos"
format = "ceos"

[ingest]
sources = ["OUT/ceos"]
output = "OUT/ingested.h5"
options = {{ missing = "repeat" }}

[info]
sources = ["OUT/ingested.h5"]

[orbit_info]
raw = "OUT/ingested.h5"
"""
    steps = _steps(tmp_path, text)
    r = cli("run", steps, "--json")
    assert r.exit_code == 0, r.stderr
    doc = json.loads(r.stdout)
    assert [s["step"] for s in doc["steps"]] == ["simulate", "ingest", "info", "orbit_info"]
    info = doc["steps"][2]["report"]
    assert info["product_type"] == "raw" and info["shape"] == [512, 300] and info["n_state_vectors"] == 15
    assert doc["steps"][1]["report"]["missing_policy"] == "repeat"
    assert doc["steps"][3]["report"]["n_vectors"] == 15
    with h5py.File(tmp_path / "ingested.h5") as f:
        assert f.attrs["command_line"].endswith(" [ingest]")  # the caller's command line and the step
        assert json.loads(f.attrs["parameters"])["config"]["options"] == {"missing": "repeat"}
    human = cli("run", steps.with_name("steps.toml"))
    assert human.exit_code == 0 and [ln for ln in human.stdout.splitlines() if ln.startswith("[")] == [
        "[simulate]", "[ingest]", "[info]", "[orbit_info]"]


def test_same_result_as_the_commands(cli, tmp_path):
    """A step does what its command does: the raw product equals `sarcli simulate`'s."""
    steps = _steps(tmp_path, f'[simulate]\nscene = "{SCENE}"\noutput = "OUT/a.h5"\n\n[[info]]\nsources = ["OUT/a.h5"]\n'
                             '\n[[info]]\nsources = ["OUT/a.h5"]\n')
    r = cli("run", steps, "--json")
    assert r.exit_code == 0, r.stderr
    assert [s["step"] for s in json.loads(r.stdout)["steps"]] == ["simulate", "info", "info"]
    assert cli("simulate", SCENE, "-o", tmp_path / "b.h5").exit_code == 0
    assert np.array_equal(read_raw(tmp_path / "a.h5").echo, read_raw(tmp_path / "b.h5").echo)


def _one_line(r, *needles):
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 2 and len(lines) == 1 and lines[0].startswith("sarcli: error: "), r.stderr
    for n in needles:
        assert n in lines[0], lines[0]


def test_unknown_step_option_or_value_is_one_line_and_nothing_runs(cli, tmp_path):
    base = f'[simulate]\nscene = "{SCENE}"\noutput = "OUT/raw.h5"\n'
    cases = [
        (base + "[focuss]\nraw = 'x'\n", "steps.toml: unknown step [focuss]; known steps: ati_compensate"),
        (base + "[info]\nsource = ['x']\n",
         "steps.toml: info: unknown option(s) source; known: format, options, sources"),
        (base + "[ati_detect]\nraw = 'x'\npfa = 2\n", "steps.toml: ati_detect: pfa must be in (0, 0.1), got 2.0"),
        (base + "[simulate_more]\n", "unknown step [simulate_more]"),
        ("verbose = true\n" + base, "steps.toml: verbose = True is not a step table"),
        (base + "[run]\nsteps = 'steps.toml'\n", "a [run] step (a steps file inside a steps file) is not allowed"),
        ("", "steps.toml: no step"),
        (base.replace("[simulate]", "[simulate"), "not valid TOML"),
        (base + "[orbit_interpolate]\nraw = 'x'\n", "steps.toml: orbit_interpolate: missing required option(s) times"),
    ]
    for text, needle in cases:
        _one_line(cli("run", _steps(tmp_path, text)), needle)
        assert not (tmp_path / "raw.h5").exists()  # checked before the first step ran
    _one_line(cli("run", tmp_path / "none.toml"), "none.toml: no such file")


def test_a_failing_step_names_itself(cli, tmp_path):
    text = f'[simulate]\nscene = "{SCENE}"\noutput = "OUT/raw.h5"\n\n[orbit_info]\nraw = "OUT/missing.h5"\n'
    r = cli("run", _steps(tmp_path, text))
    assert r.exit_code == 2 and r.stderr.strip().splitlines() == [
        f"sarcli: error: step [orbit_info]: {tmp_path / 'missing.h5'}: no such file"]
    assert (tmp_path / "raw.h5").is_file()  # the step before it ran


def test_simulate_then_doppler_then_info(cli, tmp_path):
    """A processing step from another area (doppler) runs from the same file; its product records the step."""
    text = (f'[simulate]\nscene = "{SCENE}"\noutput = "OUT/raw.h5"\n\n[doppler]\nraw = "OUT/raw.h5"\n'
            'output = "OUT/dop.h5"\noptions = { az_block = 512 }\n\n[info]\nsources = ["OUT/dop.h5"]\n')
    r = cli("run", _steps(tmp_path, text), "--json")
    assert r.exit_code == 0, r.stderr
    steps = json.loads(r.stdout)["steps"]
    assert [s["step"] for s in steps] == ["simulate", "doppler", "info"]
    assert steps[2]["report"]["product_type"] == "doppler"
    assert steps[2]["report"]["provenance"]["command_line"].endswith(" [doppler]")
