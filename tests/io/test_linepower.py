"""Line power per range group (numba, one pass) against plain numpy in float64."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import SarcliError
from sarcli.io.linepower import FLOOR_DB, group_power, line_power_db


def _reference(echo, edges):
    z = echo.astype(np.complex128)
    groups = zip(edges[:-1], edges[1:], strict=True)
    return np.stack([np.mean(np.abs(z[:, a:b]) ** 2, axis=1) for a, b in groups], axis=1)


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 40), st.integers(1, 300), st.integers(1, 6), st.integers(0, 2**31))
def test_group_power_matches_numpy(n_lines, n_samples, n_groups, seed):
    rng = np.random.default_rng(seed)
    echo = (rng.standard_normal((n_lines, n_samples)) + 1j * rng.standard_normal((n_lines, n_samples))).astype(
        np.complex64) * np.float32(10.0 ** rng.uniform(-3, 3))
    cuts = np.unique(rng.integers(1, n_samples, n_groups - 1)) if n_samples > 1 else np.zeros(0, np.int64)
    edges = np.r_[0, cuts, n_samples]
    # the same float32 parts squared and summed in float64 both ways: only the summation order differs
    # (relative error <= n eps_64 with n <= 300 terms: 1e-13; 1e-12 leaves a margin)
    np.testing.assert_allclose(group_power(echo, edges), _reference(echo, edges), rtol=1e-12)


def test_line_power_db_of_a_zero_line_and_a_strided_view():
    echo = np.ones((3, 10), np.complex128) * 2.0
    echo[1] = 0.0
    got = line_power_db(echo[:, ::2])  # a strided complex128 view: copied to contiguous complex64
    np.testing.assert_allclose(got, [10 * np.log10(4.0), FLOOR_DB, 10 * np.log10(4.0)])


@pytest.mark.parametrize("edges", [[0], [0, 0, 5], [1, 11], [0, 6, 4, 10], [-1, 10]])
def test_group_power_refuses_bad_groups(edges):
    with pytest.raises(SarcliError, match="range groups"):
        group_power(np.zeros((2, 10), np.complex64), edges)
