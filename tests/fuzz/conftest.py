"""Fuzz fixtures: pristine tiny products made once per session by the simulator and the processing chain."""

from __future__ import annotations

import dataclasses
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from sarcli.io import atomic, h5common
from tests.conftest import run_cli
from tests.fuzz.harness import SCRATCH, Catalogue, catalogue

SCENES = Path(__file__).parent / "scenes"


@dataclasses.dataclass(frozen=True)
class Pristine:
    paths: dict[str, Path]
    catalogues: dict[str, Catalogue]


def _ok(*args) -> None:
    r = run_cli(*args)
    assert r.exit_code == 0, f"sarcli {' '.join(map(str, args))}: {r.stderr}"


@pytest.fixture(scope="session")
def pristine() -> Iterator[Pristine]:
    """raw.h5 + its CEOS folder, doppler.h5, slc.h5 (tiny Radarsat-1-like scene); two GB-SAR scans,
    their images (the second scene differs by its noise seed) and their interferogram; the two scene files."""
    d = Path(tempfile.mkdtemp(prefix="sarcli-pristine-", dir=SCRATCH))  # beside the cases: hard links work
    try:
        with pytest.MonkeyPatch.context() as mp:  # byte-identical products every run: same cases, same bytes
            mp.setenv("SOURCE_DATE_EPOCH", "1024243200")
            mp.setattr(sys, "argv", ["sarcli"])
            made = _make_pristine(d)
        yield made
    finally:
        shutil.rmtree(d, ignore_errors=True)


def _make_pristine(d: Path) -> Pristine:
    p = {k: d / n for k, n in (("raw", "raw.h5"), ("ceos", "ceos"), ("doppler", "doppler.h5"), ("slc", "slc.h5"),
                              ("scan", "scan.h5"), ("scan2", "scan2.h5"), ("image", "image.h5"),
                              ("image2", "image2.h5"), ("ifg", "ifg.h5"), ("rs1_toml", "tiny_rs1.toml"),
                              ("gbsar_toml", "tiny_gbsar.toml"))}
    for key, name in (("rs1_toml", "tiny_rs1.toml"), ("gbsar_toml", "tiny_gbsar.toml")):
        shutil.copyfile(SCENES / name, p[key])  # the scene files, damaged by the scene fuzz
    _ok("simulate", SCENES / "tiny_rs1.toml", "-o", p["raw"])
    _ok("simulate", SCENES / "tiny_rs1.toml", "--format", "ceos", "-o", p["ceos"])
    _ok("doppler", p["raw"], "-o", p["doppler"])
    _ok("focus", p["raw"], "--doppler", p["doppler"], "-o", p["slc"])
    second = d / "tiny_gbsar2.toml"
    second.write_text((SCENES / "tiny_gbsar.toml").read_text().replace("seed = 1", "seed = 2"))
    for scene, scan, image in ((SCENES / "tiny_gbsar.toml", "scan", "image"), (second, "scan2", "image2")):
        _ok("gbsar", "simulate", scene, "-o", p[scan])
        _ok("gbsar", "focus", p[scan], "-o", p[image])
    _ok("gbsar", "interfere", p["image"], p["image2"], "-o", p["ifg"])
    cats = {k: catalogue(v) for k, v in p.items() if v.suffix == ".h5"}
    return Pristine(p, cats)


@pytest.fixture(autouse=True)
def _short_probe(monkeypatch):
    """A hanging metadata probe is given 2 s here (a tiny product's metadata take milliseconds)."""
    monkeypatch.setattr(h5common, "PROBE_TIMEOUT_S", 2.0)


@pytest.fixture(autouse=True)
def _no_fsync(monkeypatch):
    """Durability is tested in tests/core/test_guard.py; here thousands of writes need not wait for the disk."""
    monkeypatch.setattr(atomic, "fsync_path", lambda path: None)
