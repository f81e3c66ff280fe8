"""The product tests' small focused scene (tests/products/scenes/small.toml: two point targets, 1536 lines x
600 samples), simulated and focused once per session with its GeoTIFFs."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.conftest import run_cli

SCENE = Path(__file__).parent / "scenes" / "small.toml"


@dataclass(frozen=True)
class Small:
    raw: Path
    slc: Path
    map_tif: Path
    slant_tif: Path


@pytest.fixture(scope="session")
def small(tmp_path_factory) -> Small:
    d = tmp_path_factory.mktemp("small")
    out = Small(d / "raw.h5", d / "slc.h5", d / "amp.tif", d / "amp_slant.tif")
    r = run_cli("simulate", SCENE, "-o", out.raw)
    assert r.exit_code == 0, r.stderr
    r = run_cli("focus", out.raw, "-o", out.slc, "--range-window", "rect", "--looks-az", "2",
                "--geotiff", out.map_tif, "--geotiff-slant", out.slant_tif)
    assert r.exit_code == 0, r.stderr
    return out
