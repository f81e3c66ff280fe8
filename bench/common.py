"""Benchmark helpers: timing (best of n, compilation excluded), peak memory, result files."""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from sarcli.memory import peak_rss_bytes  # noqa: F401  (re-exported: what the benchmarks report)

RESULTS = Path(__file__).parent / "results"
#: the sarcli console script of the environment running the benchmark
SARCLI = str(Path(sys.executable).parent / "sarcli")
#: the real data beside the repository (../shared/data, or $SARCLI_SHARED/data)
SHARED = Path(os.environ.get("SARCLI_SHARED", Path(__file__).resolve().parents[2] / "shared")) / "data"
#: a full Radarsat-1 fine-beam scene's size (lines, samples)
FULL_SCENE = (23000, 6354)


def tiled_real_block(path: Path, shape: tuple[int, int] = FULL_SCENE, orbit_of: Path | None = None) -> float:
    """Write the real Vancouver raw block (``rs1_vancouver_block1.mat``, 1536 x 2048) tiled to ``shape`` as a
    raw product at ``path`` (azimuth times continued at the PRF): a full scene's size with real echoes (the
    tile seams are line-power jumps). The block has no orbit; ``orbit_of``, a raw product, lends its orbit,
    attitude, epoch and look side (times centred on its epoch) so that the scene can be map-projected:
    real pixels on a borrowed geometry, for products' costs only. Returns the echo's size in GiB."""
    import dataclasses

    import numpy as np

    from sarcli.io.matlab import read_matlab_block
    from sarcli.io.raw import read_raw, write_raw

    raw = read_matlab_block(SHARED / "rs1_vancouver_block1.mat", SHARED / "rs1_vancouver_run_params.mat")
    n, m = shape
    reps = (-(-n // raw.echo.shape[0]), -(-m // raw.echo.shape[1]))
    echo = np.ascontiguousarray(np.tile(raw.echo, reps)[:n, :m], np.complex64)
    times = raw.azimuth_time[0] + np.arange(n) / raw.radar.prf_hz
    if orbit_of is not None:
        lend = read_raw(orbit_of, load_echo=False)
        raw = dataclasses.replace(raw, orbit=lend.orbit, attitude=lend.attitude, epoch_utc=lend.epoch_utc,
                                  look_side=lend.look_side)
        times = (np.arange(n) - n / 2) / raw.radar.prf_hz
    write_raw(path, dataclasses.replace(raw, echo=echo, azimuth_time=times))
    return echo.nbytes / 2**30


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
