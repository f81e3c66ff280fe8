"""MLCC / MLBF data-only ambiguity on plain-numpy point-target raw data, and on the real block."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sarcli.doppler.cde import block_correlation, combine
from sarcli.doppler.dataonly import DataOnlyEstimate, combine_estimates, mlbf, mlcc
from sarcli.model.raw import Radar
from tests.doppler.synth import C, point_target_raw

PRF, FS, F0, K, TP = 1000.0, 60e6, 5.3e9, -12.5e12, 4e-6
RADAR = Radar(F0, C / F0, PRF, FS, K, TP, 2 * 850e3 / C, 850e3)


@pytest.mark.parametrize("fdc", [-3400.0, 2770.0, 6100.0])
def test_mlcc_mlbf_resolve_synthetic_ambiguity(fdc):
    rng = np.random.default_rng(int(abs(fdc)))
    x = point_target_raw(384, 640, PRF, FS, F0, K, TP, fdc, -2000.0, 100, rng, beam_s=0.1)
    fbb = float(combine(combine(block_correlation(x, 384, 64), 0), 1).baseband(PRF)[0, 0])
    n_true = int(np.rint((fdc - fbb) / PRF))
    for est in (mlcc(x, RADAR, fbb, rg_block=64), mlbf(x, RADAR, fbb, rg_block=64)):
        assert est.ambiguity == n_true, est.method
        assert abs(est.fdc_hz - fdc) < 4 * est.sigma_hz + 0.05 * PRF
        assert est.confidence > 0.7


def test_combination_rule_is_conservative():
    a = DataOnlyEstimate("mlcc", -7000.0, 100.0, -6, 0.9, np.zeros(1))
    b = DataOnlyEstimate("mlbf", -7600.0, 100.0, -7, 0.6, np.zeros(1))
    n, conf, _ = combine_estimates([a, b])
    assert n == -6 and conf == pytest.approx(0.9 * 0.4)
    b = dataclasses.replace(b, ambiguity=-6)
    assert combine_estimates([a, b])[1] == pytest.approx(0.9)
    assert combine_estimates([])[1] == 0.0


def test_real_vancouver_block_data_only_ambiguity(shared_data):
    """The real block: lag-one baseband ~ +487 Hz; the published estimates (-7045/-7050 Hz) mean
    ambiguity -6. MLBF must find -6; MLCC is reported as it is (too noisy on 700 valid range samples)."""
    from scipy.io import loadmat

    d = loadmat(shared_data / "rs1_vancouver_block1.mat")["data"].astype(np.complex64)
    radar = Radar(5.3e9, 2.9979e8 / 5.3e9, 1256.98, 32.317e6, -0.72135e12, 41.75e-6, 6.5956e-3, 988647.46, 4)
    fbb = float(combine(combine(block_correlation(d, 1536, 128), 0), 1).baseband(radar.prf_hz)[0, 0])
    assert fbb == pytest.approx(487.0, abs=5.0)
    b = mlbf(d, radar, fbb)
    assert b.ambiguity == -6 and b.confidence > 0.5
    a = mlcc(d, radar, fbb)
    assert 0.0 <= a.confidence < 0.5  # honest: MLCC cannot tell on this block
