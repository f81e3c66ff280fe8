"""Shared test fixtures: the CLI runner, the shared real data folder, reproducibility env."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import settings
from typer.testing import CliRunner

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("SARCLI_SHARED", REPO.parent / "shared"))
SAMPLES = REPO / "samples"

os.environ.setdefault("SARCLI_NO_PROGRESS", "1")

# Property tests draw the same examples on every run (a CI result does not depend on luck);
# HYPOTHESIS_PROFILE=explore draws new ones, to hunt for failures locally.
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


@dataclass
class CliResult:
    exit_code: int
    stdout: str
    stderr: str


def run_cli(*args: str) -> CliResult:
    """Run ``sarcli ARGS`` in-process; stdout and stderr are kept apart."""
    from sarcli.cli.app import app

    r = CliRunner().invoke(app, [str(a) for a in args])
    if r.exception is not None and not isinstance(r.exception, SystemExit):
        raise r.exception
    return CliResult(r.exit_code, r.stdout, r.stderr)


@pytest.fixture
def cli():
    """The in-process CLI: ``cli("info", path, "--json")`` -> CliResult."""
    return run_cli


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """``../shared/data`` (real data nobody here made); tests that need it skip if it is absent."""
    d = SHARED / "data"
    if not d.is_dir():
        pytest.skip("../shared/data not available")
    return d
