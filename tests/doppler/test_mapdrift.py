"""Map-drift autofocus on plain-numpy point-target raw data with a known Doppler rate."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.doppler.mapdrift import map_drift
from sarcli.doppler.rangecomp import range_compress_valid
from sarcli.errors import SarcliError
from sarcli.io.raw import Radar
from tests.doppler.synth import C, point_target_raw

PRF, FS, F0, K, TP = 1000.0, 60e6, 5.3e9, -12.5e12, 4e-6
RADAR = Radar(F0, C / F0, PRF, FS, K, TP, 2 * 850e3 / C, 850e3)


@pytest.mark.parametrize("fdc,fr,start", [(-3400.0, -2000.0, 0.8), (150.0, -1500.0, 1.2)])
def test_map_drift_recovers_the_rate(fdc, fr, start):
    rng = np.random.default_rng(2)
    x = point_target_raw(512, 512, PRF, FS, F0, K, TP, fdc, fr, 40, rng, beam_s=0.12)
    rc, v = range_compress_valid(x, RADAR)
    r_mid = 850e3 + 0.5 * (v.start + v.stop) * C / (2 * FS)
    res = map_drift(rc, PRF, C / F0, r_mid, C / (2 * FS), fdc, start * fr)
    assert res.converged
    assert res.fr_hz_per_s == pytest.approx(fr, rel=1e-3)


def test_map_drift_refuses_bad_start():
    with pytest.raises(SarcliError, match="negative"):
        map_drift(np.ones((128, 8), np.complex64), PRF, 0.05, 8e5, 5.0, 0.0, +100.0)
    with pytest.raises(SarcliError, match="64 azimuth lines"):
        map_drift(np.ones((10, 8), np.complex64), PRF, 0.05, 8e5, 5.0, 0.0, -100.0)
