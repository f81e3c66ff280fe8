"""What ``sarcli gbsar`` refuses, through the CLI: an output that is one of the inputs (same path,
symbolic or hard link; HDF5, GeoTIFF, PNG and CSV outputs alike), and scans whose rail focusing
cannot use (unknown positions or heights, a rail that does not move, a position measured twice, a
single stop). Each refusal is one ``sarcli: error:`` line, a non-zero exit, no output file and an
input left byte for byte as it was. A rail measured backwards is not refused: it focuses to the
image of the same scan measured forwards."""

from __future__ import annotations

import hashlib
import json
import os
import shutil

import h5py
import numpy as np
import pytest

from sarcli.io.gbsar_image import read_gbsar_image
from tests.conftest import run_cli

from .test_cli import _scan


def _digest(path) -> str:
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def _refused(r, code: int, needle: str) -> str:
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == code, r.stderr
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: ") and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr + r.stdout
    return lines[0]


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A scan, its focused image, a second scan of the same geometry 10 min later, the scene file."""
    d = tmp_path_factory.mktemp("made")
    a = _scan(run_cli, d, "a")
    b = _scan(run_cli, d, "b", minute=10)
    img = d / "img.h5"
    assert run_cli("gbsar", "focus", a, "-o", img, "--max-range", "50").exit_code == 0
    return {"scan": a, "scan2": b, "image": img, "scene": d / "a.toml", "dir": d}


def _copy(made, tmp_path, key="scan"):
    p = tmp_path / made[key].name
    shutil.copy(made[key], p)
    return p


@pytest.mark.parametrize("case", ["same_path", "quicklook_hard_link", "geotiff_symlink", "enu_geotiff_same"])
def test_focus_refuses_to_overwrite_its_scan(cli, made, tmp_path, case):
    scan = _copy(made, tmp_path)
    before = _digest(scan)
    out = tmp_path / "img.h5"
    if case == "same_path":
        args = ["-o", scan]
    elif case == "quicklook_hard_link":
        os.link(scan, tmp_path / "look.png")
        args = ["-o", out, "--quicklook", tmp_path / "look.png"]
    elif case == "geotiff_symlink":
        (tmp_path / "map.tif").symlink_to(scan)
        args = ["-o", out, "--geotiff", tmp_path / "map.tif"]
    else:
        args = ["-o", out, "--enu-geotiff", scan]
    _refused(cli("gbsar", "focus", scan, *args), 2, "refusing to overwrite an input")
    assert _digest(scan) == before and not out.exists()


def test_focus_refuses_one_file_for_two_outputs(cli, made, tmp_path):
    out = tmp_path / "img.h5"
    _refused(cli("gbsar", "focus", made["scan"], "-o", out, "--quicklook", out), 2, "are the same file")
    assert not out.exists()


def test_every_writing_command_refuses_its_input(cli, made, tmp_path):
    scan, scan2, img = (_copy(made, tmp_path, k) for k in ("scan", "scan2", "image"))
    scene = _copy(made, tmp_path, "scene")
    os.link(scan2, tmp_path / "values.csv")
    digests = {p: _digest(p) for p in (scan, scan2, img, scene)}
    cases = [
        (["simulate", scene, "-o", scene], tmp_path / "none"),
        (["interfere", scan, scan2, "-o", tmp_path / "i.h5", "--png", scan2], tmp_path / "i.h5"),
        (["interfere", img, scan2, "-o", tmp_path / "i.h5", "--value-geotiff", img], tmp_path / "i.h5"),
        (["coherence", scan, scan2, "-o", tmp_path / "ps.h5", "--csv", tmp_path / "values.csv"], tmp_path / "ps.h5"),
        (["coherence", scan, scan2, "-o", scan], tmp_path / "none"),
        (["polarimetry", img, "--png", img], tmp_path / "none"),
        (["polarimetry", scan, "--geotiff", scan], tmp_path / "none"),
    ]
    for args, out in cases:
        _refused(cli("gbsar", *args), 2, "refusing to overwrite an input")
        assert not out.exists(), args
    assert {p: _digest(p) for p in digests} == digests


def _edited(made, tmp_path, edit) -> str:
    p = _copy(made, tmp_path)
    with h5py.File(p, "r+") as f:
        edit(f)
    return p


def _set(name, fn):
    def edit(f):
        v = f[name][()]
        f[name][...] = fn(v)
    return edit


@pytest.mark.parametrize("edit, needle", [
    (_set("rail_position", lambda x: np.where(np.arange(x.size) == 3, np.nan, x)), "rail"),
    (_set("rail_position", lambda x: np.full_like(x, 0.2)), "rail"),
    (_set("rail_height", lambda h: np.where(np.arange(h.size) == 2, np.nan, h)), "rail_height"),
    (_set("rail_position", lambda x: np.where(np.arange(x.size) == 5, x[4], x)), "rail"),
])
def test_focus_refuses_an_unusable_rail(cli, made, tmp_path, edit, needle):
    scan = _edited(made, tmp_path, edit)
    before = _digest(scan)
    out = tmp_path / "img.h5"
    for alg in ("auto", "bp", "df", "rd"):
        _refused(cli("gbsar", "focus", scan, "-o", out, "--algorithm", alg), 1, needle)
        assert not out.exists()
    assert _digest(scan) == before


def test_focus_refuses_a_single_stop(cli, tmp_path):
    p = tmp_path / "one.toml"
    p.write_text("[sweep]\ncenter_frequency_hz = 5.3e9\nbandwidth_hz = 2e8\npoints = 101\n"
                 "[rail]\npositions_m = [0.0]\n[[points]]\ny_m = 10.0\n")
    assert cli("gbsar", "simulate", p, "-o", tmp_path / "one.h5").exit_code == 0
    _refused(cli("gbsar", "focus", tmp_path / "one.h5", "-o", tmp_path / "img.h5"), 1, "at least 2")
    assert not (tmp_path / "img.h5").exists()


def _reverse(f):
    """The stops measured in the other order: positions, heights, flags and sweeps reversed; the stop times
    still increase (the clock runs forward whatever way the rail moves)."""
    for name in ("rail_position", "rail_height", "stop_flags"):
        f[name][...] = f[name][()][::-1]
    f["s21"][...] = f["s21"][()][:, ::-1]


@pytest.mark.parametrize("alg", ["auto", "bp", "df", "rd"])
def test_a_rail_measured_backwards_focuses_to_the_same_image(cli, made, tmp_path, alg):
    fwd = made["scan"]
    back = _edited(made, tmp_path, _reverse)
    with h5py.File(back) as f:
        assert np.all(np.diff(f["rail_position"][()]) < 0)
    a, b = tmp_path / "fwd.h5", tmp_path / "back.h5"
    for scan, out in ((fwd, a), (back, b)):
        r = cli("gbsar", "focus", scan, "-o", out, "--algorithm", alg, "--max-range", "50", "--json")
        assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["rail_reordered"] is True
    ia, ib = read_gbsar_image(a), read_gbsar_image(b)
    assert np.count_nonzero(ia.image) > 0.5 * ia.image.size  # a real image, not the former all-zero one
    np.testing.assert_array_equal(ib.image, ia.image)
    np.testing.assert_array_equal(ib.algorithm_map, ia.algorithm_map)
    np.testing.assert_array_equal(ib.azimuth_m, ia.azimuth_m)
    assert (ib.rail_centre_m, ib.rail_length_m) == (ia.rail_centre_m, ia.rail_length_m)


def test_plan_of_a_backwards_rail_is_the_forward_plan(cli, made, tmp_path):
    back = _edited(made, tmp_path, _reverse)
    fwd = json.loads(cli("gbsar", "plan", made["scan"], "--json").stdout)
    assert json.loads(cli("gbsar", "plan", back, "--json").stdout) == fwd
    assert fwd["rail_length_m"] > 0
