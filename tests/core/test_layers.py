"""The import graph flows one way (docs/architecture.md):

    cli -> workflows -> processing -> io, model -> orbit

with the base modules (errors, config, registry, threads) usable from every layer. A module may import its own
layer and the layers below; ``model`` may not import ``io``; ``orbit`` imports nothing of sarcli. Every
``import`` statement counts, also those inside functions (a lazy import is still a dependency).
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

BASE = {"sarcli", "sarcli.errors", "sarcli.config", "sarcli.registry", "sarcli.threads", "sarcli.versions",
        "sarcli.memory"}
PROCESSING = {"doppler", "focus", "ati", "gbsar", "sim", "optical", "design", "acquire", "monitor", "calibration",
              "gpu"}
#: sarcli.parallel sits beside the workflows (it runs them as Dask tasks, they call it for block-parallel focus)
RANK = {"orbit": 0, "model": 1, "io": 2, "processing": 3, "workflows": 4, "parallel": 4, "cli": 5}


def _layer(module: str) -> str | None:
    """The layer of a module name (None: a base module or outside the project)."""
    parts = module.split(".")
    if parts[0] == "orbit":
        return "orbit"
    if parts[0] != "sarcli" or module in BASE:
        return None
    sub = parts[1]
    if sub in PROCESSING:
        return "processing"
    if sub in RANK:
        return sub
    raise AssertionError(f"{module}: sarcli.{sub} has no layer in docs/architecture.md")


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path: Path, name: str) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolve against the package
                base = name.split(".")
                if not path.name == "__init__.py":
                    base = base[:-1]
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.append((node.lineno, mod))
    return out


def _edges():
    for pkg in ("sarcli", "orbit"):
        for path in sorted((ROOT / pkg).rglob("*.py")):
            name = _module_name(path)
            for line, target in _imports(path, name):
                yield path, line, name, target


def test_no_import_goes_up_a_layer():
    bad = []
    for path, line, src, dst in _edges():
        a, b = _layer(src), _layer(dst)
        if a is None or b is None:
            if a == "orbit" and dst.split(".")[0] == "sarcli":
                bad.append(f"{path.relative_to(ROOT)}:{line}: orbit imports {dst}")
            continue
        if RANK[b] > RANK[a]:
            bad.append(f"{path.relative_to(ROOT)}:{line}: {a} module {src} imports {b} module {dst}")
        if a == "model" and b == "io":
            bad.append(f"{path.relative_to(ROOT)}:{line}: model imports io ({dst})")
    assert bad == [], "\n".join(bad)


def test_base_modules_import_no_layer():
    bad = []
    for path, line, src, dst in _edges():
        if src in BASE and src != "sarcli" and _layer(dst) is not None:
            bad.append(f"{path.relative_to(ROOT)}:{line}: base module {src} imports {dst}")
    assert bad == [], "\n".join(bad)


def test_the_walker_sees_an_upward_edge(tmp_path):
    """The check can fail: an io module importing a workflow is an upward edge."""
    assert RANK[_layer("sarcli.workflows.focus")] > RANK[_layer("sarcli.io.raw")]
    assert _layer("sarcli.doppler.cde") == "processing" and _layer("sarcli.errors") is None
    f = tmp_path / "m.py"
    f.write_text("def f():\n    from sarcli.workflows import focus\n")
    assert _imports(f, "sarcli.io.m") == [(2, "sarcli.workflows")]


def test_cli_imports_no_numerical_library():
    """`sarcli --help` stays fast and the CLI stays a thin layer: no numpy, scipy, h5py, numba, rasterio
    or matplotlib import anywhere under sarcli/cli (also not inside functions)."""
    heavy = ("numpy", "scipy", "h5py", "numba", "rasterio", "matplotlib", "pyproj")
    bad = []
    for path in sorted((ROOT / "sarcli" / "cli").rglob("*.py")):
        for line, mod in _imports(path, _module_name(path)):
            if mod.split(".")[0] in heavy:
                bad.append(f"{path.relative_to(ROOT)}:{line}: imports {mod}")
    assert bad == [], "\n".join(bad)
