"""Look-balance centroid (scene-contrast-robust) against plain-numpy azimuth scenes with a known centroid,
and on a simulated coastal scene against the simulator's truth, next to the CDE it corrects."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.doppler.api import estimate_doppler
from sarcli.doppler.cde import block_correlation, combine, wrap_frequency
from sarcli.doppler.lookbalance import look_balance
from sarcli.doppler.options import DopplerOptions
from sarcli.errors import SarcliError
from tests.doppler.conftest import SCENES, simulate_text

PRF, KA, B0 = 1257.0, -1780.0, 970.0  # Radarsat-1 fine beam: PRF, rate, first null of the Doppler pattern


def _scene(fdc: float, n_lines: int, bright: list[tuple[float, float]], rng: np.random.Generator,
           n_cols: int = 32, spacing: int = 3, snr_db: float = 10.0) -> np.ndarray:
    """Azimuth signals (lines x columns), written from the signal model: a target at beam-centre line
    eta has amplitude sinc^2(Ka u / B0) and phase 2 pi fdc u + pi Ka u^2 (u = (m - eta)/PRF), with a
    random complex amplitude per column; weak targets every ``spacing`` lines over the scene and its
    apertures, plus (line, power) bright ones; white noise at ``snr_db`` below the weak clutter."""
    m = np.arange(n_lines)
    half = int(B0 / abs(KA) * PRF)  # first null of the two-way pattern, in lines
    etas = [(float(e), 1.0) for e in range(-half, n_lines + half, spacing)] + bright
    x = np.zeros((n_lines, n_cols), complex)
    for eta, power in etas:
        u = (m - eta) / PRF
        sig = np.sinc(KA * u / B0) ** 2 * np.exp(1j * (2 * np.pi * fdc * u + np.pi * KA * u**2))
        amp = np.sqrt(power / 2) * (rng.standard_normal(n_cols) + 1j * rng.standard_normal(n_cols))
        x += np.outer(sig, amp)
    s = np.sqrt(np.mean(np.abs(x) ** 2) * 10 ** (-snr_db / 10) / 2)
    x += s * (rng.standard_normal(x.shape) + 1j * rng.standard_normal(x.shape))
    return x.astype(np.complex64)


def _blocks(x, az_block, start=None):
    """CDE blocks and look balance started, like the pipeline, from the CDE centroid of the scene."""
    bc = block_correlation(x, az_block, x.shape[1])
    f0 = combine(bc, 0).baseband(PRF)[0] if start is None else np.array([start])
    return bc, look_balance(x, PRF, bc.line0, bc.n_lines, bc.sample0, bc.n_samples, f0, np.array([KA]))


@pytest.mark.parametrize("fdc", [-180.0, 35.0, 420.0])
def test_bright_targets_at_block_edges_bias_the_cde_not_the_look_balance(fdc):
    rng = np.random.default_rng(int(abs(fdc)))
    # a bright town 60 lines before the middle block and another one 40 lines inside its end
    x = _scene(fdc, 1536, [(452.0, 400.0), (455.0, 400.0), (984.0, 300.0)], rng)
    bc, lb = _blocks(x, 512)
    cde_err = wrap_frequency(bc.baseband(PRF)[:, 0] - fdc, PRF)
    assert abs(cde_err[1]) > 50.0  # the CDE of the middle block follows the towns
    ok = lb.valid()[:, 0]
    assert ok[1] and lb.pixels[1, 0] == 512
    err = wrap_frequency(lb.fbb_hz[ok, 0] - fdc, PRF)
    assert np.all(np.abs(err) < np.maximum(4 * lb.sigma_hz[ok, 0], 4.0))
    assert np.all(lb.sigma_hz[ok, 0] < 15.0)


def test_homogeneous_scene_agrees_with_the_truth_and_the_sigma_is_honest():
    errs, sigs = [], []
    for seed in range(6):
        x = _scene(250.0, 1536, [], np.random.default_rng(100 + seed), n_cols=16)
        _, lb = _blocks(x, 1536, start=0.0)  # 250 Hz from the start: bracketing in 63 Hz steps
        errs.append(lb.fbb_hz[0, 0] - 250.0)
        sigs.append(lb.sigma_hz[0, 0])
    errs, sigs = np.array(errs), np.array(sigs)
    assert np.all(np.abs(errs) < 4 * sigs)
    # the standard error is neither wildly optimistic nor useless (rms error / mean sigma)
    assert 0.25 < np.sqrt(np.mean(errs**2)) / np.mean(sigs) < 2.5


def test_blocks_too_close_to_the_scene_ends_are_invalid_and_lb_refuses_short_scenes(clutter_raw):
    x = _scene(0.0, 700, [], np.random.default_rng(3), n_cols=16)
    _, lb = _blocks(x, 700)  # margin 1.15 x 0.3 PRF / |Ka| x PRF = 307 lines each side: 86 left
    assert lb.margin_lines[0] == int(np.ceil(1.15 * 0.3 * PRF / abs(KA) * PRF)) == 307
    assert lb.valid()[0, 0] and lb.pixels[0, 0] == 700 - 2 * 307
    _, lb = _blocks(x[:400], 400)
    assert not lb.valid().any()
    with pytest.raises(SarcliError, match="look balance"):
        estimate_doppler(clutter_raw, DopplerOptions(estimator="lb"))  # 512 lines: nothing 306 lines from both ends


@pytest.mark.parametrize("seed", [1, 3, 9])
def test_noise_only_blocks_are_rejected_by_the_cde_gate(seed):
    """LB alone can keep a root in pure noise (its sigma describes target scatter, not the presence of
    signal); the pipeline keeps a block only where the CDE's noise-floor test accepts it too."""
    rng = np.random.default_rng(seed)
    x = (rng.standard_normal((1536, 16)) + 1j * rng.standard_normal((1536, 16))).astype(np.complex64)
    bc, lb = _blocks(x, 512)
    assert not np.any(bc.valid() & lb.valid())


