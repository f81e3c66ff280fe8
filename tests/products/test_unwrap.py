"""Spatial unwrapping (SNAPHU through the ``snaphu`` package) against synthetic wrapped ramps whose
unwrapped phase is known."""

from __future__ import annotations

import numpy as np

from sarcli.gbsar.unwrap import unwrap


def _wrap(x):
    return np.angle(np.exp(1j * x))


def test_ramp_of_several_cycles_is_recovered():
    y, x = np.mgrid[0:60, 0:80].astype(np.float64)
    truth = 0.25 * x + 0.15 * y - 0.2 * 40 - 0.15 * 30  # 4.5 cycles across, median near 0: no 2 pi shift
    truth -= 2 * np.pi * np.round(np.median(truth) / (2 * np.pi))
    u = unwrap(_wrap(truth), np.full(truth.shape, 0.95), nlooks=9.0)
    assert u.method.startswith("snaphu")
    assert np.ptp(truth) > 6 * np.pi  # really wrapped several times
    np.testing.assert_allclose(u.phase, truth, atol=1e-4)
    assert np.all(u.component == 1)


def test_no_data_pixels_stay_nan_and_the_rest_unwraps():
    y, x = np.mgrid[0:50, 0:50].astype(np.float64)
    truth = 0.3 * (x - 25)
    w = _wrap(truth)
    w[20:30, 20:30] = np.nan  # a hole without data (outside the beam)
    u = unwrap(w, np.full(w.shape, 0.9), nlooks=9.0)
    assert np.all(np.isnan(u.phase[20:30, 20:30])) and np.all(u.component[20:30, 20:30] == 0)
    ok = np.isfinite(w)
    np.testing.assert_allclose(u.phase[ok], truth[ok], atol=1e-4)


def test_stdout_stays_clean(capfd):
    """SNAPHU's progress lines never reach stdout (``--json`` output must stay parseable)."""
    y, x = np.mgrid[0:30, 0:30].astype(np.float64)
    unwrap(_wrap(0.4 * x), np.ones((30, 30)))
    out, _ = capfd.readouterr()
    assert out == ""


def test_too_small_stays_wrapped():
    w = _wrap(np.linspace(0, 9, 5))[None, :]
    u = unwrap(w, np.ones_like(w))
    np.testing.assert_array_equal(u.phase, w.astype(np.float32))
    assert u.method.startswith("none")
