"""Run every benchmark module ``bench/bench_*.py`` (each has ``main()``), in name order.

Each benchmark writes its own table to ``bench/results/<name>.md`` (and ``.json``); then
``docs/validation.md`` is rewritten from them (:mod:`bench.validation`). Pass module names to run a
subset: ``python -m bench.run_all bench_orbit``.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
import time

import bench


def main(argv: list[str]) -> int:
    names = sorted(m.name for m in pkgutil.iter_modules(bench.__path__) if m.name.startswith("bench_"))
    if argv:
        names = [n for n in names if n in argv]
    for name in names:
        t0 = time.perf_counter()
        print(f"== {name}", flush=True)
        importlib.import_module(f"bench.{name}").main()
        print(f"== {name} done in {time.perf_counter() - t0:.1f} s", flush=True)
    from bench.validation import main as write_validation

    return write_validation([])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
