"""MLCC / MLBF data-only ambiguity on plain-numpy point-target raw data, and on the real block."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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


def _t_or_normal(dof):
    from scipy import stats

    return stats.norm if dof is None else stats.t(dof)


def test_combination_is_the_inverse_variance_mean_with_birge_scaling():
    """Expected values computed here from the formulas (maximum likelihood for independent Gaussian
    errors, Birge ratio, Welch-Satterthwaite), not from the code under test."""
    prf, fbb = 1256.98, 485.5
    a = DataOnlyEstimate("mlcc", -7000.0, 100.0, -6, 0.9, np.zeros(1), 6.0)
    b = DataOnlyEstimate("mlbf", -7100.0, 200.0, -6, 0.6, np.zeros(1), 2.0)
    c = combine_estimates([a, b], fbb, prf)
    w = np.array([1e-4, 0.25e-4])
    assert c.method == "combined"
    assert c.fdc_hz == pytest.approx((-7000.0 * w[0] - 7100.0 * w[1]) / w.sum())  # -7020
    assert c.sigma_hz == pytest.approx(w.sum() ** -0.5)  # chi2 = 0.2 < 1: no scaling
    assert c.dof == pytest.approx(w.sum() ** 2 / (w[0] ** 2 / 6.0 + w[1] ** 2 / 2.0))
    y, s_y = (c.fdc_hz - fbb) / prf, c.sigma_hz / prf
    t = _t_or_normal(c.dof)
    assert c.ambiguity == -6
    assert c.confidence == pytest.approx(t.cdf((-5.5 - y) / s_y) - t.cdf((-6.5 - y) / s_y))
    # disagreement beyond the errors: chi2 = 18 on 1 degree of freedom -> sigma x sqrt(18)
    b = DataOnlyEstimate("mlbf", -7600.0, 100.0, -7, 0.6, np.zeros(1))
    c = combine_estimates([a, b], fbb, prf)
    assert c.fdc_hz == pytest.approx(-7300.0) and c.sigma_hz == pytest.approx(100.0 / np.sqrt(2) * np.sqrt(18.0))
    assert c.dof is None  # one Gaussian input: Gaussian
    # the Squamish block of the Vancouver pass: MLCC -7 and MLBF -5, both weak; together -6
    mlcc_ = DataOnlyEstimate("mlcc", -7823.0, 1082.0, -7, 0.39, np.zeros(8), 6.6)
    mlbf_ = DataOnlyEstimate("mlbf", -6287.0, 791.0, -5, 0.35, np.zeros(8), 1.1)
    c = combine_estimates([mlcc_, mlbf_], 548.8, prf)
    assert c.ambiguity == -6 and c.fdc_hz == pytest.approx(-6822.0, abs=1.0)
    assert combine_estimates([], fbb, prf) is None
    assert combine_estimates([dataclasses.replace(a, sigma_hz=np.inf)], fbb, prf) is None


@settings(max_examples=50, deadline=None)
@given(f=st.floats(-9000, 9000), s=st.floats(1.0, 2000.0), dof=st.one_of(st.none(), st.floats(1.0, 50.0)),
       fbb=st.floats(-600, 600))
def test_one_estimate_combines_to_itself(f, s, dof, fbb):
    e = DataOnlyEstimate("mlbf", f, s, 0, 0.0, np.zeros(1), dof)
    c = combine_estimates([e], fbb, 1256.98)
    assert c.fdc_hz == pytest.approx(f) and c.sigma_hz == pytest.approx(s)
    assert c.dof is None if dof is None else c.dof == pytest.approx(dof)
    assert c.ambiguity == int(np.floor((f - fbb) / 1256.98 + 0.5))
    assert 0.0 <= c.confidence <= 1.0


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
