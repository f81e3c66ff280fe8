"""The first hour at the command line: -h, shell completion, --version with the libraries' own version
strings, choices in --help, and the documented exit codes (docs/cli.md; 3 = instrument is exercised by
tests/acquire)."""

from __future__ import annotations

import pytest


def test_h_is_help(cli):
    for args in ((), ("gbsar", "focus"), ("export",)):
        a, b = cli(*args, "-h"), cli(*args, "--help")
        assert a.exit_code == b.exit_code == 0 and a.stdout == b.stdout and "Usage:" in a.stdout


def test_completion_scripts(cli):
    """The console script prints a bash completion script for itself (the program name comes from argv).
    ``--show-completion`` detects the shell from the parent processes (none under CI); the variable
    names it, as docs/cli.md shows."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    exe = Path(sys.executable).parent / "sarcli"
    if not exe.exists():
        pytest.skip("the sarcli console script is not installed beside this interpreter")
    r = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60,
                       env={**os.environ, "_SARCLI_COMPLETE": "source_bash"})
    assert r.returncode == 0 and "_SARCLI_COMPLETE=complete_bash" in r.stdout and "complete " in r.stdout
    assert "--install-completion" in cli("--help").stdout


def test_version_names_the_libraries_as_they_report_themselves(cli):
    import numba
    import numpy
    import pyproj
    import rasterio

    out = cli("--version").stdout.splitlines()
    assert out[0].startswith("sarcli ")
    got = dict(line.split() for line in out[1:])
    assert got["numpy"] == numpy.__version__ and got["numba"] == numba.__version__
    assert got["GDAL"] == rasterio.__gdal_version__ and got["PROJ"] == pyproj.proj_version_str


@pytest.mark.parametrize("args, shown", [
    (("gbsar", "focus"), "[auto|df|rd|bp|ffbp]"), (("gbsar", "interfere"), "[dinsar|crosstrack|deltaf|combined]"),
    (("simulate",), "[hdf5|ceos|s1-l0]"), (("doppler",), "[auto|orbit|data|none]"),
    (("export",), "[nisar-rslc|sicd|envi|PLUG-IN]"), (("ingest",), "[auto|gzip|lzf|none]")])
def test_choices_in_help(cli, args, shown):
    assert shown in " ".join(cli(*args, "-h").stdout.split())


def test_exit_codes(cli, tmp_path, monkeypatch):
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not hdf5")
    r = cli("info", junk)  # bad data
    assert r.exit_code == 1 and r.stderr.startswith("sarcli: error:") and len(r.stderr.splitlines()) == 1
    r = cli("gbsar", "interfere", junk, junk, "-o", tmp_path / "x.h5", "--window", "0")  # usage
    assert r.exit_code == 2 and r.stderr.startswith("sarcli: error:")

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    import sarcli.workflows.export as export

    monkeypatch.setattr(export, "run", interrupted)
    r = cli("export", junk, "-o", tmp_path / "x.nitf", "--format", "sicd")
    assert r.exit_code == 130 and r.stderr.strip() == "sarcli: error: interrupted"


@pytest.mark.parametrize("args", [
    ("info", "{nope}"), ("focus", "{nope}", "-o", "{out}"), ("doppler", "{nope}", "-o", "{out}"),
    ("quality", "{nope}"), ("export", "{nope}", "-o", "{out}"), ("ingest", "{nope}", "-o", "{out}"),
    ("ingest", "--matlab", "{nope}", "--params", "{nope}", "-o", "{out}"),
    ("orbit", "info", "{nope}"), ("gbsar", "focus", "{nope}", "-o", "{out}"), ("run", "{nope}"),
    ("simulate", "{nope}", "-o", "{out}")])
def test_a_missing_input_file_is_a_usage_error(cli, tmp_path, args):
    """README, docs/cli.md and docs/architecture.md agree: a missing input file is a usage mistake, exit 2,
    one line naming the file, whichever command reads it."""
    nope, out = tmp_path / "nope.h5", tmp_path / "out.h5"
    r = cli(*(a.format(nope=nope, out=out) for a in args))
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 2 and len(lines) == 1, r.stderr
    assert lines[0].startswith("sarcli: error: ") and str(nope) in lines[0] and "no such file" in lines[0]


@pytest.mark.parametrize("args", [
    ("--bogus",), ("focus", "--bogus"), ("gbsar", "focus", "--bogus"), ("gbsar", "--bogus"),
    ("orbit", "info", "--bogus"), ("info", "a.h5", "b", "c", "--json", "--jsno"), ("frobnicate",),
    ("gbsar", "frobnicate"), ("focus", "--fdc"), ("simulate", "x.toml", "--format", "tiff")])
def test_a_usage_mistake_is_one_line_with_exit_2(cli, args):
    """Click's own usage errors (unknown option or command, missing value, bad choice) read like every other
    error: one line ``sarcli: error: ...`` naming the command and where to find its options, exit 2."""
    r = cli(*args)
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 2 and len(lines) == 1, r.stderr
    assert lines[0].startswith("sarcli: error: ") and "-h" in lines[0], lines[0]
    assert "Usage:" not in r.stderr and "Try '" not in r.stderr


def test_every_command_says_what_it_wrote(cli, small, tmp_path):
    """Each file a command writes is named in its status ("wrote PATH"), with the folder as given."""
    from pathlib import Path

    samples = Path(__file__).parents[2] / "samples"
    d = tmp_path / "out"
    d.mkdir()
    runs = [
        (("gbsar", "simulate", samples / "gbsar_p1.toml", "-o", d / "p1.h5"), [d / "p1.h5"]),
        (("gbsar", "simulate", samples / "gbsar_p2.toml", "-o", d / "p2.h5"), [d / "p2.h5"]),
        (("gbsar", "focus", d / "p1.h5", "-o", d / "i.h5", "--quicklook", d / "i.png"), [d / "i.h5", d / "i.png"]),
        (("gbsar", "coherence", d / "p1.h5", d / "p2.h5", "-o", d / "ps.h5", "--csv", d / "ps.csv", "--plot",
          d / "ps.png"), [d / "ps.h5", d / "ps.csv", d / "ps.png"]),
        (("quality", small.slc, "--plot", d / "irf.png"), [d / "irf.png"]),
    ]
    for args, written in runs:
        r = cli(*args)
        assert r.exit_code == 0, r.stderr
        for p in written:
            assert p.is_file() and f"wrote {p}" in r.stdout + r.stderr, (args[:2], p)
    r = cli("focus", small.raw, "-o", d / "slc.h5", "--fdc", "-6558", "--fr", "-1781")
    assert f"focused {small.raw} -> {d / 'slc.h5'}" in r.stderr  # the input's folder kept
