"""Fuzz the scene files: one number of the tiny SAR or GB-SAR scene replaced by a value of the right type
but no physical meaning (a size of 1e8 or 2e9, a spacing of 1e-9, 1e308, a seed beyond 64 bits, NaN,
zero, negative), then ``simulate`` / ``gbsar simulate``. The promises of tests/fuzz/harness.py hold:
a plausible product, or one ``sarcli: error:`` line, never a traceback. The process's address space is
capped (current size + 4 GiB) while the cases run, so that a size the code forgot to check fails as a
MemoryError traceback (the test fails) instead of taking the machine's memory."""

from __future__ import annotations

import contextlib
import re
import resource
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.harness import TextEdit, check_output, fuzz_settings, run_case

HOSTILE = ("100000000", "2000000000", "1e-9", "1e308", "-1e308", "99999999999999999999", "nan", "inf", "0", "-1",
           "0.0")
_NUMBER_LINE = re.compile(r"^(\w+) = (-?[0-9][0-9_.eE+-]*)\s*$", re.MULTILINE)
COMMANDS = {"rs1_toml": ("simulate", "{IN}", "-o", "{OUT}"), "gbsar_toml": ("gbsar", "simulate", "{IN}", "-o", "{OUT}")}


@contextlib.contextmanager
def _address_space_cap(extra_bytes: int = 4 << 30) -> Iterator[None]:
    with open("/proc/self/status") as f:
        size = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))
    old = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (size + extra_bytes, old[1]))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, old)


@pytest.mark.parametrize("product", sorted(COMMANDS))
def test_fuzz_scene_numbers(pristine, product):
    text = pristine.paths[product].read_text()
    lines = [m.group(0) for m in _NUMBER_LINE.finditer(text)]
    name = pristine.paths[product].name

    @fuzz_settings(40)
    @given(line=st.sampled_from(lines), value=st.sampled_from(HOSTILE))
    def damaged(line, value):
        edit = TextEdit(name, line, f"{line.split(' = ')[0]} = {value}")
        run_case(pristine.paths, product, COMMANDS[product], edit, check_output)

    with _address_space_cap():
        damaged()
