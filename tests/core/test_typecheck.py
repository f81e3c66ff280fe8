"""The typed public API (docs/extending.md, "Types"): mypy with the project's configuration
([tool.mypy] in pyproject.toml: sarcli/model, sarcli/workflows, config, errors, registry, orbit) finds
no error, and the distribution marks the packages typed (PEP 561 ``py.typed``)."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_mypy_clean_on_the_typed_api():
    done = subprocess.run([sys.executable, "-m", "mypy"], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"mypy (make typecheck) failed:\n{done.stdout}{done.stderr}"
    assert done.stdout.startswith("Success: no issues found"), done.stdout


def test_py_typed_markers_are_shipped():
    package_data = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for package in ("sarcli", "orbit"):
        assert (REPO / package / "py.typed").is_file(), f"{package}/py.typed missing"
        assert "py.typed" in package_data.get(package, []), f"{package}: py.typed not in package-data"
