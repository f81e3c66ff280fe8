"""The pass's AGC table and where a block sits in it (``sarcli.io.agc_table``), on synthetic blocks cut
from a synthetic pass: an attenuation table of 1 dB steps every few dozen lines, a block of complex
Gaussian echoes with a slowly varying scene power, attenuated line by line (output step g dB per dB)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.io
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import FormatError
from sarcli.io import agc_table


def _pass(rng: np.random.Generator, n: int = 3000) -> np.ndarray:
    steps = np.zeros(n)
    idx = np.sort(rng.choice(np.arange(5, n), size=n // 60, replace=False))
    steps[idx] = rng.choice([-1.0, 1.0], size=idx.size)
    return 12.0 + np.cumsum(steps)


def _block(table: np.ndarray, start: int, n: int, rng: np.random.Generator, gain: float = 0.7) -> np.ndarray:
    scene_db = 3.0 * np.sin(np.arange(n) / 90.0)  # a scene that changes over hundreds of lines
    amp = 10 ** ((scene_db - gain * table[start:start + n]) / 20)
    x = rng.standard_normal((n, 2048)) + 1j * rng.standard_normal((n, 2048))
    return (x * amp[:, None]).astype(np.complex64)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31), start=st.integers(0, 3000 - 400))
def test_the_block_is_found_where_it_was_cut(seed, start):
    rng = np.random.default_rng(seed)
    table = _pass(rng)
    if np.count_nonzero(np.diff(table[start:start + 400])) < 5:
        return  # too few steps in this stretch to place a block: covered by the next test
    al = agc_table.align(_block(table, start, 400, rng), table)
    assert al.best == start and agc_table.check_start(al, start) == "confirmed"
    # on its own the table picks a start only when no other comes within a factor 2 (a stretch whose
    # steps repeat at another offset is not singled out): never a wrong one
    assert agc_table.best_start(al) in (start, None)
    assert al.gain[start] == pytest.approx(0.7, abs=0.1)  # the output dB per input dB put in


def test_a_wrong_start_is_contradicted_and_a_flat_table_cannot_place():
    rng = np.random.default_rng(1)
    table = _pass(rng)
    al = agc_table.align(_block(table, 1000, 400, rng), table)
    assert agc_table.best_start(al) == 1000 and agc_table.check_start(al, 1500) == "contradicted"
    assert al.log_likelihood_ratio(1000, 1500) > 50
    flat = np.full(3000, 10.0)
    al = agc_table.align(_block(flat, 1000, 400, rng), flat)
    assert np.all(al.z == 0) and agc_table.best_start(al) is None and agc_table.check_start(al, 7) == "undecided"


def test_table_files_are_read_or_refused_in_one_line(tmp_path):
    scipy.io.savemat(tmp_path / "t.mat", {"nom_attenuation": np.arange(10, dtype=np.uint8)[:, None]})
    np.testing.assert_array_equal(agc_table.read_agc_table(tmp_path / "t.mat"), np.arange(10.0))
    scipy.io.savemat(tmp_path / "two.mat", {"a": np.ones(5), "b": np.ones(5)})
    with pytest.raises(FormatError, match="no AGC variable 'nom_attenuation'"):
        agc_table.read_agc_table(tmp_path / "two.mat")
    scipy.io.savemat(tmp_path / "img.mat", {"nom_attenuation": np.ones((4, 4))})
    with pytest.raises(FormatError, match="not a 1-D numeric table"):
        agc_table.read_agc_table(tmp_path / "img.mat")
    (tmp_path / "junk.mat").write_bytes(b"not a mat file at all" * 10)
    with pytest.raises(FormatError, match="not a readable MATLAB AGC table"):
        agc_table.read_agc_table(tmp_path / "junk.mat")
    with pytest.raises(FormatError, match="fewer than the block"):
        agc_table.align(np.ones((20, 4), np.complex64), np.ones(10))
