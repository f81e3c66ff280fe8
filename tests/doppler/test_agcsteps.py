"""Receiver-gain steps recovered from the echo (products without AGC records), on plain-numpy signals
with known steps, on a simulated scene without steps, and on the real Vancouver block."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.doppler.agcsteps import detect_gain_steps, step_statistic, undo_gain_steps
from tests.doppler.synth import azimuth_process, quantize_4bit

PRF = 1257.0
STEPS = [(300, 1.0), (700, 1.0), (1200, -1.0)]


def _stepped(gain: float, seed: int = 5) -> np.ndarray:
    """1536 x 2048 (the Vancouver block's size: its line power is steady to 0.14 dB line to line)."""
    rng = np.random.default_rng(seed)
    x = azimuth_process(1536, 2048, PRF, 300.0, 0.15 * PRF, rng, snr_db=5.0)
    g = np.zeros(1536)
    for m, d in STEPS:
        g[m:] += d
    return quantize_4bit(x * (10 ** (g / 20))[:, None], gain)


def test_known_steps_are_found_on_their_line_and_undone():
    e = _stepped(gain=3.0)  # ~4.6 levels rms: 4-bit, little saturation
    s = detect_gain_steps(e)
    np.testing.assert_array_equal(s.lines, [m for m, _ in STEPS])
    np.testing.assert_allclose(s.db, [d for _, d in STEPS], atol=0.1)
    assert s.db_groups.shape == (3, 8)
    assert np.ptp(_segment_levels_db(e)) > 1.9
    assert np.ptp(_segment_levels_db(undo_gain_steps(e, s))) < 0.1


def test_saturation_compresses_the_output_step_and_the_measured_one_is_undone():
    e = _stepped(gain=8.0)  # Vancouver-like loading: 6 % of the I/Q samples at +-15
    assert np.mean(np.abs(e.real) == 15) > 0.05
    s = detect_gain_steps(e)
    np.testing.assert_array_equal(s.lines, [m for m, _ in STEPS])
    assert np.all(np.abs(s.db) < 0.95)  # the quantizer compresses the 1 dB input steps
    assert np.ptp(_segment_levels_db(undo_gain_steps(e, s))) < 0.1


def _segment_levels_db(e: np.ndarray) -> np.ndarray:
    p = np.mean(np.abs(e) ** 2, axis=1)
    return 10 * np.log10([p[a + 20:b - 20].mean() for a, b in ((0, 300), (300, 700), (700, 1200), (1200, 1536))])


def test_no_steps_in_smooth_or_beating_scenes(clutter_raw):
    rng = np.random.default_rng(1)
    x = azimuth_process(1536, 2048, PRF, 300.0, 0.15 * PRF, rng, snr_db=5.0)
    env = np.exp(-0.5 * ((np.arange(1536) - 700) / 150.0) ** 2) * 3 + 0.3  # 10 dB smooth swell
    assert detect_gain_steps(quantize_4bit(x * env[:, None], 3.0)).lines.size == 0
    assert detect_gain_steps(clutter_raw.echo).lines.size == 0


def test_vancouver_steps_are_single_line_jumps_of_the_line_power(shared_data):
    from scipy.io import loadmat

    e = loadmat(shared_data / "rs1_vancouver_block1.mat")["data"].astype(np.complex64)
    s = detect_gain_steps(e)
    p = 10 * np.log10(np.mean(np.abs(e.astype(np.complex128)) ** 2, axis=1))
    jump = np.diff(p, prepend=p[0])
    level = np.zeros(p.size)  # persistent change: mean of the next 16 lines minus the previous 16
    level[16:-16] = [p[m:m + 16].mean() - p[m - 16:m].mean() for m in range(16, p.size - 16)]
    assert s.lines.size >= 6
    assert np.all(np.abs(jump[s.lines]) > 0.4) and np.all(np.sign(jump[s.lines]) == np.sign(s.db))
    assert np.all(np.abs(level[s.lines]) > 0.4)
    # every sharp AND persistent change of the line power is found (single-line spikes are not steps)
    sharp = np.flatnonzero((np.abs(jump) > 0.4) & (np.abs(level) > 0.4) & (np.sign(jump) == np.sign(level)))
    assert set(sharp) <= set(s.lines)
    # the near range (dark, little saturation) shows larger output steps than the bright far range
    assert np.mean(np.abs(s.db_groups[:, 0])) > np.mean(np.abs(s.db_groups[:, -1]))


@pytest.mark.parametrize("shape", [(0, 8), (1, 8), (2, 8), (31, 8)])
def test_short_or_empty_inputs_give_no_steps(shape):
    s = detect_gain_steps(np.ones(shape, np.complex64))
    assert s.lines.size == 0 and s.as_list() == []
    assert undo_gain_steps(np.ones(shape, np.complex64), s).shape == shape


def test_gain_step_modes_in_the_pipeline(clutter_raw):
    """auto: only quantized products without an AGC record; on: always; off: never."""
    import dataclasses

    from sarcli.doppler.api import estimate_doppler
    from sarcli.doppler.options import DopplerOptions

    q = dataclasses.replace(clutter_raw, radar=dataclasses.replace(clutter_raw.radar, quantization_bits=4))
    with_agc = dataclasses.replace(q, agc_db=np.zeros(q.echo.shape[0]))
    kw = dict(az_block=512, rg_block=96)
    assert estimate_doppler(clutter_raw, DopplerOptions(**kw)).summary.gain_steps is None  # not quantized
    assert estimate_doppler(q, DopplerOptions(**kw)).summary.gain_steps == ()  # searched, none in this scene
    assert estimate_doppler(with_agc, DopplerOptions(**kw)).summary.gain_steps is None  # the AGC record is used
    assert estimate_doppler(with_agc, DopplerOptions(gain_steps="on", **kw)).summary.gain_steps == ()
    assert estimate_doppler(q, DopplerOptions(gain_steps="off", **kw)).summary.gain_steps is None


def test_step_statistic_matches_a_least_squares_fit_per_line():
    """Against numpy lstsq of p = a + b (t - m) + d [t >= m] on each window (independent of the
    closed form the module uses)."""
    rng = np.random.default_rng(4)
    p = np.cumsum(rng.standard_normal(80)) * 0.1
    p[40:] += 0.8
    w = 6
    d, sd = step_statistic(p, w)
    for m in range(w, p.size - w + 1):
        t = np.arange(m - w, m + w) - m
        a = np.column_stack([np.ones(2 * w), t, (t >= 0).astype(float)])
        coef, rss, *_ = np.linalg.lstsq(a, p[m - w:m + w], rcond=None)
        cov = rss[0] / (2 * w - 3) * np.linalg.inv(a.T @ a)
        assert d[m] == pytest.approx(coef[2], abs=1e-12)
        assert sd[m] == pytest.approx(np.sqrt(cov[2, 2]), rel=1e-9)
    assert np.all(d[:w] == 0) and np.all(np.isinf(sd[-w + 1:]))


def test_undo_in_place_changes_the_echo_itself_to_the_same_values():
    e = _stepped(gain=3.0)
    s = detect_gain_steps(e)
    copy = undo_gain_steps(e, s)
    work = e.copy()
    same = undo_gain_steps(work, s, in_place=True)
    assert same is work and not np.array_equal(work, e)
    np.testing.assert_array_equal(work, copy)
    wide = e.astype(np.complex128)  # not complex64: a copy all the same, the input left as it was
    out = undo_gain_steps(wide, s, in_place=True)
    assert out is not wide and out.dtype == np.complex64 and np.array_equal(wide, e)
    np.testing.assert_array_equal(out, copy)


def test_a_consumed_echo_gives_the_same_estimate(clutter_raw):
    """consume=True undoes the steps in the caller's echo (no copy); the model is identical, and without
    it the caller's echo is left as it was."""
    import dataclasses

    from sarcli.doppler.api import estimate_doppler
    from sarcli.doppler.options import DopplerOptions

    g = np.zeros(clutter_raw.echo.shape[0])
    g[clutter_raw.echo.shape[0] // 2:] = 4.0  # one 4 dB receiver-gain step half-way (the line power
    # of this 384-sample scene jitters by 0.6 dB from line to line: 2 dB would not stand out)
    stepped = (clutter_raw.echo * (10 ** (g / 20)).astype(np.float32)[:, None]).astype(np.complex64)
    q = dataclasses.replace(clutter_raw, echo=stepped,
                            radar=dataclasses.replace(clutter_raw.radar, quantization_bits=4))
    opts = DopplerOptions(az_block=512, rg_block=96)
    kept = q.echo.copy()
    plain = estimate_doppler(q, opts)
    assert len(plain.summary.gain_steps) == 1
    np.testing.assert_array_equal(q.echo, kept)  # not consumed: untouched
    consumed = estimate_doppler(q, opts, consume=True)
    assert not np.array_equal(q.echo, kept)  # the step was undone in the echo itself
    assert consumed.summary == plain.summary
    np.testing.assert_array_equal(consumed.fdc_poly.coef, plain.fdc_poly.coef)
    np.testing.assert_array_equal(consumed.fr_poly.coef, plain.fr_poly.coef)
