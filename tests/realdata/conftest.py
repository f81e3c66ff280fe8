"""The six real RADARSAT-1 blocks of the Vancouver pass and their AGC table (``../shared/data``).

Never copied into the repository. When absent, every test here is skipped with a reason that names the
missing files, and a warning says so in the summary (a skipped real-data test must not look like a pass).
"""

from __future__ import annotations

import warnings

import pytest

# the pass's block table (paths, and the first block's start settled by its AGC alignment and its
# bit-identical overlaps: line 7769, cell 1050) is the benchmark's: one table for both
from bench.bench_rs1_blocks import AGC, BLOCKS


@pytest.fixture(scope="session")
def rs1_pass() -> dict:
    """The blocks' file paths (name -> (data, params, first line, first cell)) and the AGC table; skipped,
    loudly, when any is missing."""
    need = [AGC] + [p for v in BLOCKS.values() for p in v[:2]]
    missing = [str(p) for p in need if not p.is_file()]
    if missing:
        msg = f"REAL DATA ABSENT: {len(missing)} RADARSAT-1 pass file(s) missing, e.g. {missing[0]}"
        warnings.warn(msg, stacklevel=1)
        pytest.skip(msg)
    return {"blocks": BLOCKS, "agc": AGC}


@pytest.fixture(scope="session")
def rs1_raws(rs1_pass) -> dict:
    """Every block read as ``sarcli ingest --matlab DATA --params PARAMS --agc TABLE`` reads it."""
    from sarcli.io.matlab import read_matlab_block

    return {name: read_matlab_block(d, p, agc_path=rs1_pass["agc"], first_line=line, first_cell=cell)
            for name, (d, p, line, cell) in rs1_pass["blocks"].items()}
