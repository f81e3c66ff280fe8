"""The GB-SAR workflows as a Python API: configurations from TOML tables, products equal to the
CLI's, the block-wise temporal coherence equal to the whole-stack computation, and thin CLI modules."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sarcli.config import from_mapping, to_mapping
from sarcli.errors import ConfigError
from sarcli.workflows import WORKFLOWS
from tests.conftest import REPO, run_cli

from .test_cli import _scan

GBSAR_WORKFLOWS = ["gbsar_simulate", "gbsar_plan", "gbsar_focus", "gbsar_interfere", "gbsar_coherence",
                   "gbsar_polarimetry", "gbsar_scan", "gbsar_emulate", "gbsar_repeat"]

TABLES = {
    "gbsar_simulate": {"scene": "s.toml", "output": "s.h5"},
    "gbsar_plan": {"source": "s.toml", "criterion_deg": 30},
    "gbsar_focus": {"scan": "s.h5", "output": "i.h5", "algorithm": "rd", "pols": ["vv"], "max_range_m": 15,
                    "range_window": "kaiser:2.5", "azimuth_window": "hann", "quicklook": "i.png"},
    "gbsar_interfere": {"reference": "a.h5", "secondary": "b.h5", "output": "x.h5", "mode": "crosstrack"},
    "gbsar_coherence": {"images": ["a.h5", "b.h5", "c.h5"], "output": "ps.h5", "threshold": 0.99, "block_rows": 8},
    "gbsar_polarimetry": {"image": "i.h5", "png": "nd.png", "window": 5},
    "gbsar_scan": {"config": "scan.toml", "dry_run": True, "points": 401, "start": "5.2GHz"},
    "gbsar_emulate": {"scene": "s.toml", "time_scale": 0, "switch": "grbl"},
    "gbsar_repeat": {"every": "30m", "count": 3, "port": "a", "rail_port": "b", "config": "scan.toml",
                     "output": "scan_{index}.h5"},
}


@pytest.mark.parametrize("name", GBSAR_WORKFLOWS)
def test_workflow_config_loads_from_a_toml_table_and_round_trips(name):
    wf = WORKFLOWS.get(name)
    assert callable(wf.run) and dataclasses.is_dataclass(wf.Config)
    cfg = from_mapping(wf.Config, TABLES[name], f"steps.toml [{name}]")
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(cfg, dataclasses.fields(cfg)[0].name, None)
    assert from_mapping(wf.Config, to_mapping(cfg), name) == cfg
    with pytest.raises(ConfigError, match=rf"steps.toml \[{name}\]: unknown option\(s\) colour"):
        from_mapping(wf.Config, {**TABLES[name], "colour": 1}, f"steps.toml [{name}]")


@pytest.mark.parametrize("name, bad, needle", [
    ("gbsar_focus", {"algorithm": "magic"}, "'magic' is not one of"),
    ("gbsar_focus", {"range_window": "blackman"}, "unknown window 'blackman'"),
    ("gbsar_focus", {"criterion_deg": 400}, "--criterion-deg must be in (0, 180]"),
    ("gbsar_coherence", {"images": ["a.h5"]}, "at least 2 images"),
    ("gbsar_interfere", {"window": 0}, "must be >= 1 pixel"),
    ("gbsar_repeat", {"output": "same.h5"}, "{index}"),
])
def test_bad_values_are_refused_when_the_config_is_made(name, bad, needle):
    with pytest.raises(ConfigError) as e:
        from_mapping(WORKFLOWS.get(name).Config, {**TABLES[name], **bad}, name)
    assert needle in str(e.value)


def test_python_api_writes_the_cli_product(tmp_path, monkeypatch):
    """run(Config) from Python and the CLI give the same product bytes once given the same provenance;
    without one, the product says it was made through the Python API (never sys.argv)."""
    import h5py

    from sarcli.io.provenance import Provenance
    from sarcli.workflows import gbsar_focus

    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    scan = _scan(run_cli, tmp_path, "a")
    cli_out, api_out = tmp_path / "cli" / "i.h5", tmp_path / "api" / "i.h5"
    cli_out.parent.mkdir()
    api_out.parent.mkdir()
    assert run_cli("gbsar", "focus", scan, "-o", cli_out, "--max-range", "40").exit_code == 0
    with h5py.File(cli_out) as f:
        recorded = f.attrs["command_line"]
    cfg = gbsar_focus.Config(scan=scan, output=api_out, max_range_m=40.0)
    rep = gbsar_focus.run(cfg, provenance=Provenance(command_line=recorded))
    assert rep.output == str(api_out) and set(rep.focus["used"]) == {"bp", "df"}
    assert api_out.read_bytes() == cli_out.read_bytes()
    gbsar_focus.run(dataclasses.replace(cfg, output=tmp_path / "plain.h5"))
    with h5py.File(tmp_path / "plain.h5") as f:
        assert f.attrs["command_line"] == "python API"


def test_blockwise_coherence_equals_the_whole_stack(tmp_path):
    """Reading the images by blocks of rows gives the whole-stack result bit for bit: coherence map
    (NaN outside the common support), PS, their phases and displacements; a scan among the inputs is
    focused on the first image's grid."""
    from sarcli.gbsar.interferometry import support
    from sarcli.gbsar.timeseries import ps_series, select_ps, temporal_coherence
    from sarcli.io.gbsar_image import read_gbsar_image
    from sarcli.io.interferogram import read_ps
    from sarcli.workflows import gbsar_coherence, gbsar_common

    scans = [_scan(run_cli, tmp_path, f"p{k}", seed=k, minute=10 * k) for k in range(1, 5)]
    images = []
    for s in scans[:3]:
        out = s.with_suffix(".img.h5")
        assert run_cli("gbsar", "focus", s, "-o", out).exit_code == 0
        images.append(out)
    inputs = (*images, scans[3])
    imgs = [read_gbsar_image(p) for p in images]
    imgs.append(gbsar_common.focus_on_the_fly(scans[3], like=imgs[0]))
    stack = np.stack([im.pol("VV") for im in imgs])  # the former, whole-stack computation
    ok = np.logical_and.reduce([support(im, "VV") for im in imgs])
    gamma = np.where(ok, temporal_coherence(stack), np.nan).astype(np.float32)
    rows, cols = select_ps(gamma, np.mean(np.abs(stack), axis=0), 0.99, 40.0)
    phase, disp = ps_series(stack[:, rows, cols].T, imgs[0].wavelength_m)
    assert rows.size >= 2 and np.isnan(gamma).any()
    n_r = imgs[0].range_m.size
    for block_rows in (1, 7, n_r):  # 1 row, blocks not dividing the rows, one block
        out = tmp_path / f"ps{block_rows}.h5"
        rep = gbsar_coherence.run(gbsar_coherence.Config(images=inputs, output=out, threshold=0.99,
                                                         block_rows=block_rows))
        assert rep.n_ps == rows.size and rep.supported_pixels == int(ok.sum())
        ps = read_ps(out)
        np.testing.assert_array_equal(ps["coherence"], gamma)
        np.testing.assert_array_equal(ps["ps_row"], rows)
        np.testing.assert_array_equal(ps["ps_col"], cols)
        np.testing.assert_array_equal(ps["ps_phase"], phase)
        np.testing.assert_array_equal(ps["ps_displacement_mm"], disp)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".ps")]  # temporary image files removed


def test_block_size_bounds_the_memory():
    from sarcli.workflows.gbsar_coherence import BLOCK_BYTES

    # 100 images of 4096 columns: one block of every image is 8 x 4 x 100 x 4096 B x rows <= 64 MiB
    assert BLOCK_BYTES // (100 * 4096 * 8 * 4) >= 1


CLI_MODULES = [REPO / "sarcli" / "cli" / "commands" / "gbsar_processing.py",
               REPO / "sarcli" / "cli" / "commands" / "gbsar_acquisition.py",
               REPO / "sarcli" / "cli" / "gbsar_app.py"]


@pytest.mark.parametrize("path", CLI_MODULES, ids=lambda p: p.name)
def test_gbsar_cli_modules_import_no_array_or_file_library(path: Path):
    """The CLI parses options and prints reports; arrays and files are the workflows' business."""
    heavy = {"numpy", "h5py", "scipy", "rasterio", "matplotlib", "numba"}
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names = [node.module or ""]
        else:
            continue
        for n in names:
            assert n.split(".")[0] not in heavy, (path.name, n)
            assert not n.startswith(("sarcli.gbsar", "sarcli.acquire", "sarcli.io")), (path.name, n)
