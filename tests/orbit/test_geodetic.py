"""ECEF <-> geodetic: PROJ plus a Newton polish, checked against ERFA (astropy) as an independent reference."""

from __future__ import annotations

import numpy as np
import pytest

from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef


@pytest.mark.parametrize("h", [0.0, 5e3, 8e5, 3.6e7])
def test_round_trip_exact_at_any_height(h):
    lat = np.linspace(-90, 90, 721)
    lon = np.linspace(-180, 180, 721)
    la, lo, hh = ecef_to_geodetic(geodetic_to_ecef(lat, lon, np.full_like(lat, h)))
    assert np.abs(la - lat).max() * 111e3 < 1e-7
    assert np.abs(hh - h).max() < 1e-7
    inner = np.abs(lat) < 89.999
    dlon = (lo - lon + 180) % 360 - 180
    assert np.abs(dlon[inner]).max() < 1e-10


def test_agrees_with_erfa_gc2gd():
    erfa = pytest.importorskip("erfa")
    rng = np.random.default_rng(3)
    r = rng.normal(size=(200, 3))
    r *= (rng.uniform(6.36e6, 7.3e6, 200) / np.linalg.norm(r, axis=1))[:, None]
    lat, lon, h = ecef_to_geodetic(r)
    elong, phi, height = erfa.gc2gd(1, r)  # 1 = WGS84
    assert np.abs(np.radians(lat) - phi).max() * 6.4e6 < 1e-5  # ERFA itself is good to ~us
    assert np.abs(np.radians(lon) - elong).max() * 6.4e6 < 1e-6
    assert np.abs(h - height).max() < 1e-6


def test_proj_inverse_alone_is_mm_off_at_orbit_height():
    """The reason for the Newton polish: PROJ's non-iterative inverse at 800 km altitude."""
    from orbit.geodetic import _to_geodetic

    lat = np.linspace(-80, 80, 161)
    r = geodetic_to_ecef(lat, 0 * lat + 10.0, 0 * lat + 8e5)
    _, la, h = _to_geodetic().transform(r[:, 0], r[:, 1], r[:, 2])
    assert np.abs(np.asarray(h) - 8e5).max() > 1e-3  # ~5 mm
    assert np.abs(ecef_to_geodetic(r)[2] - 8e5).max() < 1e-7
