"""CLI plumbing: discovery, --version, one-line errors and exit codes."""

from __future__ import annotations

import subprocess
import sys

from sarcli import __version__


def test_version(cli):
    r = cli("--version")
    assert r.exit_code == 0 and r.stdout.splitlines()[0] == f"sarcli {__version__}"  # then the libraries


def test_help_lists_commands(cli):
    r = cli("--help")
    assert r.exit_code == 0
    assert "design" in r.stdout


def test_missing_file_is_one_line_through_console_script(tmp_path):
    """The installed entry point, as a user runs it: no traceback, exit 2, one line."""
    r = subprocess.run([sys.executable, "-c", "from sarcli.cli.app import main; main()", "design",
                        str(tmp_path / "nope.toml")], capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == [f"sarcli: error: {tmp_path / 'nope.toml'}: no such file"]
