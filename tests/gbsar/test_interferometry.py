"""Interferometric phase rates of [LeeGBSAR-I-2007] measured from simulated interferograms, PS coherence,
polarimetry and the mismatched-scan errors."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.errors import SarcliError
from sarcli.gbsar.focus import FocusOptions, Grid, image_from_scan
from sarcli.gbsar.interferometry import interfere
from sarcli.gbsar.polarimetry import normalized_difference
from sarcli.gbsar.scene import scene_from_dict
from sarcli.gbsar.simulate import simulate
from sarcli.gbsar.timeseries import ps_series, select_ps, temporal_coherence
from tests.gbsar.helpers import scene_dict

H = 21.0  # antenna height above the lawn ([LeeGBSAR-I-2007, §3])
BP = FocusOptions(algorithm="bp")


def _scan(points, effects=None, seed=1, **kw):
    d = scene_dict(points, bw=200e6, n=401, rail=5.0, height=H, effects=effects, seed=seed, **kw)
    return simulate(scene_from_dict(d))


def _ground(x, r0, h=0.0, **extra):
    """A point at height h seen at range r0 from the rail line at height H."""
    return {"x_m": x, "y_m": float(np.sqrt(r0 ** 2 - (H - h) ** 2)), "z_m": h, **extra}


def _pair(points, effects_b, grid):
    a = image_from_scan(_scan(points), BP, grid)
    b = image_from_scan(_scan(points, effects_b), BP, grid)
    return a, b


def _slope_deg(x, phase_rad):
    return float(np.polyfit(x, np.degrees(np.unwrap(phase_rad)), 1)[0])


def test_dinsar_rate_minus_12729_deg_per_m():
    d_mm = np.array([0.0, 0.5, 1.0, 1.5, 2.0])
    xs = np.array([-8.0, -4.0, 0.0, 4.0, 8.0])  # all inside the beam from the whole rail
    pts = [_ground(x, 100.0, los_displacement_mm=float(d)) for x, d in zip(xs, d_mm, strict=True)]
    grid = Grid(ranges=np.array([100.0]), azimuths=xs)
    a, b = _pair(pts, {"displacement": {"scale": 1.0}}, grid)
    ifg = interfere(a, b, "dinsar", "VV", window=1)
    rate = _slope_deg(d_mm * 1e-3, ifg.phase[0].astype(np.float64))
    assert rate == pytest.approx(-12729.0, rel=0.03)
    np.testing.assert_allclose(ifg.value[0], d_mm, atol=0.05)  # LOS displacement recovered (mm)


def test_crosstrack_range_and_height_rates():
    rs = np.arange(96.0, 104.1, 2.0)
    grid = Grid(ranges=rs, azimuths=np.array([0.0]))
    a, b = _pair([_ground(0.0, r) for r in rs], {"vertical_baseline": {"offset_m": -0.3}}, grid)
    ifg = interfere(a, b, "crosstrack", "VV", window=1)
    assert _slope_deg(rs, ifg.phase[:, 0].astype(np.float64)) == pytest.approx(-8.0, rel=0.03)
    hs = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    xs = np.array([-8.0, -4.0, 0.0, 4.0, 8.0])  # all inside the beam from the whole rail
    grid2 = Grid(ranges=np.array([100.0]), azimuths=xs)
    a, b = _pair([_ground(x, 100.0, h) for x, h in zip(xs, hs, strict=True)],
                 {"vertical_baseline": {"offset_m": -0.3}}, grid2)
    ifg = interfere(a, b, "crosstrack", "VV", window=1)
    assert _slope_deg(hs, ifg.phase[0].astype(np.float64)) == pytest.approx(-38.2, rel=0.03)
    np.testing.assert_allclose(ifg.value[0], hs, atol=0.1)  # heights after flat-surface removal (m)
    assert ifg.rate["height_ambiguity_at_100m_m"] == pytest.approx(9.4, abs=0.15)  # "9.5 m per fringe"


def test_deltaf_rate_24_deg_per_m():
    rs = np.arange(60.0, 140.1, 2.0)
    grid = Grid(ranges=rs, azimuths=np.array([0.0]))
    a, b = _pair([_ground(0.0, r) for r in rs], {"frequency_shift": {"shift_hz": -10e6}}, grid)
    ifg = interfere(a, b, "deltaf", "VV", window=1)
    assert _slope_deg(rs, ifg.phase[:, 0].astype(np.float64)) == pytest.approx(24.0, rel=0.03)
    assert ifg.rate["ambiguity_m"] == pytest.approx(15.0, rel=0.01)  # "15 m per fringe"
    assert np.all(np.abs(ifg.value[:, 0]) < 0.05)  # points exactly at the pixel ranges


def test_combined_rate_16_deg_per_m_at_100m():
    rs = np.arange(96.0, 104.1, 2.0)
    grid = Grid(ranges=rs, azimuths=np.array([0.0]))
    a, b = _pair([_ground(0.0, r) for r in rs],
                 {"vertical_baseline": {"offset_m": -0.3}, "frequency_shift": {"shift_hz": -10e6}}, grid)
    ifg = interfere(a, b, "combined", "VV", window=1)
    assert _slope_deg(rs, ifg.phase[:, 0].astype(np.float64)) == pytest.approx(16.0, rel=0.03)
    np.testing.assert_allclose(ifg.value[:, 0], 0.0, atol=0.1)  # ground points -> height 0


def test_mismatched_scans_are_clear_errors():
    grid = Grid(ranges=np.array([50.0]), azimuths=np.array([0.0]))
    a = image_from_scan(_scan([_ground(0.0, 50.0)]), BP, grid)
    d = scene_dict([_ground(0.0, 50.0)], bw=200e6, n=201, rail=5.0, height=H)
    other = image_from_scan(simulate(scene_from_dict(d)), BP, grid)
    with pytest.raises(SarcliError, match="different frequency grids"):
        interfere(a, other, "dinsar", "VV")
    shifted = image_from_scan(_scan([_ground(0.0, 50.0)], {"frequency_shift": {"shift_hz": -10e6}}), BP, grid)
    with pytest.raises(SarcliError, match="deltaf or combined"):
        interfere(a, shifted, "dinsar", "VV")
    g2 = Grid(ranges=np.array([50.0, 51.0]), azimuths=np.array([0.0]))
    with pytest.raises(SarcliError, match="different grids"):
        interfere(a, image_from_scan(_scan([_ground(0.0, 50.0)]), BP, g2), "dinsar", "VV")
    with pytest.raises(SarcliError, match="no vertical baseline"):
        interfere(a, a, "crosstrack", "VV")


def test_ps_coherence_stable_vs_decorrelated():
    """Nine scans ([LeeGBSAR-I-2007] P1-P9): stable points gamma > 0.99, phase change < 1 deg; clutter drops."""
    stable = [_ground(x, 40.0) for x in (-6.0, 0.0, 6.0)]
    clutter = {"x_m": [-8.0, 8.0], "y_m": [45.0, 55.0], "density_per_m2": 2.0, "scattering": 0.3, "seed": 5}
    grid = Grid(ranges=np.array([40.0] + list(np.arange(49.0, 55.0, 0.6))), azimuths=np.arange(-7.5, 7.6, 0.5))
    stack = []
    for seed in range(1, 10):
        d = scene_dict(stable, bw=200e6, n=401, rail=5.0, height=H, seed=seed,
                       effects={"decorrelation": {"coherence": 0.3}, "noise": {"power_db": -50.0}})
        d["clutter"] = clutter
        stack.append(image_from_scan(simulate(scene_from_dict(d)), BP, grid).image[0])
    stack = np.stack(stack)
    gamma = temporal_coherence(stack)
    cols = [int(np.argmin(abs(grid.azimuths - x))) for x in (-6.0, 0.0, 6.0)]
    assert np.all(gamma[0, cols] > 0.99)
    phase, disp = ps_series(stack[:, np.zeros(3, int), np.array(cols)].T, 299792458.0 / 5.3e9)
    assert np.max(np.abs(np.degrees(phase))) < 1.0
    assert np.median(gamma[1:]) < 0.9  # decorrelating clutter
    rows, cs = select_ps(gamma, np.mean(np.abs(stack), axis=0), 0.99)
    assert {(0, c) for c in cols} <= set(zip(rows.tolist(), cs.tolist(), strict=True))


def test_temporal_coherence_theory():
    """gamma = |sum z| / sum |z| ([LeeGBSAR-I-2007, §3.6]): unequal amplitudes tell it apart from |sum z| / N."""
    amp, ph = np.array([1.0, 3.0, 0.5, 2.0]), np.array([0.0, 0.1, -0.1, 0.05])
    z = (amp * np.exp(1j * ph))[:, None]
    assert temporal_coherence(z)[0] == pytest.approx(abs(np.sum(amp * np.exp(1j * ph))) / amp.sum())
    with pytest.raises(SarcliError):
        temporal_coherence(z[:1])


def test_polarimetric_normalized_difference():
    pts = [{"x_m": -5.0, "y_m": 40.0, "scattering": {"HH": 1.0}},
           {"x_m": 0.0, "y_m": 40.0, "scattering": {"HH": 1.0, "VV": 1.0}},
           {"x_m": 5.0, "y_m": 40.0, "scattering": {"VV": 1.0}}]
    s = simulate(scene_from_dict(scene_dict(pts, bw=200e6, n=401, rail=5.0, pols=("VV", "HH"))))
    img = image_from_scan(s, BP, Grid(ranges=np.array([40.0]), azimuths=np.array([-5.0, 0.0, 5.0])))
    nd = normalized_difference(img.pol("HH"), img.pol("VV"))
    np.testing.assert_allclose(nd[0], [1.0, 0.0, -1.0], atol=0.01)


def _synthetic(image, alg_map=None, report=None, **kw):
    """A one-polarization GbsarImage on a 1 m grid (ranges 40.., azimuths centred on the rail)."""
    from sarcli.model.gbsar import GbsarImage

    n_r, n_x = image.shape
    d = dict(image=image[None].astype(np.complex64), range_m=40.0 + np.arange(n_r, dtype=float),
             azimuth_m=np.arange(n_x, dtype=float) - n_x // 2, polarizations=("VV",), algorithm="bp",
             algorithm_map=np.full((n_r, n_x), 3, np.uint8) if alg_map is None else alg_map,
             center_frequency_hz=5.3e9, frequency_step_hz=5e5, n_freq=401, rail_height_m=H, rail_centre_m=0.0,
             rail_length_m=5.0, epoch_utc="2007-05-10T02:00:00Z", scan_time_s=0.0, report=report or {})
    d.update(kw)
    return GbsarImage(**d)


def test_value_masked_below_min_coherence_and_kept_on_coherent_pixels():
    """DInSAR value -phi lam/(4 pi) where the 5x5 coherence is 1; NaN where the phase is random."""
    rng = np.random.default_rng(3)
    n_r, n_x = 30, 40
    phi = np.full((n_r, n_x), -0.4)  # -0.4 rad = +0.180 mm LOS (theory: d = -phi lam / (4 pi))
    phi[:, 20:] = rng.uniform(-np.pi, np.pi, (n_r, 20))  # decorrelated half
    a = _synthetic(np.ones((n_r, n_x)))
    b = _synthetic(np.exp(1j * phi))
    ifg = interfere(a, b, "dinsar", "VV", window=5, min_coherence=0.5)
    lam = 299792458.0 / 5.3e9
    np.testing.assert_allclose(ifg.value[:, :17], 0.4 * lam / (4 * np.pi) * 1e3, rtol=1e-5)
    assert np.all(ifg.coherence[:, :17] > 0.999)
    assert np.all(np.isnan(ifg.value[:, 23:])) and np.all(ifg.coherence[:, 23:] < 0.5)
    assert np.all(np.isfinite(ifg.phase)) and np.all(np.isfinite(ifg.residual))  # only the value is thresholded
    kept = interfere(a, b, "dinsar", "VV", window=5, min_coherence=0.0)
    # without the threshold the value is defined wherever the unwrapper placed the pixel in a component
    np.testing.assert_array_equal(np.isfinite(kept.value), kept.component > 0)
    assert np.all(np.isfinite(kept.value[:, :17]))
    with pytest.raises(SarcliError, match="minimum coherence"):
        interfere(a, b, "dinsar", "VV", min_coherence=1.5)


def test_signed_zeros_outside_support_are_nan_not_pi():
    """Unsupported pixels hold +-0: angle() would give 0 or +-pi (bands of half-ambiguity heights)."""
    img = np.ones((10, 12), np.complex64)
    img[:, :3] = np.complex64(complex(-0.0, 0.0))  # DF: interpolated value times a zero aperture gain
    amap = np.full((10, 12), 1, np.uint8)
    amap[:, -2:] = 0  # not covered by the algorithm (non-zero leftovers must not count)
    a = _synthetic(img, amap)
    b = _synthetic(img * np.complex64(np.exp(0.3j)), amap, rail_height_m=H - 0.3)
    ifg = interfere(a, b, "crosstrack", "VV", window=1, min_coherence=0.0)
    for arr in (ifg.phase, ifg.coherence, ifg.residual, ifg.value):
        assert np.all(np.isnan(arr[:, :3])) and np.all(np.isnan(arr[:, -2:]))
        assert np.all(np.isfinite(arr[:, 3:-2]))


def test_pixels_outside_the_beam_footprint_are_nan_for_every_algorithm():
    """BP images 0 outside the footprint, RD leaks energy there: both masked by the footprint geometry
    |x| - X/2 > lam R0/(2 L_x) ([LeeGBSAR-II-2007, Fig. 2]); a bright target inside keeps its height."""
    lx, lam = 0.25, 299792458.0 / 5.3e9
    ant = {"length_azimuth_m": lx, "pattern": "sinc"}
    pts = [_ground(0.0, 50.0, 2.0), _ground(-4.0, 50.0)]
    grid = Grid(ranges=np.arange(46.0, 54.1, 1.0), azimuths=np.arange(-14.0, 14.1, 0.5))
    outside = (np.abs(grid.azimuths)[None, :] - 2.5) > lam * grid.ranges[:, None] / (2 * lx) + 1e-9
    assert outside.any() and (~outside).any()
    eff = {"antenna_pattern": {}}
    for alg in ("bp", "rd"):
        opts = FocusOptions(algorithm=alg)
        a = image_from_scan(_scan(pts, eff, antenna=ant), opts, grid)
        b = image_from_scan(_scan(pts, {**eff, "vertical_baseline": {"offset_m": -0.3}}, seed=2, antenna=ant),
                            opts, grid)
        ifg = interfere(a, b, "crosstrack", "VV", window=1)
        for arr in (ifg.phase, ifg.coherence, ifg.residual, ifg.value):
            assert np.all(np.isnan(arr[outside])), alg
        assert np.all(np.isfinite(ifg.phase[~outside])), alg
        i, j = int(np.argmin(abs(grid.ranges - 50.0))), int(np.argmin(abs(grid.azimuths)))
        assert ifg.value[i, j] == pytest.approx(2.0, abs=0.15), alg  # the 2 m high target keeps its height