@pytest.mark.slow
def test_coastal_scene_512_line_blocks_against_the_truth():
    """The simulated coast (bright town, land edge, sea; orbit, attitude, antenna pattern, noise):
    512-line CDE blocks are off by up to ~250 Hz and the fitted scene centroid by ~23 Hz; the
    look-balance blocks are within 4 sigma + 5 Hz and the scene centroid meets the 0.5 % PRF bar."""
    raw = simulate_text((SCENES / "rs1_coast.toml").read_text())
    prf, rho = raw.radar.prf_hz, raw.slant_range()
    tf = raw.truth["doppler_centroid_hz"]
    cde = estimate_doppler(raw, DopplerOptions(estimator="cde", az_block=512, rg_block=128))
    lb = estimate_doppler(raw, DopplerOptions(estimator="lb", az_block=512, rg_block=128))
    b_cde, b_lb = cde.blocks, lb.blocks
    err_cde = b_cde["fdc_hz"] - np.interp(b_cde["range_m"], rho, tf)
    assert np.max(np.abs(err_cde)) > 150.0
    ok = b_lb["valid"]
    err = b_lb["fdc_hz"][ok] - np.interp(b_lb["range_m"][ok], rho, tf)
    sig = np.array(lb.summary.estimator_info["sigma_hz"]).ravel()[ok]
    assert ok.sum() >= 5 and np.all(np.abs(err) < 4 * sig + 5.0)
    rms = lambda m: float(np.sqrt(np.mean((m.fdc(rho, 0.0) - tf) ** 2)))  # noqa: E731
    assert rms(cde) > 0.01 * prf and rms(lb) < 0.005 * prf
    assert lb.summary.fdc_method == "lb" and lb.summary.estimator_info["band_fraction"] == 0.6
    # edge blocks are placed at the centre of the pixels they used (margin 307 lines at each end)
    t = raw.azimuth_time
    assert b_lb["azimuth_time_s"][0] == pytest.approx(np.interp(0.5 * (307 + 511), np.arange(t.size), t))


@pytest.mark.slow
def test_cli_look_balance_matches_the_library(cli, tmp_path):
    from sarcli.io.raw import write_raw

    raw = simulate_text((SCENES / "rs1_coast.toml").read_text())
    path = tmp_path / "coast.h5"
    write_raw(path, raw)
    r = cli("doppler", path, "--estimator", "lb", "--az-block", "512", "--rg-block", "128", "--json")
    assert r.exit_code == 0, r.stderr
    import json

    d = json.loads(r.stdout)
    ref = estimate_doppler(raw, DopplerOptions(estimator="lb", az_block=512, rg_block=128))
    assert d["fdc_method"] == "lb" and d["fdc_hz"] == pytest.approx(ref.summary.fdc_hz, abs=1e-6)
    bad = cli("doppler", path, "--estimator", "lb", "--lb-band", "0.95")
    assert bad.exit_code != 0 and bad.stderr.count("\n") == 1 and "band fraction" in bad.stderr
    short = cli("doppler", path, "--estimator", "lb", "--az-block", "16")
    assert short.exit_code != 0 and "--az-block" in short.stderr
