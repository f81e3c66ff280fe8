"""The command modules of ingest, info, simulate, orbit, ati, optical, design and run only parse options,
run a workflow and print its report: no numpy/h5py/scipy/numba/rasterio import in them (``--help`` stays
fast), checked in the source and by importing them in a fresh interpreter."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

CLI = Path(__file__).resolve().parents[2] / "sarcli" / "cli"
MODULES = ["app", "common", "commands/ingest", "commands/info", "commands/simulate", "commands/orbit_cmd",
           "commands/ati", "commands/optical", "commands/design", "commands/run"]
HEAVY = ("numpy", "h5py", "scipy", "numba", "rasterio", "matplotlib")


def _imports(path: Path) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            out.append(node.module)
    return out


def test_no_heavy_imports_in_the_source():
    for m in MODULES:
        bad = [i for i in _imports(CLI / f"{m}.py") if i.split(".")[0] in HEAVY]
        assert not bad, f"sarcli/cli/{m}.py imports {bad}"


def test_processing_is_reached_through_workflows_only():
    """Commands import the workflow registry (sarcli.workflows) lazily, never processing packages."""
    allowed = ("sarcli.cli", "sarcli.errors", "sarcli.config", "sarcli.workflows", "sarcli.io.provenance",
               "sarcli.io.h5common", "orbit.errors", "sarcli")
    for m in MODULES:
        for i in _imports(CLI / f"{m}.py"):
            if i.startswith(("sarcli", "orbit")):
                assert i in allowed or i.startswith("sarcli.cli."), f"sarcli/cli/{m}.py imports {i}"


def test_importing_the_command_modules_loads_no_heavy_package():
    mods = ", ".join("sarcli.cli." + m.replace("/", ".") for m in MODULES if m != "app")
    code = f"import sys, {mods}; print(sorted(set(m.split('.')[0] for m in sys.modules) & set({HEAVY!r})))"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "[]", r.stdout
