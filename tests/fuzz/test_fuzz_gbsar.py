"""Fuzz the commands that read GB-SAR scans and images: gbsar focus, interfere (scans and images),
polarimetry, info (docs/products.md, "The fuzz suite"; the promises are in tests/fuzz/harness.py)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.harness import COMMANDS, fuzz, fuzz_settings


@fuzz_settings(80)
@given(data=st.data())
def test_fuzz_scan(pristine, data):
    fuzz(pristine, "scan", COMMANDS["scan"], data)


@fuzz_settings(70)
@given(data=st.data())
def test_fuzz_image(pristine, data):
    fuzz(pristine, "image", COMMANDS["image"], data)
