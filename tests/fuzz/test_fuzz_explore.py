"""The fuzz exploration run: every (damaged product, command) pair, CI's and the costly ones, with new
random cases each run. Skipped unless asked for:

    SARCLI_FUZZ_EXPLORE=1 SARCLI_FUZZ_EXAMPLES=2000 HYPOTHESIS_PROFILE=explore \\
        .venv/bin/python -m pytest -q -n 2 tests/fuzz/test_fuzz_explore.py

(about 0.2 s a case and core: 2000 cases a pair is about an hour). A failure prints the case
(product, corruption, command); a new one that is a defect of the readers gets a regression test in
tests/io/test_reader_checks.py, one elsewhere an entry in test_fuzz_cases.py.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.harness import COMMANDS, EXPLORE_ONLY, fuzz, fuzz_settings

PAIRS = [(product, commands) for table in (COMMANDS, EXPLORE_ONLY) for product, commands in table.items()]


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("SARCLI_FUZZ_EXPLORE"),
                    reason="exploration run: set SARCLI_FUZZ_EXPLORE=1 (tests/fuzz/test_fuzz_explore.py)")
@pytest.mark.parametrize("product, commands", PAIRS, ids=[f"{p}-{c[0][0]}-{i}" for i, (p, c) in enumerate(PAIRS)])
def test_fuzz_explore(pristine, product, commands):
    @settings(fuzz_settings(2000), derandomize=os.environ.get("HYPOTHESIS_PROFILE") != "explore")
    @given(data=st.data())
    def explore(data):
        fuzz(pristine, product, commands, data)

    explore()
