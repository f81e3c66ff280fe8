"""CFAR detection on synthetic co-registered image pairs (no focusing): plain-numpy scenes."""

import numpy as np

from sarcli.ati.detect import CfarKnobs, bistatic_phase, ca_cfar, detect
from sarcli.ati.geometry import Platform, los_rate_from_phase

P = Platform(10e3, 2000.0, 299792458.0 / 1e9)
D = 2.0


def _pair(blobs, n=600, m=64, noise=1.0, seed=0):
    """Images with complex noise per channel and Gaussian blobs (row, col, amplitude, ATI phase)."""
    rng = np.random.default_rng(seed)
    ranges = 11200.0 + np.arange(m)
    z0 = noise * (rng.standard_normal((n, m)) + 1j * rng.standard_normal((n, m))) / np.sqrt(2)
    z1 = noise * (rng.standard_normal((n, m)) + 1j * rng.standard_normal((n, m))) / np.sqrt(2)
    rr, cc = np.mgrid[0:n, 0:m]
    phic = bistatic_phase(ranges, D, P.wavelength)[None, :]
    for r, c, a, phi in blobs:
        g = a * np.exp(-((rr - r) / 2.0) ** 2 - ((cc - c) / 1.0) ** 2) * np.exp(0.4j)
        z0 = z0 + g
        z1 = z1 + g * np.exp(1j * (phi + phic))
    return z0.astype(np.complex64), z1.astype(np.complex64), np.arange(n) / 3000.0, ranges


def test_ca_cfar_false_alarm_rate_on_exponential_noise():
    rng = np.random.default_rng(4)
    x = rng.exponential(1.0, (2000, 200))
    for pfa in (1e-2, 1e-3):
        rate = ca_cfar(x, (2, 2), (8, 8), pfa).mean()
        assert 0.5 * pfa < rate < 2.0 * pfa


def test_stationary_points_are_rejected_movers_found_with_their_phase():
    blobs = [(100, 20, 300.0, 0.0), (300, 40, 300.0, 0.2), (480, 10, 100.0, -0.5)]
    z0, z1, t, r = _pair(blobs)
    cands, summary = detect(z0, z1, t, r, P, D, CfarKnobs(train=(60, 10), guard=(10, 3)))
    assert len(cands) == 2
    by_row = sorted(cands, key=lambda c: c.peak_row)
    for c, (row, col, _, phi) in zip(by_row, blobs[1:], strict=True):
        assert abs(c.peak_row - row) <= 1 and abs(c.peak_col - col) <= 1
        assert abs(c.ati_phase_rad - phi) < 4 * c.ati_phase_sigma_rad + 0.01
        tol = los_rate_from_phase(4 * c.ati_phase_sigma_rad + 0.01, D, P)
        assert abs(c.vr_los_mps - los_rate_from_phase(phi, D, P)) < tol
        assert c.confidence > 0.99 and not c.ati_ambiguous
    assert summary["min_vr_los_bright_mps"] < 2.0


def test_phase_near_pi_is_flagged_ambiguous():
    z0, z1, t, r = _pair([(300, 30, 300.0, 3.0)])
    (c,) = detect(z0, z1, t, r, P, D, CfarKnobs(train=(60, 10), guard=(10, 3)))[0]
    assert c.ati_ambiguous
    assert abs(c.ati_phase_rad - 3.0) < 0.05


def test_noise_only_gives_nothing():
    for seed in range(3):
        z0, z1, t, r = _pair([], seed=seed)
        assert detect(z0, z1, t, r, P, D, CfarKnobs(train=(60, 10), guard=(10, 3)))[0] == []
