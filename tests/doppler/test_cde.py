"""CDE / SDE kernels against plain numpy and against synthetic signals of known centroid."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.doppler.cde import block_correlation, block_correlation_numpy, block_edges, combine, wrap_frequency
from sarcli.errors import SarcliError
from tests.doppler.synth import azimuth_process, quantize_4bit

PRF = 1256.98


@settings(max_examples=25, deadline=None)
@given(n_lines=st.integers(2, 40), n_samples=st.integers(1, 30), az=st.integers(1, 50), rg=st.integers(1, 40),
       est=st.sampled_from(["cde", "sde"]), lag=st.integers(1, 3), seed=st.integers(0, 2**31))
def test_kernel_matches_numpy_reference(n_lines, n_samples, az, rg, est, lag, seed):
    rng = np.random.default_rng(seed)
    h = (rng.standard_normal((n_lines, n_samples)) + 1j * rng.standard_normal((n_lines, n_samples))).astype(
        np.complex64)
    h[rng.random(h.shape) < 0.1] = 0  # exact zeros: sign(0) = 0 in both
    if n_lines < lag + 1:
        return
    a = block_correlation(h, az, rg, est, lag)
    b = block_correlation_numpy(h, az, rg, est, lag)
    # float32 sums over one line of a range block (<= 40 products here): ~1e-7 relative to the energy
    assert np.all(np.abs(a.corr - b.corr) <= 1e-6 * b.energy + 1e-12)
    np.testing.assert_allclose(a.energy, b.energy, rtol=1e-6, atol=1e-12)
    np.testing.assert_array_equal(a.pairs, b.pairs)
    assert a.n_lines.sum() == n_lines and a.n_samples.sum() == n_samples
    # the per-pair line energies (of the complex samples, for the SDE too)
    np.testing.assert_allclose(a.line_energy, b.line_energy, rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("est", ["cde", "sde"])
@pytest.mark.parametrize("fdc", [-611.0, -200.0, 0.0, 37.5, 480.0])
def test_recovers_known_centroid(est, fdc):
    rng = np.random.default_rng(7)
    x = azimuth_process(1024, 128, PRF, fdc, bw=0.15 * PRF, rng=rng, snr_db=10)
    bc = combine(combine(block_correlation(x, 1024, 128, est), 0), 1)
    err = wrap_frequency(bc.baseband(PRF)[0, 0] - fdc, PRF)
    # phase std ~ sqrt((1-q^2)/(2 N q^2)); N_eff ~ N / 3 for this bandwidth -> a few Hz
    assert abs(err) < 0.005 * PRF
    assert 0.5 < bc.quality()[0, 0] < 1.0


@pytest.mark.parametrize("fdc", [PRF / 2, -PRF / 2])
def test_centroid_at_exactly_half_prf_wraps(fdc):
    rng = np.random.default_rng(3)
    x = azimuth_process(512, 64, PRF, fdc, bw=0.1 * PRF, rng=rng)
    f = block_correlation(x, 512, 64).baseband(PRF)[0, 0]
    assert -PRF / 2 <= f < PRF / 2
    assert abs(wrap_frequency(f - fdc, PRF)) < 0.01 * PRF


def test_noise_and_zero_blocks_are_flagged_not_used():
    rng = np.random.default_rng(11)
    x = azimuth_process(512, 256, PRF, 300.0, bw=0.1 * PRF, rng=rng)
    x[:, 128:192] = (rng.standard_normal((512, 64)) + 1j * rng.standard_normal((512, 64))).astype(np.complex64)
    x[:, 192:] = 0
    bc = block_correlation(x, 512, 64)
    v = bc.valid()[0]
    assert v.tolist() == [True, True, False, False]
    w = bc.weight()[0]
    assert w[0] > 0 and w[2] == 0 and w[3] == 0
    assert bc.quality()[0, 3] == 0
    # pure white noise sits below the 5-sigma floor of the SNR-aware flag
    assert bc.quality()[0, 2] < 5 / np.sqrt(2 * bc.pairs[0, 2])


def test_saturated_4bit_data_keeps_the_centroid():
    rng = np.random.default_rng(5)
    x = azimuth_process(1024, 128, PRF, -350.0, bw=0.12 * PRF, rng=rng, snr_db=15)
    q = quantize_4bit(x, gain=40.0)  # heavy saturation: most samples at +-15
    assert np.mean(np.abs(q.real) == 15) > 0.5
    for est in ("cde", "sde"):
        f = combine(combine(block_correlation(q, 1024, 128, est), 0), 1).baseband(PRF)[0, 0]
        assert abs(wrap_frequency(f + 350.0, PRF)) < 0.01 * PRF


def test_nan_inf_input_is_a_clear_error():
    x = np.ones((8, 8), np.complex64)
    x[3, 4] = np.nan
    with pytest.raises(SarcliError, match="NaN/inf"):
        block_correlation(x, 4, 4)
    x[3, 4] = np.inf
    with pytest.raises(SarcliError, match="NaN/inf"):
        block_correlation(x, 4, 4)


def test_short_scene_gives_one_block_and_too_short_is_an_error():
    rng = np.random.default_rng(2)
    x = azimuth_process(100, 64, PRF, 100.0, bw=0.1 * PRF, rng=rng)
    bc = block_correlation(x, 2048, 128)
    assert bc.corr.shape == (1, 1) and bc.n_lines[0] == 100 and bc.n_samples[0] == 64
    with pytest.raises(SarcliError, match="at least 2 azimuth lines"):
        block_correlation(x[:1], 2048, 128)


def test_block_edges_cover_everything():
    for n in (1, 5, 127, 128, 129, 500, 23000):
        for size in (1, 64, 128, 2048):
            s, ln = block_edges(n, size)
            assert s[0] == 0 and ln.sum() == n and np.all(ln > 0)
            assert np.all(np.diff(s) == ln[:-1])


@settings(max_examples=20, deadline=None)
@given(n_lines=st.integers(2, 60), chunk=st.integers(1, 7), az=st.integers(2, 50), est=st.sampled_from(["cde", "sde"]),
       lag=st.integers(1, 4), seed=st.integers(0, 2**31))
def test_kernel_cut_into_short_tasks_matches_numpy_reference(n_lines, chunk, az, est, lag, seed):
    """Azimuth blocks cut into tasks of a few lines (shorter than the lag too): each line's energy
    counted once per role, the partial sums of a block's tasks added up."""
    from unittest import mock

    import sarcli.doppler.cde as cde

    if n_lines < lag + 1:
        return
    rng = np.random.default_rng(seed)
    h = (rng.standard_normal((n_lines, 9)) + 1j * rng.standard_normal((n_lines, 9))).astype(np.complex64)
    with mock.patch.object(cde, "CHUNK_LINES", chunk):
        a = block_correlation(h, az, 4, est, lag)
    b = block_correlation_numpy(h, az, 4, est, lag)
    assert np.all(np.abs(a.corr - b.corr) <= 1e-6 * b.energy + 1e-12)
    np.testing.assert_allclose(a.energy, b.energy, rtol=1e-6, atol=1e-12)
    np.testing.assert_array_equal(a.pairs, b.pairs)


@pytest.mark.parametrize("est", ["cde", "sde"])
def test_result_does_not_depend_on_the_thread_count(est):
    """Fixed tasks, partial sums added in task order: one thread and every thread give the same bits."""
    from unittest import mock

    import numba

    import sarcli.doppler.cde as cde
    from sarcli.threads import limited

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("SKIPPED LOUDLY: numba has one thread here; the thread-count comparison needs two")
    rng = np.random.default_rng(4)
    h = (rng.standard_normal((300, 70)) + 1j * rng.standard_normal((300, 70))).astype(np.complex64)
    with mock.patch.object(cde, "CHUNK_LINES", 7):  # 43 tasks: both threads get several
        many = block_correlation(h, 128, 32, est)
        with limited(1):
            one = block_correlation(h, 128, 32, est)
    for f in ("corr", "energy", "line_energy"):
        np.testing.assert_array_equal(getattr(many, f), getattr(one, f))
