"""Benchmark helpers: timing (best of n, compilation excluded), peak memory, result files."""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from sarcli.memory import peak_rss_bytes  # noqa: F401  (re-exported: what the benchmarks report)

RESULTS = Path(__file__).parent / "results"


def best_time(fn: Callable[[], Any], repeat: int = 3, warmup: int = 1) -> float:
    """Best wall time (s) of ``repeat`` calls after ``warmup`` calls (numba compiles in the warm-up)."""
    for _ in range(warmup):
        fn()
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def first_call_time(fn: Callable[[], Any]) -> float:
    """Wall time of one call (use on a fresh kernel to report compilation separately)."""
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def markdown_table(headers: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    def fmt(v: Any) -> str:
        if isinstance(v, float):
            return f"{v:.4g}"
        return str(v)

    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(fmt(v) for v in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def write_results(name: str, markdown: str, data: Any) -> None:
    """Write ``bench/results/<name>.md`` and ``.json`` and echo the markdown."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / f"{name}.md").write_text(markdown)
    (RESULTS / f"{name}.json").write_text(json.dumps(data, indent=2, default=float) + "\n")
    print(markdown)
