"""``make batch IN=dir OUT=dir``: three small simulated scenes (two HDF5, one CEOS folder) reprocessed
raw -> doppler -> slc -> GeoTIFF + quicklook in parallel; only out-of-date products are rebuilt; a bad
input stops make with the file's name."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from .theory import irf_theory

C = 299792458.0
REPO = Path(__file__).resolve().parents[2]
SCENE = Path(__file__).parent / "scenes" / "batch_long.toml"  # longer than its aperture: GeoTIFFs hold pixels


def _make(inp: Path, out: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, SARCLI_NO_PROGRESS="1")
    return subprocess.run(["make", "-C", str(REPO), "--no-print-directory", "-j2", "batch", f"IN={inp}",
                           f"OUT={out}"], capture_output=True, text=True, env=env, timeout=600)


@pytest.mark.slow
def test_make_batch_three_scenes(cli, tmp_path):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    assert cli("simulate", SCENE, "-o", inp / "a.h5").exit_code == 0
    shutil.copy(inp / "a.h5", inp / "b.h5")
    assert cli("simulate", SCENE, "--format", "ceos", "-o", inp / "c").exit_code == 0
    r = _make(inp, out)
    assert r.returncode == 0, r.stderr
    for n in "abc":
        for suffix in (".doppler.h5", ".slc.h5", ".tif", ".png"):
            assert (out / f"{n}{suffix}").stat().st_size > 0, (n, suffix)
    assert (out / "c.raw.h5").exists()  # the CEOS scene was ingested first
    # focusing quality with the Doppler ESTIMATED by `sarcli doppler` (the HDF5 products carry the truth; a
    # CEOS scene does not): targets in
    # place to 0.1 pixel; range IRW of the default Kaiser 2.5 window, 0.886-equivalent 1.042 c/(2B),
    # within 10 % (the scene's 5 us chirp has a time-bandwidth product of 18: Fresnel ripple widens it)
    band = 0.72135e12 * 5.0e-6
    for n in "ab":
        q = cli("quality", out / f"{n}.slc.h5", "--json")
        assert q.exit_code == 0, q.stderr
        for m in json.loads(q.stdout):
            assert abs(m["position_error_range_px"]) < 0.1 and abs(m["position_error_azimuth_px"]) < 0.1, m
            assert m["irw_range_m"] == pytest.approx(irf_theory("kaiser:2.5")["irw"] * C / (2 * band), rel=0.10)
    # up to date: nothing runs; an input made newer rebuilds only its own chain
    stamps = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    r = _make(inp, out)
    assert r.returncode == 0 and "sarcli" not in r.stdout
    time.sleep(0.01)
    (inp / "b.h5").touch()
    r = _make(inp, out)
    assert r.returncode == 0, r.stderr
    changed = {p.name for p in out.iterdir() if p.stat().st_mtime_ns != stamps.get(p.name)}
    assert changed == {"b.doppler.h5", "b.slc.h5", "b.tif", "b.qml", "b.png"}  # b.qml: the GeoTIFF's QGIS style


def test_make_batch_stops_on_a_bad_input_with_its_name(tmp_path):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    (inp / "broken.h5").write_bytes(b"not an HDF5 file")
    r = _make(inp, out)
    assert r.returncode != 0
    assert "broken.h5" in r.stderr and "sarcli: error:" in r.stderr
    assert not (out / "broken.slc.h5").exists()
