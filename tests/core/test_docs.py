"""The manuals run as written: every relative link and image of README.md and docs/*.md resolves (with its
``#anchor``), and every ``sarcli`` command of their shell blocks either runs, exit 0, in order, in a scratch
folder holding ``samples/`` (what a new user has after cloning), or is named in :data:`SKIP` with the reason
it cannot run in CI (instruments, real data not in the repository, a user's own file, a server).

A command is a line of a fenced ``sh`` block, or of an unlabelled block whose lines start with ``sarcli``
(``\\`` continuations joined, ``#`` comments dropped, ``a && b`` two commands); ``mkdir -p`` lines are
run too. Its globs are expanded in the
scratch folder, as a shell would. Each manual is one test case, its commands run in-process (the ``cli``
fixture), one after the other: a command that needs an earlier one's output finds it.
"""

from __future__ import annotations

import glob
import os
import re
import shlex
from pathlib import Path

import pytest

from tests.conftest import REPO, run_cli

MANUALS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]

#: (pattern searched in the command, why it does not run in CI); every pattern must match some command
SKIP: list[tuple[str, str]] = [
    (r"/dev/tty|\$\(port |focus scan\.h5", "needs the VNA and the rail (tests/acquire and "
                                           "tests/monitor/test_e2e_emulator.py run these on emulated ones)"),
    (r"gbsar emulate --json", "starts the emulated instruments in the background (tests/acquire, tests/monitor)"),
    (r"gbsar serve", "a web server that runs until stopped (tests/monitor/test_page.py serves the page)"),
    (r"\.\./shared/data|\$B/|gotcha\.h5", "real data outside the repository (tests/realdata, tests/nisar, tests/gbsar/"
                               "test_gotcha.py read it through the shared_data fixture)"),
    (r"S1A_\.\.\.|ALOS_L0B\.h5|ALPSRP\d+|block\.mat|\bvan\.h5|\bsp\.h5|\balos(_slc|_rslc)?\.h5",
     "a real scene the user has (the manuals' real-data sections)"),
    (r"srtm\.tif", "a DEM of the user's site (tests/focus/test_terrain.py)"),
    (r"\bCR\.csv", "the surveyed reflectors of the user's site (tests/nisar/test_calibration.py)"),
    (r"sweeps\.npz|rail\.npz|stop_\*\.s2p|gpr\.h5", "the user's own phase histories (tests/gbsar/test_import*.py)"),
    (r"\bscenes/|tcp://host|coherence '?scans/", "a folder of the user's scenes or scans, a Dask cluster "
                                                "(tests/parallel/test_batch.py, test_gbsar_parallel.py)"),
    (r"\bcampaign/", "the campaign the emulated instruments acquire above (tests/monitor/test_e2e_emulator.py "
                     "runs these commands)"),
    (r"\bbig(_raw)?\.h5", "a full-size scene (bench/bench_parallel.py)"),
    (r"ingest demo/ceos -o ceos_raw\.h5", "README's line for a user's CEOS folder (docs/ingest.md makes and "
                                           "ingests one)"),
    (r"demo/amplitude\.tif", "a GeoTIFF of the user's (docs/ingest.md: any GeoTIFF)"),
    (r"ati montecarlo|orbit accuracy|--algorithm backprojection",
     "minutes of computation (bench/; tests/ati, tests/orbit, tests/focus test the same code on small inputs)"),
    (r"--format s1-l0", "7-17 s of simulation (tests/sentinel1/test_simulate_l0.py)"),
    (r"--device cuda", "needs a CUDA GPU and the gpu extra (tests/gpu runs the same code under numba's CUDA "
                       "simulator)"),
    (r"interfere t\d\.h5 t\d\.h5", "focuses two outdoor scans first: 15-25 s each alone, minutes on a shared CI "
                                   "machine (README's `gbsar interfere t1_img.h5 t2_img.h5` runs; "
                                   "tests/gbsar/test_interferometry.py)"),
]

_LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_FENCE = re.compile(r"^```(\w*)\s*$")


def _prose(text: str) -> str:
    """The text without fenced blocks and inline code (where brackets are code, not links)."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def _anchors(path: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces to hyphens."""
    heads = re.findall(r"^#+\s+(.*?)\s*$", _prose(path.read_text(encoding="utf-8")), flags=re.M)
    return {re.sub(r"[^\w\- ]", "", h.lower()).replace(" ", "-") for h in heads}


@pytest.mark.parametrize("manual", MANUALS, ids=lambda p: p.name)
def test_links_and_images_resolve(manual):
    broken = []
    for m in _LINK.finditer(_prose(manual.read_text(encoding="utf-8"))):
        target = m.group(1)
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        name, _, anchor = target.partition("#")
        path = (manual.parent / name).resolve() if name else manual
        if not path.exists():
            broken.append(f"{target}: no such file")
        elif anchor and path.suffix == ".md" and anchor not in _anchors(path):
            broken.append(f"{target}: no heading '#{anchor}' in {path.name}")
    assert not broken, f"{manual.name}: {broken}"


def commands(manual: Path) -> list[tuple[int, str]]:
    """(line number, command) of every ``sarcli`` command in the manual's shell blocks (module docstring)."""
    lines = manual.read_text(encoding="utf-8").split("\n")
    out: list[tuple[int, str]] = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while not lines[j].startswith("```"):
            j += 1
        body = lines[i + 1:j]
        if m.group(1) == "sh" or (m.group(1) == "" and any(x.startswith("sarcli ") for x in body)):
            k = 0
            while k < len(body):
                start, text = i + 2 + k, body[k]
                while text.rstrip().endswith("\\") and k + 1 < len(body):
                    k += 1
                    text = text.rstrip()[:-1] + " " + body[k].strip()
                k += 1
                words = shlex.split(text, comments=True) if re.search(r"sarcli|^mkdir -p ", text) else []
                for part in " ".join(shlex.quote(w) if w != "&&" else w for w in words).split(" && "):
                    while part and re.match(r"^[A-Z_]+=\S+ ", part):  # VAR=value sarcli ...
                        part = part.split(" ", 1)[1]
                    if part.startswith(("sarcli ", "mkdir -p ")):
                        out.append((start, part))
        i = j + 1
    return out


def _skipped(command: str) -> str | None:
    return next((why for pattern, why in SKIP if re.search(pattern, command)), None)


def test_every_skip_reason_is_used():
    """No stale entry: each pattern of SKIP matches a command of the manuals."""
    every = [c for manual in MANUALS for _, c in commands(manual) if c.startswith("sarcli ")]
    assert every and all(any(re.search(p, c) for c in every) for p, _ in SKIP), [
        p for p, _ in SKIP if not any(re.search(p, c) for c in every)]


@pytest.mark.slow
@pytest.mark.parametrize("manual", [m for m in MANUALS if any(c.startswith("sarcli ") and not _skipped(c)
                                                               for _, c in commands(m))],
                         ids=lambda p: p.name)
def test_the_manuals_commands_run(manual, tmp_path, monkeypatch):
    """Each command not in SKIP runs, exit 0, in the order of the manual, in a folder holding samples/."""
    (tmp_path / "samples").symlink_to(REPO / "samples")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    ran = 0
    for line, command in commands(manual):
        if _skipped(command):
            continue
        if command.startswith("mkdir -p "):
            for folder in shlex.split(command)[2:]:
                os.makedirs(folder, exist_ok=True)
            continue
        args: list[str] = []
        for word in shlex.split(command)[1:]:
            matches = sorted(glob.glob(word)) if any(ch in word for ch in "*?[") else []
            args.extend(matches or [word])
        r = run_cli(*args)
        assert r.exit_code == 0, f"{manual.name} line {line}: {command}\n{r.stderr}"
        ran += 1
    assert ran > 0
