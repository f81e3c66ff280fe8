"""Hard cases: bad Doppler rates, NaN models, tables not covering the scene, all-zero data,
scenes shorter than the synthetic aperture, non-uniform PRF."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.errors import SarcliError
from sarcli.focus.quality import point_target_metrics
from sarcli.focus.rda import focus_rd
from sarcli.model.doppler import GeometricDoppler

from .synth import C, scene

LAM, V, PRF = 0.0566, 7000.0, 1500.0
DR = C / (2 * 24e6)
R0 = 850e3 + 384.3 * DR


class Model:
    """A Doppler model given by two functions (and optionally the blocks it was estimated on)."""

    def __init__(self, fdc, fr, blocks=None):
        self._fdc, self._fr = fdc, fr
        if blocks is not None:
            self.blocks = blocks

    def fdc(self, r, t):
        return self._fdc(np.asarray(r), np.asarray(t))

    def fr(self, r, t):
        return self._fr(np.asarray(r), np.asarray(t))


@pytest.fixture(scope="module")
def small():
    return scene([(R0, 0.2, 1.0)], n_lines=600, n_samples=768)


@pytest.mark.parametrize("fr,msg", [(lambda r, t: 0 * r + 2000.0, "negative"),
                                    (lambda r, t: 0 * r - 1e-6, "too close to zero"),
                                    (lambda r, t: 0 * r + np.nan, "NaN")])
def test_bad_doppler_rate_is_a_clear_error(small, fr, msg):
    with pytest.raises(SarcliError, match=msg):
        focus_rd(small, Model(lambda r, t: 0 * r, fr))


def test_table_not_covering_the_scene_extrapolates_with_a_warning(small):
    geo = GeometricDoppler(V, 0.0, LAM)
    blocks = {"range_m": np.array([700e3, 701e3]), "azimuth_time_s": np.array([50.0, 51.0])}
    with pytest.warns(UserWarning, match="extrapolating"):
        slc = focus_rd(small, Model(geo.fdc, geo.fr, blocks))
    assert np.all(np.isfinite(slc.image))
    assert any("extrapolating" in w for w in slc.parameters["warnings"])


def test_all_zero_raw_gives_a_zero_image_and_no_nan(small):
    raw = scene([], n_lines=600, n_samples=768)
    slc = focus_rd(raw, GeometricDoppler(V, 0.0, LAM))
    assert np.all(slc.image == 0)
    with pytest.raises(SarcliError, match="no signal"):
        point_target_metrics(slc.image, 300, 384)


def test_scene_shorter_than_the_aperture_warns_and_still_places_the_target():
    # aperture: 1200 Hz / 2037 Hz/s = 0.59 s = 884 lines; the scene has 300 lines around the target
    eta0 = 0.1
    raw = scene([(R0, eta0, 1.0)], n_lines=300)
    with pytest.warns(UserWarning, match="shorter than the synthetic aperture"):
        slc = focus_rd(raw, GeometricDoppler(V, 0.0, LAM), azimuth_window="rect", range_window="rect")
    assert np.all(np.isfinite(slc.image))
    assert slc.first_full_line > slc.last_full_line
    row = float(np.interp(eta0, slc.azimuth_time, np.arange(300)))
    m = point_target_metrics(slc.image, row, 384.3, half=32)
    assert abs(m["row"] - row) < 0.1 and abs(m["col"] - 384.3) < 0.1
    # the resolution is that of the Doppler band actually seen: 300 lines x 2037 Hz/s / PRF = 407 Hz
    fr = 2 * V**2 / (LAM * R0)
    assert m["irw_azimuth_px"] == pytest.approx(0.886 * PRF / (300 / PRF * fr), rel=0.1)


def test_non_uniform_prf_is_refused(small):
    import dataclasses

    t = small.azimuth_time.copy()
    t[300:] += 0.01
    with pytest.raises(SarcliError, match="uniform"):
        focus_rd(dataclasses.replace(small, azimuth_time=t), GeometricDoppler(V, 0.0, LAM))


@pytest.mark.parametrize("knob", [{"rcmc": "cubic"}, {"range_window": "blackman"}, {"precision": "half"},
                                  {"azimuth_bandwidth_hz": 5000.0}, {"bogus": 1}])
def test_bad_knobs_are_refused(small, knob):
    with pytest.raises(SarcliError):
        focus_rd(small, GeometricDoppler(V, 0.0, LAM), **knob)
