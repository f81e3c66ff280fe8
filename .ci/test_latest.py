"""Run the test suite in the current environment (the newest releases) and report what broke.

Usage (what ``make test-latest`` runs, with the .venv-latest interpreter)::

    python .ci/test_latest.py --lock requirements/constraints.txt [--report FILE] -- PYTEST_ARGS...

Prints, after pytest's own output, a report: every package whose installed version differs from the
lock (locked -> installed), packages the lock does not know, and every failed or erroring test with the
first line of its message. Exit status: pytest's (0 when the newest releases pass).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path


def _canon(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def read_pins(lines: list[str]) -> dict[str, tuple[str, str]]:
    """``name==version`` lines (comments and editable installs skipped) -> {canonical name: (name, version)}."""
    pins = {}
    for line in lines:
        line = line.split("#", 1)[0].strip()
        if "==" in line and not line.startswith("-"):
            name, version = line.split("==", 1)
            pins[_canon(name)] = (name.strip(), version.strip())
    return pins


def version_changes(locked: dict, installed: dict) -> list[str]:
    """Report lines for packages whose installed version is not the locked one."""
    out = []
    for key in sorted(installed):
        name, v = installed[key]
        if key not in locked:
            out.append(f"  {name}: not in the lock -> {v}")
        elif locked[key][1] != v:
            out.append(f"  {name}: {locked[key][1]} -> {v}")
    out += [f"  {locked[k][0]}: {locked[k][1]} -> not installed" for k in sorted(set(locked) - set(installed))]
    return out


def failures(junit_xml: Path) -> list[str]:
    """``nodeid: first line of the message`` for every failed or erroring test case."""
    out = []
    for case in ET.parse(junit_xml).getroot().iter("testcase"):
        for kind in ("failure", "error"):
            el = case.find(kind)
            if el is not None:
                cls = case.get("classname", "").replace(".", "/")
                msg = (el.get("message") or el.text or "").strip().splitlines()
                out.append(f"  {cls}.py::{case.get('name')} [{kind}]: {msg[0][:160] if msg else ''}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lock", type=Path, required=True, help="constraints file of the tested set")
    ap.add_argument("--report", type=Path, help="also write the report to this file")
    ap.add_argument("pytest_args", nargs="*", help="arguments for pytest (after --)")
    args = ap.parse_args(argv)

    freeze = subprocess.run([sys.executable, "-m", "pip", "freeze", "--all", "--exclude-editable"],
                            capture_output=True, text=True, check=True).stdout.splitlines()
    installed = {k: v for k, v in read_pins(freeze).items() if k not in ("sarcli", "setuptools", "wheel")}
    locked = read_pins(args.lock.read_text().splitlines()) if args.lock.is_file() else {}
    with tempfile.TemporaryDirectory() as tmp:
        junit = Path(tmp) / "junit.xml"
        rc = subprocess.call([sys.executable, "-m", "pytest", f"--junitxml={junit}", *args.pytest_args])
        failed = failures(junit) if junit.is_file() else []

    changes = version_changes(locked, installed)
    lines = ["", "=" * 30 + " test-latest report " + "=" * 30,
             f"python {sys.version.split()[0]}; lock {args.lock} ({len(locked)} packages)"]
    lines += [f"{len(changes)} package(s) differ from the lock:"] + (changes or ["  none"])
    if rc == 0:
        lines += ["the suite PASSES with the newest releases: adopt them with",
                  "  make lock LOCK_VENV=.venv-latest && make install && make test   (then commit the lock)"]
    else:
        lines += [f"the suite FAILS with the newest releases (pytest exit {rc}); {len(failed)} test(s) broke:"]
        lines += failed or ["  (no failed test in the report: see pytest's output above)"]
        lines += ["the lock stays as it is; open an issue with this report (docs/dependencies.md)"]
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if args.report:
        args.report.write_text(text)
    return rc


if __name__ == "__main__":
    sys.exit(main())
