"""docs/validation.md is generated from bench/results (measured accuracy is not hand-copied)."""

from __future__ import annotations

from bench.validation import PAGE, render


def test_the_page_is_what_the_results_give():
    assert PAGE.read_text(encoding="utf-8") == render(), "run: python -m bench.validation"


def test_every_result_with_a_table_has_a_section(tmp_path):
    (tmp_path / "bench_x.md").write_text("# X bench\n\nRun 2026-01-01.\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\nmore\n")
    (tmp_path / "bench_y.md").write_text("# no table here\n")
    text = render(tmp_path)
    assert "## x: X bench" in text and "| 1 | 2 |" in text and "Run 2026-01-01." in text
    assert "## y" not in text
