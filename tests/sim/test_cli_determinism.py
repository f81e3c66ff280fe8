"""`sarcli simulate` end to end: determinism, SOURCE_DATE_EPOCH byte-identity, JSON, CEOS refusal.

The simulate -> CEOS -> ingest bit-exact round trip is tested in tests/io/test_sim_ceos_roundtrip.py.
"""

from __future__ import annotations

import json

import numpy as np

from sarcli.io.raw import read_raw
from sarcli.sim.scene import parse_scene
from sarcli.sim.stripmap import simulate
from tests.sim.conftest import orbit_scene_text

CLUTTER = """
[[clutter]]
slant_range_m = 994000.0
range_extent_m = 200.0
azimuth_extent_m = 400.0
sigma0_db = -10.0
density_per_m2 = 0.01
"""
NOISE = "[noise]\nsnr_db = 5.0\n"


def _scene(seed):
    return parse_scene(orbit_scene_text(effects=("range_migration", "noise", "antenna_pattern"), seed=seed,
                                        targets=CLUTTER, extra=NOISE, n_lines=256), "d.toml")


def test_same_seed_same_echo_other_seed_differs():
    a, b, c = simulate(_scene(3)), simulate(_scene(3)), simulate(_scene(4))
    assert np.array_equal(a.echo, b.echo)
    assert not np.array_equal(a.echo, c.echo)


def test_source_date_epoch_gives_byte_identical_files(cli, tmp_path, monkeypatch):
    scene = tmp_path / "s.toml"
    scene.write_text(orbit_scene_text(effects=("range_migration", "noise", "chirp_replica"), extra=NOISE,
                                      n_lines=128))
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    paths = [tmp_path / "a.h5", tmp_path / "b.h5"]
    for p in paths:
        r = cli("simulate", scene, "-o", p)
        assert r.exit_code == 0, r.stderr
    assert paths[0].read_bytes() == paths[1].read_bytes()


def test_cli_json_and_product_contents(cli, tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(orbit_scene_text(effects=("range_migration", "earth_rotation"), n_lines=128))
    r = cli("simulate", scene, "-o", tmp_path / "raw.h5", "--json")
    assert r.exit_code == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["shape"] == [128, 400] and out["effects"] == ["range_migration", "earth_rotation"]
    # the whole time is reported, not only the simulation's: scene, simulation, writing the product
    assert out["total_time_s"] >= out["simulation_time_s"] + out["writing_time_s"] > 0
    assert out["writing_time_s"] > 0
    raw = read_raw(tmp_path / "raw.h5")
    assert raw.orbit.frame == "ECI" and raw.orbit.time.size == 15
    assert np.allclose(np.diff(raw.orbit.time), 480.0)
    assert abs(raw.orbit.time[7] - raw.azimuth_time.mean()) < 1e-6  # centred on the scene
    assert raw.truth["targets"].shape == (1,) and raw.truth["doppler_centroid_hz"].shape == (400,)
    assert "range_migration" in raw.truth["scene_toml"]


def test_ceos_export_refuses_unquantized_scene(cli, tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(orbit_scene_text(n_lines=64, n_samples=402))
    r = cli("simulate", scene, "--format", "ceos", "-o", tmp_path / "ceos")
    last = r.stderr.strip().splitlines()[-1]
    assert r.exit_code != 0 and last.startswith("sarcli: error:") and "quantiz" in last
    assert "Traceback" not in r.stderr


def test_cli_seed_override(cli, tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(orbit_scene_text(effects=("range_migration", "noise"), extra=NOISE, n_lines=64, seed=3))
    for name, extra in (("a.h5", ()), ("b.h5", ("--seed", "3")), ("c.h5", ("--seed", "4"))):
        assert cli("simulate", scene, "-o", tmp_path / name, *extra).exit_code == 0
    a, b, c = (read_raw(tmp_path / n) for n in ("a.h5", "b.h5", "c.h5"))
    assert np.array_equal(a.echo, b.echo) and not np.array_equal(a.echo, c.echo)
    assert int(c.truth["seed"]) == 4
