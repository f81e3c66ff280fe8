"""Fuzz the commands that read a raw product: doppler, focus (estimating the Doppler: the echo read in
memory, and streamed with --fdc/--fr or --doppler), orbit info, info (docs/products.md, "The fuzz suite"), damage to
/truth included (processing never reads it; quality and info check it). Every corrupted input gives
exit 0 with a plausible product or exactly one error line, never a traceback or a hang, the input bytes
unchanged, no partial output (tests/fuzz/harness.py).

Derandomized: the same cases every run. More: ``SARCLI_FUZZ_EXAMPLES=2000``; new ones:
``HYPOTHESIS_PROFILE=explore`` (the exploration run: test_fuzz_explore.py).
"""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.harness import COMMANDS, fuzz, fuzz_settings


@fuzz_settings(180)
@given(data=st.data())
def test_fuzz_raw(pristine, data):
    fuzz(pristine, "raw", COMMANDS["raw"], data)
