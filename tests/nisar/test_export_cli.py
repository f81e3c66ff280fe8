"""``sarcli export``: a sarcli SLC product -> NISAR RSLC through the CLI; the format plug-in registry."""

from __future__ import annotations

import json

import numpy as np
import pytest


@pytest.fixture(scope="module")
def slc_file(sim_slc, tmp_path_factory):
    from sarcli.io.slc import write_slc

    p = tmp_path_factory.mktemp("slc") / "slc.h5"
    write_slc(p, sim_slc)
    return p


def test_export_writes_an_rslc_with_the_command_line(cli, slc_file, tmp_path):
    from sarcli.io.h5common import provenance
    from sarcli.io.nisar.rslc import read_rslc

    out = tmp_path / "rslc.h5"
    r = cli("export", slc_file, "--format", "nisar-rslc", "-o", out, "--polarization", "HV", "--option",
            "compression=gzip", "--json")
    assert r.exit_code == 0, r.stderr
    rep = json.loads(r.stdout)
    assert rep["format"] == "nisar-rslc" and rep["details"]["polarization"] == "HV"
    s = read_rslc(out, polarization="HV")
    assert s.image.shape == tuple(rep["shape"])
    import h5py

    with h5py.File(out, "r") as f:
        p = provenance(f)
        assert p["command_line"] and p["inputs"][0]["path"] == "slc.h5"  # the caller's line (pytest's here)
        assert f["science/LSAR/RSLC/swaths/frequencyA/HV"].compression == "gzip"
    # an RSLC layer re-exported keeps its name
    again = tmp_path / "again.h5"
    assert cli("export", out, "-o", again).exit_code == 0
    np.testing.assert_array_equal(read_rslc(again, polarization="HV").image, s.image)


@pytest.mark.parametrize("args, code, message", [
    (["--format", "geojpeg"], 2, "unknown export format 'geojpeg'"),
    (["--option", "colour=red"], 2, "unknown option(s) colour"),
    (["--option", "nokey"], 2, "expected KEY=VALUE"),
    (["--frequency", "A"], 2, "apply to NISAR RSLC files only"),
])
def test_export_usage_errors_one_line(cli, slc_file, tmp_path, args, code, message):
    r = cli("export", slc_file, "-o", tmp_path / "x.h5", *args)
    assert r.exit_code == code and message in r.stderr and r.stderr.count("\n") == 1
    assert not (tmp_path / "x.h5").exists()


def test_export_refuses_overwriting_its_input_and_missing_files(cli, slc_file, tmp_path):
    r = cli("export", slc_file, "-o", slc_file)
    assert r.exit_code == 2 and "refusing to overwrite an input" in r.stderr
    r = cli("export", tmp_path / "absent.h5", "-o", tmp_path / "x.h5")
    assert r.exit_code == 2 and "no such file" in r.stderr


def test_a_plugin_format_is_used_without_changing_the_command(cli, slc_file, tmp_path):
    from dataclasses import dataclass

    from sarcli.workflows.export import FORMATS

    @dataclass(frozen=True)
    class Opts:
        scale: float = 1.0

    class Npy:
        name, description, suffix, Options = "npy", "numpy array", ".npy", Opts

        def write(self, slc, output, options, inputs):
            np.save(output, slc.image * options.scale)
            return {"scale": options.scale}

    FORMATS.register("npy", Npy())
    try:
        out = tmp_path / "img.npy"
        r = cli("export", slc_file, "--format", "npy", "-o", out, "--option", "scale=2", "--json")
        assert r.exit_code == 0, r.stderr
        assert json.loads(r.stdout)["details"]["scale"] == 2.0
        assert np.load(out).shape == (2048, 1536)
    finally:
        FORMATS.unregister("npy")


def test_info_summarizes_an_exported_rslc(cli, sim_rslc):
    r = cli("info", sim_rslc, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["product_type"] == "nisar_rslc" and s["main_dataset"] == "/science/LSAR/RSLC/swaths/frequencyA/HH"


def test_info_describes_an_rslc_without_sarcli_provenance(cli, sim_rslc, tmp_path):
    """An RSLC written by another tool carries no ``product_type``: info recognises the layout itself."""
    import shutil

    import h5py

    other = tmp_path / "isce3_like.h5"
    shutil.copy(sim_rslc, other)
    with h5py.File(other, "r+") as f:
        del f.attrs["product_type"]
    r = cli("info", other, "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["product_type"] == "nisar_rslc" and s["frequencies"] == {"frequencyA": ["HH"]}
    assert s["shape"] == [2048, 1536]
    r = cli("info", other)
    assert r.exit_code == 0 and "NISAR RSLC (L-band" in r.stdout and "frequencyA: HH" in r.stdout


def test_export_status_rounds_its_numbers_and_warns_without_a_focused_line(cli, slc_file, tmp_path):
    """The details are printed to 10 significant digits (no 30109148.999999996); an SLC whose lines are all
    partly focused (first fully focused line after the last) is exported with a warning saying so."""
    import re

    import h5py

    r = cli("export", slc_file, "-o", tmp_path / "a.h5")
    assert r.exit_code == 0, r.stderr
    numbers = re.findall(r"\d+\.\d+", r.stdout + r.stderr)
    assert numbers and all(len(n.replace(".", "").lstrip("0")) <= 10 for n in numbers), numbers
    assert "no fully focused line" not in r.stderr
    bad = tmp_path / "partial.h5"
    bad.write_bytes(slc_file.read_bytes())
    with h5py.File(bad, "r+") as f:
        f.attrs["first_full_line"], f.attrs["last_full_line"] = 3644, 999
    r = cli("export", bad, "-o", tmp_path / "b.h5")
    assert r.exit_code == 0, r.stderr
    assert "no fully focused line" in r.stderr and "3644" in r.stderr
