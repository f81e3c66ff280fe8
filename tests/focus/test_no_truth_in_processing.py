"""Processing never reads the simulator's answer (docs/focusing.md): a scan of the processing packages'
sources for reads of ``truth`` (``x.truth[...]``, ``(x.truth or {}).get``, ``truth[...]``,
``truth.get(``) and for the truth's ``reference_height_m``.

Allowed, each named: the quality and validation modules, whose job is to compare with the truth
(``sarcli/focus/quality.py`` and ``sarcli/workflows/quality.py``: ``sarcli quality``;
``sarcli/optical/compare.py``: ``sarcli optical compare`` against the truth targets;
``sarcli/ati/montecarlo.py``: the Monte-Carlo accuracy of the ATI estimates against the truth;
``sarcli/doppler/plot.py``: the ``--plot`` picture draws a simulated product's truth beside the estimate).
The simulators write the truth (``sarcli/sim``, ``sarcli/gbsar/simulate.py``) and do not read it
back; products copy it through (``truth=raw.truth``) without looking inside.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

SARCLI = Path(__file__).resolve().parents[2] / "sarcli"
PACKAGES = ("doppler", "focus", "ati", "gbsar", "optical", "workflows")
ALLOWED = {"focus/quality.py", "workflows/quality.py", "optical/compare.py", "ati/montecarlo.py", "ati/evaluation.py",
           "doppler/plot.py"}
READS = re.compile(r"\.truth\b[^\n]*?(\[|\.get\()|\btruth\s*\[|\btruth\.get\(|reference_height_m")


def _offenders(package: str) -> list[str]:
    out = []
    for path in sorted((SARCLI / package).rglob("*.py")):
        rel = path.relative_to(SARCLI).as_posix()
        if rel in ALLOWED:
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if READS.search(line.split("#")[0]):
                out.append(f"{rel}:{n}: {line.strip()}")
    return out


@pytest.mark.parametrize("package", PACKAGES)
def test_processing_does_not_read_the_truth(package):
    assert _offenders(package) == []


def test_the_scan_finds_a_read():
    assert READS.search('h = float(raw.truth["reference_height_m"])')
    assert READS.search('tab = (raw.truth or {}).get("targets")')
    assert READS.search("x = truth.get('targets')")
    assert not READS.search("truth=raw.truth, orbit=raw.orbit")
