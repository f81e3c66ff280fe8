"""A new Doppler centroid estimator is one object and one registration (the recipe of docs/doppler.md,
"A new Doppler estimator"): a toy registered from this file runs end to end through ``sarcli doppler
--estimator toy``, and the first-pass hook cannot recurse."""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest

from sarcli.doppler.api import estimate_doppler
from sarcli.doppler.estimators import ESTIMATORS
from sarcli.doppler.estimators.base import BasebandBlocks, EstimationInput
from sarcli.doppler.options import DopplerOptions
from sarcli.errors import ConfigError
from sarcli.io.raw import write_raw


# --- the recipe: one object with baseband(data) -> BasebandBlocks ------------------------------------
@dataclass(frozen=True)
class SpectralCentroid:
    """Toy estimator: the circular mean of the scene's azimuth power spectrum, one block for the scene.

    With X the azimuth DFT of the N lines, sum_k |X_k|^2 exp(j 2 pi k / N) = N sum_m x(m+1) conj(x(m))
    (circular), so the phase of sum_f P(f) exp(j 2 pi f / PRF) is the CDE's 2 pi fdc / PRF."""

    def baseband(self, data: EstimationInput) -> BasebandBlocks:
        raw = data.raw
        prf = raw.radar.prf_hz
        power = np.sum(np.abs(np.fft.fft(raw.echo, axis=0)) ** 2, axis=1)
        f = np.fft.fftfreq(raw.echo.shape[0], 1.0 / prf)
        c = np.sum(power * np.exp(2j * np.pi * f / prf))
        fbb, q = prf * np.angle(c) / (2 * np.pi), abs(c) / np.sum(power)

        def one(v):
            return np.full((1, 1), v)

        return BasebandBlocks(fbb_hz=one(fbb), quality=one(q), valid=one(True), weight=one(1.0),
                              range_m=one(raw.slant_range().mean()), time_s=one(raw.azimuth_time.mean()),
                              scene_fbb_hz=float(fbb), scene_quality=float(q), info={"bins": int(f.size)})


@pytest.fixture
def toy():
    ESTIMATORS.register("toy", SpectralCentroid())
    yield
    ESTIMATORS.unregister("toy")
# ------------------------------------------------------------------------------------------------------


def test_toy_estimator_through_the_cli(toy, cli, clutter_raw, tmp_path):
    raw, out = tmp_path / "raw.h5", tmp_path / "doppler.h5"
    write_raw(raw, clutter_raw)
    r = cli("doppler", raw, "--estimator", "toy", "--json", "-o", out)
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["fdc_method"] == "toy" and d["estimator_info"] == {"bins": 512} and d["n_blocks"] == 1
    assert d["ambiguity_source"] == "orbit" and d["ambiguity_resolved"] is True
    # the CDE of one scene-sized block (numba kernel, linear correlation): the toy adds one wrap-around
    # pair of unrelated lines to its 511, at most 1/511 / quality (0.37) = 0.005 rad = 1.1 Hz
    n, m = clutter_raw.echo.shape
    cde = estimate_doppler(clutter_raw, DopplerOptions(az_block=n, rg_block=m))
    assert d["fdc_baseband_hz"] == pytest.approx(cde.summary.fdc_baseband_hz, abs=2.0)
    assert d["ambiguity"] == cde.summary.ambiguity
    r = cli("doppler", raw, "--estimator", "nope")
    assert r.exit_code == 2 and "known: cde, lb, rc-cde, sde, toy" in r.stderr


def test_an_estimator_must_have_baseband():
    with pytest.raises(ConfigError, match="has no baseband"):
        ESTIMATORS.register("broken", object())
    assert "broken" not in ESTIMATORS


def test_the_first_pass_hook_cannot_recurse(clutter_raw):
    calls = []

    @dataclass(frozen=True)
    class Greedy:
        def baseband(self, data: EstimationInput) -> BasebandBlocks:
            calls.append(data.options.estimator)
            data.first_pass("greedy")  # asks for itself: the first pass may not ask again
            raise AssertionError("not reached")

    ESTIMATORS.register("greedy", Greedy())
    try:
        with pytest.raises(ConfigError, match="asked for a first pass inside a first pass"):
            estimate_doppler(clutter_raw, DopplerOptions(estimator="greedy"))
    finally:
        ESTIMATORS.unregister("greedy")
    assert calls == ["greedy", "greedy"]


def test_a_bad_block_table_is_the_estimators_fault(clutter_raw):
    @dataclass(frozen=True)
    class Ragged(SpectralCentroid):
        def baseband(self, data):
            bb = super().baseband(data)
            return BasebandBlocks(**{**bb.__dict__, "weight": np.ones((1, 2))})

    ESTIMATORS.register("ragged", Ragged())
    try:
        with pytest.raises(ConfigError, match="'ragged' returned weight of shape"):
            estimate_doppler(clutter_raw, DopplerOptions(estimator="ragged"))
    finally:
        ESTIMATORS.unregister("ragged")
