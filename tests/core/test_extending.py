"""The recipes of docs/extending.md, executed as written: each code block is run, its plug-in is then used
through the CLI, and the result is checked against an independent expectation (numpy, theory)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from sarcli.doppler.estimators import ESTIMATORS
from sarcli.focus import FOCUSERS
from sarcli.io.readers import READERS

DOC = Path(__file__).resolve().parents[2] / "docs" / "extending.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(), re.S)


def _run(n: int) -> dict:
    """Execute recipe ``n`` as a module (dataclasses look their module up in sys.modules)."""
    import sys
    import types

    module = types.ModuleType(f"extending_recipe_{n + 1}")
    sys.modules[module.__name__] = module
    exec(compile(_blocks()[n], f"{DOC}:recipe{n + 1}", "exec"), module.__dict__)
    return module.__dict__


def test_the_manual_has_four_recipes():
    assert len(_blocks()) == 4
    assert [h for h in re.findall(r"(?m)^## (.*)$", DOC.read_text())] == [
        "1. A new Doppler centroid estimator", "2. A new focuser", "3. A new sensor reader",
        "4. Running a workflow on a Dask cluster"]


@pytest.fixture
def recipe():
    """Run recipe n of the manual; unregister whatever it registered afterwards."""
    before = {r: set(r.names()) for r in (ESTIMATORS, FOCUSERS, READERS)}
    yield _run
    for r, names in before.items():
        for name in set(r.names()) - names:
            r.unregister(name)


def test_recipe_estimator(recipe, cli, tmp_path):
    """The spectral-centroid estimator agrees with a plain lag-one correlation of the same echo: both are
    the phase of the same sum (the recipe's identity), so to float round-off."""
    from sarcli.io.raw import write_raw
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    recipe(0)
    raw = simulate(load_scene(Path(__file__).resolve().parents[1] / "doppler" / "scenes" / "rs1_clutter.toml"))
    write_raw(tmp_path / "raw.h5", raw)
    r = cli("doppler", tmp_path / "raw.h5", "--estimator", "spectral", "--json")
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    e = raw.calibrated().echo.astype(np.complex128)
    lag1 = np.sum(np.roll(e, -1, axis=0) * np.conj(e))  # circular, as the DFT identity
    expect = raw.radar.prf_hz * np.angle(lag1) / (2 * np.pi)
    assert d["fdc_method"] == "spectral" and d["fdc_baseband_hz"] == pytest.approx(expect, abs=1e-6)


def test_recipe_focuser(recipe, cli, tmp_path):
    """The range-only focuser compresses a point target to its closest-approach range sample (rect window:
    a sinc whose peak is at the target's delay), line by line, streamed in blocks."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    try:
        from focus.synth import C, scene
    finally:
        sys.path.pop(0)
    from sarcli.io.raw import write_raw
    from sarcli.io.slc import read_slc

    recipe(1)
    r0 = 850e3 + 200 * C / (2 * 24e6)  # on sample 200
    raw = scene([(r0, 0.2, 1.0)], n_lines=300, n_samples=400, fdc=0.0, replica=True)
    write_raw(tmp_path / "raw.h5", raw)
    r = cli("focus", tmp_path / "raw.h5", "-o", tmp_path / "rc.h5", "--algorithm", "range-only",
            "--fdc", "0", "--fr", "-2000", "--set", "block_lines=64")
    assert r.exit_code == 0, r.stderr
    img = read_slc(tmp_path / "rc.h5").image
    line = int(np.argmax(np.abs(img).max(axis=1)))
    rng = raw.slant_range()
    r_line = np.hypot(r0, 7000.0 * (raw.azimuth_time[line] - 0.2))  # the hyperbola at that line
    assert abs(rng[int(np.argmax(np.abs(img[line])))] - r_line) <= 0.5 * (rng[1] - rng[0])


def test_recipe_reader(recipe, cli, tmp_path):
    """The lab-sar reader is found by sniffing; the product holds exactly the samples written."""
    from sarcli.io.raw import read_raw

    recipe(2)
    rng = np.random.default_rng(3)
    echo = (rng.standard_normal((12, 16)) + 1j * rng.standard_normal((12, 16))).astype(np.complex64)
    head = {"format": "lab-sar", "n_lines": 12, "n_samples": 16, "carrier_hz": 9.6e9, "sampling_hz": 50e6,
            "window_start_s": 2e-5, "prf_hz": 500.0, "chirp_rate_hz_per_s": 2e12, "pulse_s": 4e-6}
    src = tmp_path / "scan.lab"
    src.write_bytes(json.dumps(head).encode() + b"\n" + echo.tobytes())
    r = cli("ingest", src, "-o", tmp_path / "raw.h5", "--option", 'epoch="2021-05-01T10:00:00Z"')
    assert r.exit_code == 0, r.stderr
    p = read_raw(tmp_path / "raw.h5")
    assert np.array_equal(p.echo, echo) and p.source == "lab-sar" and p.epoch_utc == "2021-05-01T10:00:00Z"
    assert cli("info", src).exit_code == 0


def test_recipe_dask(recipe, tmp_path):
    """The Dask recipe on a local cluster of two processes: every product equals the one the same step
    makes in this process, and records the task's provenance (not a worker's command line)."""
    import shutil

    from sarcli.io.doppler_product import read_doppler
    from sarcli.io.h5common import open_product, provenance
    from sarcli.io.raw import write_raw
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate
    from sarcli.workflows import doppler

    ns = recipe(3)
    raw = simulate(load_scene(Path(__file__).resolve().parents[1] / "doppler" / "scenes" / "rs1_clutter.toml"))
    raws = [tmp_path / "a.h5", tmp_path / "b.h5"]
    write_raw(raws[0], raw)
    shutil.copyfile(raws[0], raws[1])
    out = tmp_path / "out"
    out.mkdir()
    reports = ns["doppler_on_cluster"]([str(r) for r in raws], out)
    assert len(reports) == 2
    local = doppler.run(doppler.Config(raw=raws[0], output=tmp_path / "local.h5"))
    for r in raws:
        m = read_doppler(out / f"{r.stem}.doppler.h5")
        assert m.summary.fdc_hz == local.summary.fdc_hz
        with open_product(out / f"{r.stem}.doppler.h5") as f:
            assert provenance(f)["command_line"] == f"dask: doppler of {r.name}"
