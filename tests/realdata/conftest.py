"""The six real RADARSAT-1 blocks of the Vancouver pass and their AGC table (``../shared/data``).

Never copied into the repository. When absent, every test here is skipped with a reason that names the
missing files, and a warning says so in the summary (a skipped real-data test must not look like a pass).
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SARCLI_SHARED", REPO.parent / "shared")) / "data"
BLOCKS_DIR = DATA / "rs1_vancouver_blocks"
AGC = BLOCKS_DIR / "AGC_attenuation_values.mat"
#: name -> (data, params, first line, first cell) as the bench reads them (the first block's start is
#: settled by its AGC alignment and its bit-identical overlaps: line 7769, cell 1050)
BLOCKS = {
    "coal_ferry_terminals": (BLOCKS_DIR / "coal_ferry_terminals.mat",
                             BLOCKS_DIR / "coal_ferry_terminals_run_params.mat", None, None),
    "vancouver_airport": (BLOCKS_DIR / "vancouver_airport.mat", BLOCKS_DIR / "vancouver_airport_run_params.mat",
                          None, None),
    "ubc_one_ship": (BLOCKS_DIR / "ubc_one_ship.mat", BLOCKS_DIR / "ubc_one_ship_run_params.mat", None, None),
    "stanley_park_city": (BLOCKS_DIR / "stanley_park_city.mat", BLOCKS_DIR / "stanley_park_city_run_params.mat",
                          None, None),
    "block1": (DATA / "rs1_vancouver_block1.mat", DATA / "rs1_vancouver_run_params.mat", 7769, 1050),
    "squamish_garibaldi": (BLOCKS_DIR / "squamish_garibaldi.mat", BLOCKS_DIR / "squamish_garibaldi_run_params.mat",
                           None, None),
}


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
