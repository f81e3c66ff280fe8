"""The ``doppler`` workflow: a configuration from a TOML table, ``run`` file to file with the caller's
provenance, the product recording the configuration, the guards that act before any work."""

from __future__ import annotations

import json
import tomllib

import pytest

from sarcli.config import from_mapping, to_mapping
from sarcli.errors import ConfigError
from sarcli.io.doppler_product import read_doppler
from sarcli.io.h5common import open_product, provenance
from sarcli.io.provenance import Provenance
from sarcli.io.raw import write_raw
from sarcli.workflows import WORKFLOWS
from sarcli.workflows import doppler as wf


@pytest.fixture(scope="module")
def raw_file(tmp_path_factory, clutter_raw):
    p = tmp_path_factory.mktemp("wf") / "raw.h5"
    write_raw(p, clutter_raw)
    return p


def test_run_from_a_toml_table(raw_file, tmp_path):
    text = f"""
[doppler]
raw = "{raw_file}"
output = "{tmp_path / 'doppler.h5'}"
plot = "{tmp_path / 'doppler.png'}"
height_m = 120.0
[doppler.options]
az_block = 256
rg_block = 96
fit_degree = [1, 1]
"""
    assert WORKFLOWS.get("doppler") is wf
    config = from_mapping(wf.Config, tomllib.loads(text)["doppler"], "steps.toml [doppler]")
    stages = []
    report = wf.run(config, Provenance("python: test_run_from_a_toml_table"),
                    lambda stage, done, total: stages.append((stage, done, total)))
    assert stages == [(s, i + 1, 5) for i, s in enumerate(("baseband centroid", "unwrap", "ambiguity", "fit",
                                                           "Doppler rate"))]
    m = read_doppler(config.output)
    assert m.parameters == json.loads(json.dumps(to_mapping(config)))  # the product records the configuration
    assert from_mapping(wf.Config, m.parameters) == config  # ... and can run it again
    with open_product(config.output, "doppler") as f:
        assert provenance(f)["command_line"] == "python: test_run_from_a_toml_table"
    d = report.to_dict()
    assert d["output"] == str(config.output) and d["warnings"] == [] and d["n_blocks"] == len(d["blocks"]) == 8
    assert set(d["blocks"][0]) == set(wf.JSON_BLOCK_KEYS)
    assert d["fdc_hz"] == pytest.approx(m.summary.fdc_hz, abs=0) and d["ambiguity_resolved"] is True
    assert report.lines()[0].startswith("fdc ") and report.lines()[-1] == f"wrote {config.plot}"
    assert config.plot.read_bytes()[:4] == b"\x89PNG"


def test_guards_act_before_any_work(raw_file, tmp_path):
    before = raw_file.read_bytes()
    with pytest.raises(ConfigError, match="is the input"):
        wf.run(wf.Config(raw=raw_file, output=raw_file))
    link = tmp_path / "same.h5"
    link.hardlink_to(raw_file)
    with pytest.raises(ConfigError, match="is the input"):
        wf.run(wf.Config(raw=raw_file, plot=link))
    assert raw_file.read_bytes() == before
    for h in (1e6, -5000.0, float("nan")):
        with pytest.raises(ConfigError, match="terrain height"):
            wf.Config(raw=raw_file, height_m=h)
    with pytest.raises(ConfigError, match=r"unknown option\(s\) az_blocks; known: ambiguity"):
        from_mapping(wf.Config, {"raw": "r.h5", "options": {"az_blocks": 3}})
    with pytest.raises(ConfigError, match="'sideways' is not one of"):
        from_mapping(wf.Config, {"raw": "r.h5", "options": {"fdc_model": "sideways"}})


@pytest.mark.parametrize("args,match", [
    (("--ambiguity", "maybe"), "'maybe' is not one of 'auto', 'orbit', 'data', 'none'"),
    (("--az-block", "1"), "block size must be at least 2 lines"),
    (("--fit-degree", "7,1"), "fit_degree must be two degrees"),
    (("--hermite-nodes", "1"), "at least 2 nodes"),
    (("--height", "inf"), "terrain height inf m"),
])
def test_cli_option_errors_are_one_line(cli, raw_file, args, match):
    r = cli("doppler", raw_file, *args)
    assert r.exit_code == 2 and r.stderr.startswith("sarcli: error:") and len(r.stderr.strip().splitlines()) == 1
    assert match in r.stderr, r.stderr
