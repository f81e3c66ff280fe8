"""Fuzz ``sarcli ingest`` on damaged CEOS folders, and the SLC and interferogram readers on damaged
products (the commands that read SLCs are fuzzed in test_fuzz_cases.py). The promises:
tests/fuzz/harness.py."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from sarcli.io.interferogram import read_interferogram
from sarcli.io.slc import read_slc
from tests.fuzz.harness import COMMANDS, corruptions, fuzz, fuzz_settings, run_reader_case


@fuzz_settings(100)
@given(data=st.data())
def test_fuzz_ceos_ingest(pristine, data):
    fuzz(pristine, "ceos", COMMANDS["ceos"], data)


@fuzz_settings(45)
@given(data=st.data())
def test_fuzz_read_slc(pristine, data):
    slc = run_reader_case(pristine.paths["slc"], data.draw(corruptions(pristine, "slc")), read_slc)
    if slc is not None:  # what it returns is what quality, geocoding and info may trust
        assert slc.image.shape == (slc.azimuth_time.size, slc.slant_range.size)
        for a in (slc.image, slc.azimuth_time, slc.slant_range, slc.doppler.fdc_hz, slc.doppler.fr_hz_per_s):
            assert np.all(np.isfinite(a))
        assert np.all(np.diff(slc.azimuth_time) > 0) and np.all(np.diff(slc.slant_range) > 0)
        assert slc.slant_range[0] > 0 and 1.0 <= slc.radar.prf_hz <= 1e6


@fuzz_settings(35)
@given(data=st.data())
def test_fuzz_read_interferogram(pristine, data):
    d = run_reader_case(pristine.paths["ifg"], data.draw(corruptions(pristine, "ifg")), read_interferogram)
    if d is not None:
        grid = (d["range"].size, d["azimuth"].size)
        assert all(d[k].shape == grid for k in ("phase", "coherence", "model_phase", "residual_phase", "value"))
        c = d["coherence"][np.isfinite(d["coherence"])]
        assert np.all((c >= -1e-6) & (c <= 1 + 1e-6)) and isinstance(d["rate"], dict)
