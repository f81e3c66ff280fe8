"""``sarcli batch`` in this process (--workers 0): three scenes (two raw products, a CEOS folder) through
ingest -> doppler -> focus + GeoTIFF + quicklook; a bad input fails alone and is listed; unrelated entries
are ignored; provenance is each step's own command line; make's up-to-date rule; refusals."""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import h5py
import pytest

#: longer than its synthetic aperture, so that the GeoTIFFs hold fully focused lines (an image without a valid
#: pixel is refused)
SCENE = Path(__file__).parents[1] / "focus" / "scenes" / "batch_long.toml"


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    from tests.conftest import run_cli

    inp = tmp_path_factory.mktemp("batch") / "in"
    inp.mkdir()
    assert run_cli("simulate", SCENE, "-o", inp / "a.h5").exit_code == 0
    shutil.copy(inp / "a.h5", inp / "b.h5")
    assert run_cli("simulate", SCENE, "--format", "ceos", "-o", inp / "c").exit_code == 0
    return inp


@pytest.mark.slow
def test_batch_here(cli, scenes, tmp_path):
    inp = tmp_path / "in"
    shutil.copytree(scenes, inp)
    (inp / "broken.h5").write_bytes(b"not an HDF5 file")
    (inp / "notes.txt").write_text("field notes")
    (inp / ".a.h5.x1y2.tmp").write_bytes(b"a half-written product of another run")
    out = tmp_path / "out"
    r = cli("batch", inp, "-o", out, "--workers", "0", "--json")
    assert r.exit_code == 1, r.stderr  # something failed
    rep = json.loads(r.stdout)
    assert [s["scene"] for s in rep["scenes"]] == ["a", "b", "c"]
    assert [s["steps"] for s in rep["scenes"]] == [{"doppler": "done", "focus": "done"}] * 2 + [
        {"ingest": "done", "doppler": "done", "focus": "done"}]
    assert rep["failures"] == [{"scene": "broken", "step": "input", "error": f"{inp / 'broken.h5'}: neither a sarcli "
                                "raw product nor a file a sensor reader recognises"}]
    assert rep["ignored"] == [{"entry": "notes.txt", "why": "no sensor reader recognises it"}]
    assert "failed:" in r.stderr and "broken" in r.stderr
    for n in "abc":
        for suffix in (".doppler.h5", ".slc.h5", ".tif", ".png", ".json"):
            assert (out / f"{n}{suffix}").stat().st_size > 0, (n, suffix)
    with h5py.File(out / "c.slc.h5") as f:  # provenance: the step's own command line, not sys.argv
        assert f.attrs["command_line"] == (f"sarcli focus {out / 'c.raw.h5'} --doppler {out / 'c.doppler.h5'} -o "
                                           f"{out / 'c.slc.h5'} --geotiff {out / 'c.tif'} --quicklook {out / 'c.png'} "
                                           f"(sarcli batch {inp} -o {out})")
    with h5py.File(out / "c.raw.h5") as f:
        assert f.attrs["command_line"].startswith(f"sarcli ingest {inp / 'c'} -o {out / 'c.raw.h5'}")
    doc = json.loads((out / "c.json").read_text())
    assert [s["step"] for s in doc["steps"]] == ["ingest", "doppler", "focus"]
    assert doc["steps"][2]["report"]["products"]["geotiff"] == str(out / "c.tif")
    assert set(doc["steps"][2]["report"]["warnings"]) <= set(doc["steps"][2]["warnings"])  # focus's own, listed

    # up to date: nothing runs; an input made newer rebuilds its own chain only
    (inp / "broken.h5").unlink()
    stamps = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    r = cli("batch", inp, "-o", out, "--workers", "0", "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["counts"] == {"done": 0, "failed": 0, "skipped": 0, "up_to_date": 7}
    assert {p.name: p.stat().st_mtime_ns for p in out.iterdir()} == stamps
    time.sleep(0.01)
    (inp / "b.h5").touch()
    r = cli("batch", inp, "-o", out, "--workers", "0")
    assert r.exit_code == 0, r.stderr
    changed = {p.name for p in out.iterdir() if p.stat().st_mtime_ns != stamps.get(p.name)}
    assert changed == {"b.doppler.h5", "b.slc.h5", "b.tif", "b.qml", "b.png", "b.json"}


def test_a_failing_step_skips_the_rest_of_its_scene_only(cli, scenes, tmp_path):
    """A raw product the focus refuses (a LOCAL orbit cannot make the GeoTIFF asked for with geotiff =
    always) fails its focus step; the other scenes are done."""
    from sarcli.workflows.batch import Config, run

    inp = tmp_path / "in"
    inp.mkdir()
    shutil.copy(scenes / "a.h5", inp / "a.h5")
    shutil.copy(scenes / "a.h5", inp / "flat.h5")
    with h5py.File(inp / "flat.h5", "r+") as f:
        f["orbit"].attrs["frame"] = "LOCAL"
    rep = run(Config(input=inp, output=tmp_path / "out", workers=0, geotiff="always"))
    assert [(s["scene"], s["steps"]) for s in rep.scenes] == [
        ("a", {"doppler": "done", "focus": "done"}), ("flat", {"doppler": "done", "focus": "failed"})]
    assert rep.failures[0]["scene"] == "flat" and "GeoTIFF needs an Earth orbit" in rep.failures[0]["error"]


@pytest.mark.parametrize("args, needle", [
    (["--workers", "0", "--scheduler", "tcp://127.0.0.1:8786"], "drop --scheduler"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"], "--workers sizes a local cluster"),
    (["--scheduler", "127.0.0.1:8786"], "not a Dask scheduler address"),
    (["--workers", "0", "--report", "r.html"], "needs a cluster"),
    (["--workers", "-1"], "--workers must be at least 1"),
    (["--threads-per-worker", "0"], "--threads-per-worker must be at least 1"),
    (["--focus", "output=x.h5"], "set by the batch"),
    (["--focus", "looks=3"], "looks"),
])
def test_bad_options_are_one_line(cli, tmp_path, args, needle):
    (tmp_path / "in").mkdir()
    r = cli("batch", tmp_path / "in", "-o", tmp_path / "out", *args)
    assert r.exit_code == 2 and needle in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not (tmp_path / "out").exists()


def test_folders_are_checked_before_any_work(cli, tmp_path):
    r = cli("batch", tmp_path / "missing", "-o", tmp_path / "out", "--workers", "0")
    assert r.exit_code == 2 and "does not exist" in r.stderr
    (tmp_path / "in").mkdir()
    r = cli("batch", tmp_path / "in", "-o", tmp_path / "in", "--workers", "0")
    assert r.exit_code == 2 and "is the input folder" in r.stderr
    r = cli("batch", tmp_path / "in", "-o", tmp_path / "out", "--workers", "0")
    assert r.exit_code == 2 and "no raw products or sensor inputs" in r.stderr


def test_batch_is_a_workflow_with_a_toml_table():
    import tomllib

    from sarcli.config import from_mapping
    from sarcli.workflows import WORKFLOWS

    doc = tomllib.loads('[batch]\ninput = "scenes"\noutput = "products"\nworkers = 2\n'
                        '[batch.focus]\nlooks_az = 4\noptions = { block_lines = 2048 }\n')
    cfg = from_mapping(WORKFLOWS.get("batch").Config, doc["batch"], "batch")
    assert cfg.workers == 2 and cfg.focus == {"looks_az": 4, "options": {"block_lines": 2048}}
    assert cfg.cluster().describe() == "local cluster of 2 process(es) x 1 thread(s)"


def test_the_batch_command_module_loads_no_heavy_package():
    """`sarcli batch --help` stays fast: the command imports neither Dask nor arrays nor files libraries."""
    import subprocess
    import sys

    code = ("import sys, sarcli.cli.commands.batch; print(sorted(set(m.split('.')[0] for m in sys.modules) & "
            "{'numpy', 'h5py', 'scipy', 'numba', 'rasterio', 'matplotlib', 'dask', 'distributed'}))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "[]", r.stdout


@pytest.mark.slow
def test_a_scene_without_an_orbit_is_focused_without_its_geotiff(cli, scenes, tmp_path):
    """--geotiff auto (default): a scene without an Earth orbit gets its SLC and quicklook, no GeoTIFF, and a
    warning in its report; --geotiff never: no GeoTIFF for any scene; always: the orbit-less scene fails."""
    inp = tmp_path / "in"
    inp.mkdir()
    shutil.copy(scenes / "a.h5", inp / "bare.h5")
    with h5py.File(inp / "bare.h5", "r+") as f:
        for name in ("orbit", "orbit_ecef", "attitude"):
            del f[name]
    out = tmp_path / "out"
    r = cli("batch", inp, "-o", out, "--workers", "0", "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["scenes"][0]["steps"] == {"doppler": "done", "focus": "done"}
    assert (out / "bare.slc.h5").is_file() and (out / "bare.png").is_file() and not (out / "bare.tif").exists()
    focus = json.loads((out / "bare.json").read_text())["steps"][1]
    assert any("no GeoTIFF" in w and "no Earth orbit" in w for w in focus["warnings"]), focus["warnings"]
    assert "--geotiff" not in focus["report"]["products"] and "geotiff" not in focus["report"]["products"]
    r = cli("batch", inp, "-o", tmp_path / "always", "--workers", "0", "--geotiff", "always")
    assert r.exit_code == 1 and "GeoTIFF needs an Earth orbit" in r.stderr
    r = cli("batch", inp, "-o", tmp_path / "o", "--workers", "0", "--focus", "geotiff=null")
    assert r.exit_code == 2 and "--geotiff auto|always|never" in r.stderr


def test_matlab_blocks_are_scenes_in_folders_of_their_own(tmp_path):
    """A MATLAB block is two files (block and run parameters): a folder holding both is one scene (read by
    matlab-cw); loose MAT files are listed as ignored, saying how to make them a scene, and a folder with
    nothing else names what it ignored."""
    import numpy as np
    import scipy.io

    from sarcli.errors import ConfigError
    from sarcli.workflows.batch import Config, discover, run

    inp = tmp_path / "in"
    (inp / "blk").mkdir(parents=True)
    levels = 2 * np.random.default_rng(1).integers(-8, 8, size=(2, 32, 64)) + 1
    scipy.io.savemat(inp / "blk" / "block.mat", {"data": levels[0] + 1j * levels[1]})
    scipy.io.savemat(inp / "blk" / "run_params.mat", {"f0": 5.3e9, "Fr": 32.317e6, "Kr": 0.72135e12, "Tr": 41.75e-6,
                                                      "PRF": 1256.98, "R0": 988647.462, "c": 2.9979e8})
    scenes, ignored, bad = discover(inp)
    assert [(s.name, s.reader) for s in scenes] == [("blk", "matlab-cw")] and not ignored and not bad
    loose = tmp_path / "loose"
    loose.mkdir()
    for name in ("block.mat", "run_params.mat"):
        shutil.copy(inp / "blk" / name, loose / name)
    with pytest.raises(ConfigError) as e:
        run(Config(input=loose, output=tmp_path / "out", workers=0))
    msg = str(e.value)
    assert "no raw products or sensor inputs" in msg and "ignored: block.mat (" in msg and "run_params.mat (" in msg
    assert "a folder of its own" in msg


def test_a_matlab_block_folder_ingests(cli, tmp_path):
    """`sarcli ingest FOLDER` reads a folder holding a block and its run parameters, as --matlab/--params do."""
    import numpy as np
    import scipy.io

    levels = 2 * np.random.default_rng(1).integers(-8, 8, size=(2, 32, 64)) + 1
    (tmp_path / "blk").mkdir()
    scipy.io.savemat(tmp_path / "blk" / "block.mat", {"data": levels[0] + 1j * levels[1]})
    scipy.io.savemat(tmp_path / "blk" / "p.mat", {"f0": 5.3e9, "Fr": 32.317e6, "Kr": 0.72135e12, "Tr": 41.75e-6,
                                                  "PRF": 1256.98, "R0": 988647.462, "c": 2.9979e8})
    r = cli("ingest", tmp_path / "blk", "-o", tmp_path / "a.h5", "--json")
    assert r.exit_code == 0, r.stderr
    r2 = cli("ingest", "--matlab", tmp_path / "blk" / "block.mat", "--params", tmp_path / "blk" / "p.mat", "-o",
             tmp_path / "b.h5", "--json")
    with h5py.File(tmp_path / "a.h5") as a, h5py.File(tmp_path / "b.h5") as b:
        assert np.array_equal(a["echo"][...], b["echo"][...])
    assert json.loads(r.stdout)["first_range_m"] == json.loads(r2.stdout)["first_range_m"]


def test_a_steps_warnings_include_those_its_workflow_caught():
    """focus catches its focuser's warnings and lists them in its report: the scene's JSON lists them
    for the step too (each once), and the table says which scene has warnings."""
    from types import SimpleNamespace

    from sarcli.workflows.batch import BatchReport, _step_warnings

    o = SimpleNamespace(warnings=("raised while it ran", "both"), value={"warnings": ["both", "focus's own"]})
    assert _step_warnings(o) == ["raised while it ran", "both", "focus's own"]
    assert _step_warnings(SimpleNamespace(warnings=(), value=None)) == []
    rep = BatchReport(input="in", output="out", where="here", failures=[], ignored=[], wall_s=1.0,
                      counts={"done": 2, "failed": 0, "skipped": 0, "up_to_date": 0}, performance_report=None,
                      scenes=[{"scene": "a", "input": "in/a.h5", "steps": {"doppler": "done", "focus": "done"},
                               "warnings": {"focus": 2}, "report": "out/a.json"}])
    assert "a: 2 warning(s) in focus (see out/a.json)" in rep.lines()
