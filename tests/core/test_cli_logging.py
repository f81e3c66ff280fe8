"""What reaches the terminal: -v/-vv diagnostics (std logging of sarcli's modules), --quiet (no status
lines), --log-file (everything, with times), warnings as one line ``sarcli: warning: ...``."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

SCENE = Path(__file__).resolve().parents[2] / "tests" / "focus" / "scenes" / "batch.toml"


@pytest.fixture(scope="module")
def ceos(tmp_path_factory):
    from tests.conftest import run_cli

    d = tmp_path_factory.mktemp("logging") / "ceos"
    assert run_cli("simulate", SCENE, "--format", "ceos", "-o", d).exit_code == 0
    return d


def _diagnostics(stderr: str) -> list[str]:
    return [ln for ln in stderr.splitlines() if ln.startswith(("sarcli: info: ", "sarcli: debug: "))]


def test_default_shows_no_diagnostics(cli, ceos, tmp_path):
    r = cli("ingest", ceos, "-o", tmp_path / "a.h5")
    assert r.exit_code == 0 and _diagnostics(r.stderr) == [] and "wrote" in r.stderr


def test_verbose_shows_info_and_very_verbose_debug(cli, ceos, tmp_path):
    r = cli("-v", "ingest", ceos, "-o", tmp_path / "a.h5")
    lines = _diagnostics(r.stderr)
    assert r.exit_code == 0 and lines and all(ln.startswith("sarcli: info: sarcli.") for ln in lines)
    assert any("reading" in ln and "ceos-rs1" in ln for ln in lines), lines
    r = cli("-vv", "ingest", ceos, "-o", tmp_path / "b.h5")
    debug = [ln for ln in _diagnostics(r.stderr) if ln.startswith("sarcli: debug: ")]
    assert any("sarcli.io.readers: reader ceos-rs1 recognises" in ln for ln in debug), r.stderr
    assert "wrote" in r.stderr  # the status line stays


def test_quiet_hides_status_lines_not_results_or_errors(cli, ceos, tmp_path):
    r = cli("-q", "ingest", ceos, "-o", tmp_path / "a.h5")
    assert r.exit_code == 0 and r.stderr == "" and (tmp_path / "a.h5").is_file()
    r = cli("--quiet", "ingest", ceos, "-o", tmp_path / "a2.h5", "--json")
    assert r.exit_code == 0 and r.stderr == "" and '"shape"' in r.stdout
    r = cli("-q", "ingest", ceos, "-o", tmp_path / "nope" / "a.h5")
    assert r.exit_code == 2 and r.stderr.startswith("sarcli: error: ") and "does not exist" in r.stderr
    r = cli("-q", "-v", "info", tmp_path / "a.h5")
    assert r.exit_code == 2 and "--verbose and --quiet exclude each other" in r.stderr


def test_log_file_gets_everything_with_times(cli, ceos, tmp_path):
    log = tmp_path / "run.log"
    r = cli("--log-file", log, "ingest", ceos, "-o", tmp_path / "a.h5")
    assert r.exit_code == 0 and _diagnostics(r.stderr) == []  # the terminal stays as it was
    r = cli("--log-file", log, "ingest", ceos, "-o", tmp_path / "nope" / "a.h5")
    assert r.exit_code == 2
    text = log.read_text()
    lines = text.splitlines()
    assert lines[0][:4].isdigit() and " INFO sarcli.cli: command: " in lines[0]   # appended, timestamped
    assert "DEBUG sarcli.io.readers: reader ceos-rs1 recognises" in text
    assert "INFO sarcli.cli: wrote " in text                                       # the status line
    assert "ERROR sarcli.cli: error (exit 2): output folder" in text                # the second run's error
    assert text.count(" command: ") == 2
    r = cli("--log-file", tmp_path / "no" / "run.log", "info", tmp_path / "a.h5")
    assert r.exit_code == 2 and "--log-file" in r.stderr and "cannot open" in r.stderr


def test_warnings_are_one_line_and_logged(cli, tmp_path):
    """A user-facing warning (here: times extrapolated beyond the state vectors) is one line on stderr."""
    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENE, "-o", raw).exit_code == 0
    log = tmp_path / "w.log"
    for _ in range(2):  # shown again in the next invocation (once per place in the code and per run)
        r = cli("--log-file", log, "orbit", "interpolate", raw, "-t", "3400", "--extrapolate", "100", "--json")
        warn = [ln for ln in r.stderr.splitlines() if "extrapolated" in ln]
        assert r.exit_code == 0 and warn == [
            "sarcli: warning: extrapolated 1 of 1 time(s) beyond the state-vector span [-3360.000000, "
            "3360.000000] s: 3400.000000"], r.stderr
    assert log.read_text().count("WARNING sarcli.cli: warning: extrapolated 1 of 1") == 2


def test_logging_is_restored_after_each_invocation(cli, ceos, tmp_path):
    lg = logging.getLogger("sarcli")
    state = (lg.level, lg.propagate, list(lg.handlers))
    cli("-vv", "--log-file", tmp_path / "x.log", "ingest", ceos, "-o", tmp_path / "a.h5")
    assert (lg.level, lg.propagate, list(lg.handlers)) == state
