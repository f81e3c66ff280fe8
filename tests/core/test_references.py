"""Every citation key resolves to an entry of docs/references.md, and no internal planning reference
(the old paper nicknames, contract or issue numbers of the project's history) is left in the code.

Key syntax. docs/references.md defines a key by an entry that starts a line with ``**[Key]**``. In the
code and docs a citation is ``[Key]`` or ``[Key, locator]`` (``[Koh2003, eq. 6]``,
``[LeeGBSAR-II-2007, Table 1]``, ``[S1-ISP, §3.2.5.7]``) where

- ``Key`` is a capital letter followed by at least one letter or digit, optionally followed by
  hyphen-joined alphanumeric parts (``Koh2003``, ``KimAODCCD``, ``NGA-SICD``, ``RSI-GS-026``);
- the ``[`` does not follow a letter, digit, ``_``, ``.``, ``]``, ``)`` or ``\\`` (indexing such as
  ``a[Key]`` or ``x.y[Key]``), and the ``]`` is not followed by ``(`` or ``[`` (Markdown links);
- in Python files only comments and string literals (docstrings, help texts) are read, so code such as
  ``[True, False]`` is not a citation.

Such a bracket counts as a citation when it carries a locator, or when its key contains a digit, a
hyphen, or a lower-case letter followed by a capital (CamelCase such as ``KimAODCCD``). What remains, a
single word in capitals or Capitalized (``[NAME]`` placeholders, ``[MHz]`` units, regex classes such as
``[HV]``), is indistinguishable from a key such as ``[PROJ]`` and is only counted when references.md
defines it. Lower-case brackets (option lists ``[nisar-rslc|sicd]``, TOML tables ``[scene]``) are never
citations; one-letter labels (``[A]``, ``[S]``) are a module's own legend, defined in its docstring.
"""

from __future__ import annotations

import io
import re
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
REFERENCES = ROOT / "docs" / "references.md"

KEY = r"[A-Z][A-Za-z0-9]+(?:-[A-Za-z0-9]+)*"
CITATION = re.compile(r"(?<![\w.\])\\])\[(" + KEY + r")(, [^\]\n]+)?\](?![(\[])")
ENTRY = re.compile(r"^\*\*\[([^\]\n]+)\]\*\*", re.M)
CHECKED_BARE = re.compile(r"[0-9-]|[a-z][A-Z]")

CODE_DIRS = ("sarcli", "orbit", "bench")
# Planning references: the papers' old nicknames, the digest of them, contract and issue numbers.
# A document's own issue (a revision, "S1-IF-ASD-PL-0007 issue 13") follows a document number or the
# word "document" and is allowed.
PLANNING = re.compile(
    r"\bseeds? 0\d\d\b|\bseed-0\d\d\b|\bseed (?:eq|§|section|sec\.|Fig|Table|paper)|\bthe seed's\b"
    r"|\bthe digest\b|\bdigest's\b|\bdigest §|\bcontracts? \d+|(?<!document )(?<!\d )\bissues? \d+\b",
    re.I,
)


def defined_keys(text: str | None = None) -> set[str]:
    return set(ENTRY.findall(REFERENCES.read_text(encoding="utf-8") if text is None else text))


def _python_text(path: Path) -> list[tuple[int, str]]:
    out = []
    string_like = {tokenize.STRING, tokenize.COMMENT, getattr(tokenize, "FSTRING_MIDDLE", -1)}
    for tok in tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline):
        if tok.type in string_like:
            out.append((tok.start[0], tok.string))
    return out


def _texts(path: Path) -> list[tuple[int, str]]:
    if path.suffix == ".py":
        return _python_text(path)
    return list(enumerate(path.read_text(encoding="utf-8").splitlines(), 1))


def citation_sources() -> list[Path]:
    files = [p for d in CODE_DIRS for p in sorted((ROOT / d).rglob("*.py"))]
    files += sorted((ROOT / "bench" / "results").glob("*.md"))
    files += sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]
    return [p for p in files if p.is_file()]


def keys_in(text: str, defined: set[str]) -> list[tuple[int, str]]:
    """(offset, key) of every citation in ``text`` under the syntax of the module docstring."""
    return [(m.start(), m.group(1)) for m in CITATION.finditer(text)
            if m.group(2) or CHECKED_BARE.search(m.group(1)) or m.group(1) in defined]


def citations(path: Path, defined: set[str]) -> list[tuple[int, str]]:
    """(line, key) of every citation in ``path``."""
    return [(line + text.count("\n", 0, offset), key)
            for line, text in _texts(path) for offset, key in keys_in(text, defined)]


def unresolved(defined: set[str]) -> list[str]:
    return [f"{p.relative_to(ROOT)}:{line}: [{key}]" for p in citation_sources()
            for line, key in citations(p, defined) if key not in defined]


def test_the_key_syntax_on_examples():
    text = ("see [Koh2003, eq. 6] and [KimAODCCD]; ([S1-ISP, §3.2]) [NGA-SICD] [PROJ] [NAME] [MHz] [HV] "
            "a[Koh2003] x.y[Ryu2017] [Link](http://x) [Text][ref] [nisar-rslc|sicd] [scene] [A] [X, Y]")
    keys = [key for _, key in keys_in(text, {"PROJ"})]
    assert keys == ["Koh2003", "KimAODCCD", "S1-ISP", "NGA-SICD", "PROJ"]


def test_every_citation_resolves_to_an_entry_of_references_md():
    defined = defined_keys()
    assert len(defined) > 50, "docs/references.md lost its entries"
    bad = unresolved(defined)
    assert not bad, "citations without an entry in docs/references.md:\n" + "\n".join(bad)


@pytest.mark.parametrize("key", ["Koh2003", "KimAODCCD", "S1-ISP", "Buck1981"])
def test_removing_an_entry_is_detected(key):
    """The check is not vacuous: without the entry, the key's citations are reported."""
    defined = defined_keys()
    assert key in defined
    bad = unresolved(defined - {key})
    assert any(b.endswith(f"[{key}]") for b in bad)


def test_references_md_defines_each_key_once():
    keys = ENTRY.findall(REFERENCES.read_text(encoding="utf-8"))
    duplicates = sorted({k for k in keys if keys.count(k) > 1})
    assert not duplicates, f"keys defined more than once in docs/references.md: {duplicates}"


def test_no_internal_planning_reference_in_code():
    files = [p for d in (*CODE_DIRS, "tests", "samples") for p in sorted((ROOT / d).rglob("*"))
             if p.suffix in (".py", ".toml") and p.resolve() != Path(__file__).resolve()]
    bad = []
    for p in files:
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1):
            m = PLANNING.search(line)
            if m:
                bad.append(f"{p.relative_to(ROOT)}:{n}: {m.group(0)!r}: {line.strip()[:100]}")
    assert not bad, ("internal planning references (cite [Key, locator] or point to the docs page):\n"
                     + "\n".join(bad))


@pytest.mark.parametrize("line, planning", [
    ("(seed 002 eq. 4)", True), ("Seed 003 Table 2", True), ("the seed's closed form", True),
    ("(issue 13 §4)", True), ("(contract 4)", True), ("the digest's typo", True),
    ("S1-IF-ASD-PL-0007 issue 13", False), ("the document issue 12", False),
    ("the seed is part of the scene", False), ("seed route (look angle)", False), ("hexdigest()", False),
])
def test_the_planning_pattern_on_examples(line, planning):
    assert bool(PLANNING.search(line)) is planning
