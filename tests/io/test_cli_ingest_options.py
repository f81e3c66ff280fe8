"""`sarcli ingest`: an unreadable MATLAB file and out-of-range options give one line, no traceback."""

from __future__ import annotations

import pytest

from sarcli.io.ceos.radarsat1 import write_ceos

from .test_ingest_cli import one_line_error


def test_matlab_garbage_is_one_line(cli, tmp_path):
    junk = tmp_path / "garbage.toml"
    junk.write_text("a = 1\n")
    other = tmp_path / "other.mat"
    other.write_bytes(b"\0" * 300)
    for args in (["--matlab", junk, "--params", other], ["--matlab", other, "--params", junk]):
        r = cli("ingest", *args, "-o", tmp_path / "m.h5")
        one_line_error(r, "not a readable MATLAB")
        assert "Traceback" not in r.stderr
    assert not (tmp_path / "m.h5").exists()


@pytest.mark.parametrize("args, needle", [
    (["--max-gap", "-1"], "--max-gap"),
    (["--f3-pulses", "99"], "--f3-pulses must be 8 or 9"),
    (["--f3-pulses", "0"], "--f3-pulses must be 8 or 9"),
])
def test_bad_ceos_options_refused(cli, make_raw, tmp_path, args, needle):
    write_ceos(tmp_path / "scene", make_raw(n_lines=24))
    r = cli("ingest", tmp_path / "scene", "-o", tmp_path / "x.h5", *args)
    one_line_error(r, needle)
    assert not (tmp_path / "x.h5").exists()


def test_missing_output_folder_refused_before_reading(cli, make_raw, tmp_path):
    write_ceos(tmp_path / "scene", make_raw(n_lines=24))
    r = cli("ingest", tmp_path / "scene", "-o", tmp_path / "nope" / "x.h5")
    one_line_error(r, "does not exist")
