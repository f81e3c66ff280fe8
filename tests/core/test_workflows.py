"""The workflow layer of ingest, info, simulate, orbit, ati, optical and design: every step registered with a
Config loadable from a TOML table, products recording the caller's provenance (not sys.argv), and no
workflow that writes accepting an output that is one of its inputs (refused before any work, input
unchanged)."""

from __future__ import annotations

import dataclasses
import json
import tomllib
from pathlib import Path

import h5py
import pytest

from sarcli.config import from_mapping
from sarcli.errors import ConfigError
from sarcli.io.h5common import sha256_file
from sarcli.io.provenance import Provenance
from sarcli.workflows import WORKFLOWS

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "focus" / "scenes" / "batch.toml"
MINE = ("ingest", "info", "simulate", "orbit_info", "orbit_interpolate", "orbit_accuracy", "ati_detect",
        "ati_estimate", "ati_compensate", "ati_montecarlo", "optical_compare", "design", "run")

TABLES = """
[ingest]
sources = ["scene"]
output = "raw.h5"
options = { missing = "repeat", max_gap = 10 }
[info]
sources = ["raw.h5"]
[simulate]
scene = "s.toml"
output = "raw.h5"
seed = 3
[orbit_info]
raw = "raw.h5"
[orbit_interpolate]
raw = "raw.h5"
times = [0.0, "2002-06-16T15:41:00Z"]
frame = "ECEF"
[orbit_accuracy]
timing = false
[ati_detect]
raw = "raw.h5"
pfa = 1e-5
[ati_estimate]
raw = "raw.h5"
route = "nonlinear"
[ati_compensate]
raw = "raw.h5"
output = "comp.h5"
method = "quadratic"
[ati_montecarlo]
scene = "s.toml"
snr = [10, 20]
[optical_compare]
raw = "raw.h5"
quick = true
[design]
source = "d.toml"
[run]
steps = "steps.toml"
"""


def test_every_step_is_registered_with_a_config_from_its_toml_table():
    doc = tomllib.loads(TABLES)
    assert set(MINE) <= set(WORKFLOWS.names())
    for name in MINE:
        module = WORKFLOWS.get(name)
        cfg = from_mapping(module.Config, doc[name], name)
        assert dataclasses.is_dataclass(cfg)
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(cfg, dataclasses.fields(cfg)[0].name, None)
    cfg = from_mapping(WORKFLOWS.get("orbit_interpolate").Config, doc["orbit_interpolate"])
    assert cfg.frame == "ecef" and cfg.times == (0.0, "2002-06-16T15:41:00Z")
    assert from_mapping(WORKFLOWS.get("ati_montecarlo").Config, doc["ati_montecarlo"]).snr == (10.0, 20.0)


@pytest.mark.parametrize("name, table, needle", [
    ("ati_estimate", {"raw": "r.h5", "route": "magic"}, "route 'magic': choose one of seed, exact, nonlinear"),
    ("ati_detect", {"raw": "r.h5", "pfa": 0.5}, "pfa must be in (0, 0.1)"),
    ("ati_montecarlo", {"scene": "s.toml", "snr": "5:1:1"}, "snr '5:1:1': expected start:stop:step"),
    ("simulate", {"scene": "s.toml", "output": "o.h5", "format": "tiff"}, "format: 'tiff' is not one of"),
    ("orbit_interpolate", {"raw": "r.h5", "times": "0", "frame": "j2000"}, "frame must be native, eci or ecef"),
    ("optical_compare", {"raw": "r.h5", "magnification": "huge"}, "magnification must be 'carrier' or 'fit_aod'"),
    ("ingest", {"sources": [], "output": "o.h5"}, "give LEADER DATA"),
])
def test_configs_refuse_bad_values_before_any_work(name, table, needle):
    with pytest.raises(ConfigError) as ei:
        from_mapping(WORKFLOWS.get(name).Config, table, name)
    assert needle in str(ei.value)


def test_products_record_the_callers_provenance(tmp_path):
    sim = WORKFLOWS.get("simulate")
    out = tmp_path / "raw.h5"
    report = sim.run(sim.Config(scene=SCENE, output=out), provenance=Provenance("dask batch task 17"))
    assert report.output == [str(out)]
    with h5py.File(out) as f:
        assert f.attrs["command_line"] == "dask batch task 17"
        params = json.loads(f.attrs["parameters"])
    assert params["workflow"] == "simulate" and params["config"] == {"scene": str(SCENE), "format": "hdf5",
                                                                       "compression": "auto"}
    calls = []
    report = sim.run(sim.Config(scene=SCENE, output=tmp_path / "b.h5", seed=5),
                     progress=lambda label, done, total: calls.append((label, done, total)))
    assert calls[-1][0] == "simulating" and calls[-1][1] == calls[-1][2] and report.seed == 5


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A raw product and a CEOS scene folder of the small batch scene."""
    from tests.conftest import run_cli

    d = tmp_path_factory.mktemp("guard")
    assert run_cli("simulate", SCENE, "-o", d / "raw.h5").exit_code == 0
    assert run_cli("simulate", SCENE, "--format", "ceos", "-o", d / "ceos").exit_code == 0
    return d


@pytest.mark.parametrize("args", [
    ("simulate", "{scene}", "-o", "{scene}"),
    ("ingest", "{ceos}", "-o", "{ceos}/LEA_01.001"),
    ("ingest", "{ceos}/LEA_01.001", "{ceos}/DAT_01.001", "-o", "{ceos}/DAT_01.001"),
    ("orbit", "interpolate", "{raw}", "-t", "0", "--csv", "{raw}"),
    ("ati", "detect", "{raw}", "-o", "{raw}"),
    ("ati", "estimate", "{raw}", "-o", "{raw}"),
    ("ati", "compensate", "{raw}", "-o", "{raw}"),
    ("ati", "montecarlo", "--scene", "{scene}", "--plot", "{scene}"),
    ("optical", "compare", "{raw}", "--plot", "{raw}"),
])
def test_an_output_that_is_an_input_is_refused_before_any_work(cli, tmp_path, made, args):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.read_text())
    names = {"scene": scene, "raw": made / "raw.h5", "ceos": made / "ceos"}
    args = [a.format(**names) for a in args]
    inputs = [scene, made / "raw.h5", *sorted((made / "ceos").iterdir())]
    before = [sha256_file(p) for p in inputs]
    r = cli(*args)
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 2 and len(lines) == 1 and "refusing to overwrite an input" in lines[0], r.stderr
    assert [sha256_file(p) for p in inputs] == before

