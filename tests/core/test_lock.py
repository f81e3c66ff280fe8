"""The pinned tested set (requirements/constraints.txt) and the test-latest report (.ci/test_latest.py)."""

from __future__ import annotations

import importlib.util
import re
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LOCK = REPO / "requirements" / "constraints.txt"


def _report_module():
    spec = importlib.util.spec_from_file_location("test_latest", REPO / ".ci" / "test_latest.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _canon(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def test_every_dependency_is_pinned_exactly():
    """A dependency added to pyproject.toml without `make lock` would install unpinned on a new machine."""
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    # the gpu extra (CuPy and numba-cuda for CUDA) installs only where a GPU is (docs/parallel.md): a CPU
    # environment, where `make lock` runs, cannot hold it, so it is the one extra the lock does not pin
    extras = {k: v for k, v in project["optional-dependencies"].items() if k != "gpu"}
    wanted = list(project["dependencies"]) + [d for ds in extras.values() for d in ds]
    names = {_canon(re.split(r"[<>=!~\[; ]", d, maxsplit=1)[0]) for d in wanted}
    pins = _report_module().read_pins(LOCK.read_text().splitlines())
    assert names - set(pins) == set(), "pyproject dependencies missing from the lock: run make lock"
    for line in LOCK.read_text().splitlines():
        if line and not line.startswith("#"):
            assert re.fullmatch(r"[A-Za-z0-9_.\-]+==[A-Za-z0-9_.+\-]+", line), f"not an exact pin: {line!r}"
    assert "pip" in pins and "setuptools" not in pins and "sarcli" not in pins


def test_version_changes_lists_upgrades_additions_and_removals():
    m = _report_module()
    locked = m.read_pins(["# header", "numpy==2.4.6", "SciPy==1.17.1", "gone==1.0", "-e /src"])
    installed = m.read_pins(["numpy==2.5.0", "scipy==1.17.1", "new_pkg==0.1"])
    assert m.version_changes(locked, installed) == ["  new_pkg: not in the lock -> 0.1", "  numpy: 2.4.6 -> 2.5.0",
                                                    "  gone: 1.0 -> not installed"]


def test_failures_are_read_from_the_junit_report(tmp_path):
    xml = tmp_path / "j.xml"
    xml.write_text(
        '<testsuites><testsuite><testcase classname="tests.orbit.test_geometry" name="test_a"/>'
        '<testcase classname="tests.io.test_x" name="test_b"><failure message="assert 1 == 2&#10;more">'
        "tb</failure></testcase>"
        '<testcase classname="tests.io.test_y" name="test_c"><error message="ImportError: numpy">e</error>'
        "</testcase></testsuite></testsuites>")
    assert _report_module().failures(xml) == ["  tests/io/test_x.py::test_b [failure]: assert 1 == 2",
                                              "  tests/io/test_y.py::test_c [error]: ImportError: numpy"]
