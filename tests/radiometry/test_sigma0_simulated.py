"""Calibrated backscatter of simulated scenes against the radar equation of the scene file.

The scene (``scenes/clutter.toml``) is read here with ``tomllib``, not through the simulator: the
expected values are what its author stated, never the simulator's bookkeeping (/truth) nor the code
under test. The radar equation of that scene (sarcli's simulator is a unit radar: transmitted power,
peak antenna gains, receiver gain and (4 pi)^3 are 1, and there is no 1/R^4):

    received amplitude of a scatterer of RCS s:  sqrt(s) G_az G_el,  G = sinc^2(L sin(psi) / lam)
    a clutter patch of backscatter sigma0:       scatterers with sum |a_i|^2 = sigma0 x (its ground area)
    thermal noise:                               E|n|^2 = noise_power per raw complex sample

so a calibrated product must give back sigma0 for each patch (the antenna patterns and every processing
gain removed), RCS = amplitude^2 for the point target, and a noise floor (NESZ) that is the sigma0 of
the noise-only pixels.

Error analysis (tolerances of the issue: 0.3 dB mid-swath, 0.5 dB at the swath's edges, 0.3 dB for the
point target, 1 dB for the NESZ). Statistical: a patch window holds about 70 columns x 400 lines; the
range IRF spans ~4.9 samples (4.5x oversampled chirp) and the azimuth one ~1.3 lines, so ~4000
independent looks of a speckle whose intensity variance is at most twice exponential (about two
scatterers per resolution cell): 2.2 % (0.1 dB) at 1 sigma, plus the subtracted noise floor of the
weak patch (4 dB below it, its own 2 % fluctuation: 0.05 dB). Model: the range gain is exact on the
filter; the stationary-phase azimuth gain is within 0.1 % at a time-bandwidth product of 566; the
elevation pattern is evaluated on the beam-centre geometry (0.01 dB from the simulator's angle at
mid-swath); the patches' edges are kept 20 % of their width away (the IRF's sidelobes). Point target:
its integrated energy (33 x 33 pixels, the ring to 24 pixels as background): the truncated sidelobes
(< 1 %) and the cross-term with the noise (0.4 % at 1 sigma for RCS 9e4 m^2).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

SCENE = Path(__file__).parent / "scenes" / "clutter.toml"
pytestmark = pytest.mark.slow


def _stated():
    doc = tomllib.loads(SCENE.read_text())
    return doc["clutter"], doc["targets"][0], doc["noise"]["noise_power"]


@pytest.fixture(scope="module")
def raw_path(tmp_path_factory):
    from sarcli.workflows import simulate

    out = tmp_path_factory.mktemp("radiometry") / "raw.h5"
    simulate.run(simulate.Config(scene=SCENE, output=out))
    return out


def _focus(raw_path, algorithm, **options):
    from sarcli.io.raw import read_raw
    from sarcli.io.slc import read_slc
    from sarcli.workflows import focus

    raw = read_raw(raw_path, load_echo=False)
    # the Doppler of the geometry (as from an orbit): mid-swath centroid and rate of the scene
    fdc = float(np.median(raw.truth["doppler_centroid_hz"]))
    fr = float(np.median(raw.truth["doppler_rate_hz_per_s"]))
    name = "_".join([algorithm] + [f"{k}{v}" for k, v in sorted(options.items())]).replace(":", "")
    out = raw_path.parent / f"{name}.h5".replace(" ", "").replace("(", "").replace(")", "").replace(",", "_")
    focus.run(focus.Config(raw=raw_path, output=out, fdc=fdc, fr=fr, algorithm=algorithm, options=options))
    slc = read_slc(out)
    slc.parameters["path"] = str(out)
    return slc


def _closest_range(slc, rho: float) -> float:
    """Zero-Doppler range of a scatterer the scene places at beam-centre range rho (geometry, not radiometry:
    R0 = rho cos(squint), the squint of the product's Doppler)."""
    from sarcli.focus.kinematics import velocity_and_squint

    d = slc.doppler
    k = np.argmin(np.abs(d.range_m - rho))
    _, s = velocity_and_squint(d.fdc_hz[0, k], d.fr_hz_per_s[0, k], rho, slc.radar.wavelength_m)
    return float(rho * math.sqrt(1.0 - float(s) ** 2))


def _rows(slc, centre_row: int, half: int = 200) -> slice:
    return slice(max(centre_row - half, slc.first_full_line), min(centre_row + half, slc.last_full_line + 1))


def _target(slc, r0: float) -> tuple[int, int]:
    j0 = int(np.argmin(np.abs(slc.slant_range - r0)))
    p = np.abs(slc.image[:, j0 - 10:j0 + 11]) ** 2
    i, j = np.unravel_index(np.argmax(p), p.shape)
    return int(i), int(j + j0 - 10)


def _patch_sigma0(slc, rows: slice, r0: float, half_width_m: float) -> float:
    """Mean calibrated sigma0 (noise floor subtracted) over the central 60 % of a patch."""
    from sarcli.calibration.radiometry import lut_on

    r, t = slc.slant_range, slc.azimuth_time
    cols = np.flatnonzero(np.abs(r - r0) < 0.6 * half_width_m)
    lut = lut_on(slc.calibration, "sigma0", t[rows], r[cols])
    nes0 = lut_on(slc.calibration, "nes0", t[rows], r[cols])
    p = np.abs(slc.image[rows, cols].astype(np.complex128)) ** 2
    return float(np.mean(p * lut) - np.mean(nes0))


def _check_scene(slc, tolerance_mid=0.3, tolerance_edge=0.5):
    clutter, target, _ = _stated()
    rt = _closest_range(slc, target["slant_range_m"])
    row, _ = _target(slc, rt)
    rows = _rows(slc, row)
    sin_inc = float(np.nanmedian(slc.calibration.sigma0 / slc.calibration.beta0))
    got = []
    for patch in clutter:
        r0 = _closest_range(slc, patch["slant_range_m"])
        half = 0.5 * patch["range_extent_m"] * sin_inc  # ground extent -> slant
        got.append(10 * np.log10(_patch_sigma0(slc, rows, r0, half)) - patch["sigma0_db"])
    near, mid, far = got
    assert abs(mid) < tolerance_mid, got
    assert abs(near) < tolerance_edge and abs(far) < tolerance_edge, got
    return got


@pytest.fixture(scope="module")
def rd(raw_path):
    return _focus(raw_path, "rd")


def test_rd_sigma0_of_patches_across_the_swath(rd):
    cal = rd.calibration
    assert not cal.not_applied
    # the elevation pattern falls by several dB from mid-swath to the edges: the test has teeth
    b = cal.beta0[cal.beta0.shape[0] // 2]
    assert 10 * np.log10(np.nanmax(b) / np.nanmin(b)) > 3.0
    _check_scene(rd)


def test_rd_point_target_rcs_by_integrated_energy(rd):
    from sarcli.calibration.radiometry import point_rcs

    _, target, _ = _stated()
    i, j = _target(rd, _closest_range(rd, target["slant_range_m"]))
    rcs = point_rcs(rd, i, j)
    assert abs(10 * np.log10(rcs / target["amplitude"] ** 2)) < 0.3


def test_rd_noise_floor_is_the_sigma0_of_noise_only_pixels(rd):
    """NESZ of the product (from the stated receiver noise) vs the sigma0 of the pixels between the near
    and mid patches (noise only, 60 m from either patch's edge: the IRF's sidelobes below -30 dB)."""
    from sarcli.calibration.radiometry import lut_on

    clutter, _, p_n = _stated()
    sin_inc = float(np.nanmedian(rd.calibration.sigma0 / rd.calibration.beta0))
    a = _closest_range(rd, clutter[0]["slant_range_m"]) + 0.5 * clutter[0]["range_extent_m"] * sin_inc
    b = _closest_range(rd, clutter[1]["slant_range_m"]) - 0.5 * clutter[1]["range_extent_m"] * sin_inc
    cols = np.flatnonzero((rd.slant_range > a + 100) & (rd.slant_range < b - 100))
    assert cols.size > 20
    rows = slice(rd.first_full_line, rd.last_full_line + 1)
    t, r = rd.azimuth_time[rows], rd.slant_range[cols]
    measured = np.mean(np.abs(rd.image[rows, cols].astype(np.complex128)) ** 2 * lut_on(rd.calibration, "sigma0",
                                                                                          t, r))
    product = np.mean(lut_on(rd.calibration, "nes0", t, r))
    assert rd.calibration.details["noise_power"] == p_n
    assert abs(10 * np.log10(measured / product)) < 1.0
    import h5py

    with h5py.File(rd.parameters["path"]) as f:  # the noise floor per column, beside the image
        per = f["calibration/nes0_per_sample"][()]
    assert per.shape == rd.slant_range.shape
    assert 10 * np.log10(np.mean(per[cols]) / product) == pytest.approx(0.0, abs=0.05)


@pytest.mark.parametrize("options", [
    {"range_window": "rect", "azimuth_window": "rect"},
    {"range_window": "hamming", "azimuth_window": "hamming:0.6", "range_bandwidth_fraction": 0.8},
    {"block_lines": 512, "rcmc_oversample": 1, "azimuth_bandwidth_hz": 800.0},
])
def test_rd_sigma0_does_not_depend_on_windows_bands_blocks(raw_path, options):
    _check_scene(_focus(raw_path, "rd", **options))


@pytest.mark.parametrize("options", [{}, {"range_window": "rect", "azimuth_window": "hamming", "block_lines": 150}])
def test_backprojection_sigma0_and_point_target(raw_path, options):
    from sarcli.calibration.radiometry import point_rcs

    slc = _focus(raw_path, "backprojection", lines=(700, 1100), upsample=4, **options)
    _check_scene(slc)
    _, target, _ = _stated()
    i, j = _target(slc, _closest_range(slc, target["slant_range_m"]))
    assert abs(10 * np.log10(point_rcs(slc, i, j) / target["amplitude"] ** 2)) < 0.3


def _reflector_csv(slc, path: Path, rcs_m2: float) -> None:
    """A NISAR corner-reflector CSV with one trihedral on the scene's point target, its boresight on the line
    of sight (CSV angles as ISCE3 reads them: azimuth = boresight heading from east, clockwise; tilt =
    boresight elevation - 35.26 deg), its side making ``rcs_m2`` = 4 pi a^4 / (3 lam^2)."""
    from orbit.geodetic import geodetic_to_ecef
    from sarcli.calibration.predict import image_orbit
    from sarcli.calibration.reflectors import enu_basis

    tg = slc.truth["targets"][0]
    p = np.asarray(geodetic_to_ecef(tg["lat_deg"], tg["lon_deg"], tg["height_m"]), np.float64)
    sat = image_orbit(slc).interpolate(np.array([tg["zero_doppler_time_s"]]))[0][0]
    u = enu_basis(tg["lat_deg"], tg["lon_deg"]).T @ ((sat - p) / np.linalg.norm(sat - p))
    heading = math.degrees(math.atan2(u[0], u[1]))
    elevation = math.degrees(math.asin(u[2]))
    side = (rcs_m2 * 3 * slc.radar.wavelength_m**2 / (4 * math.pi)) ** 0.25
    path.write_text(f"CR1,{tg['lat_deg']:.9f},{tg['lon_deg']:.9f},{tg['height_m']:.3f},{heading - 90.0:.6f},"
                    f"{elevation - math.degrees(math.asin(1 / math.sqrt(3))):.6f},{side:.6f},"
                    "2002-06-01T00:00:00Z,7,0,0,0\n")


def test_quality_reports_reflector_rcs_and_calibrate_derives_k(rd, cli, tmp_path):
    """The scene's target (RCS amplitude^2 = 9e4 m^2) surveyed as a trihedral whose theoretical RCS is half
    of it: the product (K = 1, the simulator's unit radar) measures it 3.01 dB above theory; calibrate
    must find K = 2 (within the point target's 0.3 dB) and the calibrated product read the reflector's RCS."""
    import json

    from sarcli.calibration.radiometry import point_rcs
    from sarcli.io.slc import read_slc

    _, target, _ = _stated()
    csv = tmp_path / "cr.csv"
    _reflector_csv(rd, csv, 0.5 * target["amplitude"] ** 2)
    r = cli("quality", rd.parameters["path"], "--corner-reflectors", csv, "--json")
    assert r.exit_code == 0, r.stderr
    (rec,) = json.loads(r.stdout)
    assert rec["rcs_theory_dbsm"] == pytest.approx(10 * np.log10(0.5 * target["amplitude"] ** 2), abs=0.01)
    assert rec["rcs_dbsm"] == pytest.approx(10 * np.log10(target["amplitude"] ** 2), abs=0.3)
    assert rec["rcs_error_db"] == pytest.approx(10 * np.log10(2.0), abs=0.3)
    out = tmp_path / "cal.h5"
    r = cli("calibrate", rd.parameters["path"], "--corner-reflectors", csv, "-o", out)
    assert r.exit_code == 0, r.stderr
    cal = read_slc(out)
    assert 10 * np.log10(cal.calibration.constant / 2.0) == pytest.approx(0.0, abs=0.3)
    assert any("measured" in a for a in cal.calibration.applied)
    i, j = _target(cal, _closest_range(cal, target["slant_range_m"]))
    assert 10 * np.log10(point_rcs(cal, i, j) / (0.5 * target["amplitude"] ** 2)) == pytest.approx(0.0, abs=0.05)


class _Plane:
    """Terrain facing the radar with slope alpha (rising AWAY from it): height = tan(alpha) x (the horizontal
    distance from a point away from the radar), in a local tangent plane (east/north metres from lat0, lon0)."""

    def __init__(self, lat0, lon0, toward_e, toward_n, alpha):
        self.lat0, self.lon0, self.e, self.n, self.k = lat0, lon0, toward_e, toward_n, math.tan(alpha)

    def height(self, lat, lon):
        east = (np.asarray(lon) - self.lon0) * 111319.49 * math.cos(math.radians(self.lat0))
        north = (np.asarray(lat) - self.lat0) * 111132.95
        return self.k * (east * self.e + north * self.n)

    def describe(self):
        return {"kind": "plane"}


@pytest.mark.parametrize("alpha_deg", [0.0, 6.0, -10.0])
def test_gamma0_flattening_of_a_plane(rd, alpha_deg):
    """A_beta / A_gamma of a plane facing the radar with slope alpha is tan(theta_i - alpha) (the pixel's
    ground extent dr / sin(theta - alpha) seen at local incidence theta - alpha, projected normal to the
    line of sight: dr dx cot(theta - alpha)). Interior pixels, mean within 2 % (the facets are binned to
    whole pixels: the per-pixel area is noisy, its mean is not)."""
    from sarcli.calibration.products import flattening
    from sarcli.calibration.radiometry import node_geometry
    from sarcli.calibration.reflectors import enu_basis
    from sarcli.focus.geolocation import platform_state, zero_doppler_points

    la, lr = 16, 16
    n, m = rd.azimuth_time.size // la, rd.slant_range.size // lr
    t0, r0 = rd.azimuth_time[n * la // 2], rd.slant_range[m * lr // 2]
    p0 = zero_doppler_points(rd.orbit, rd.epoch_utc, t0, r0, rd.radar.wavelength_m, rd.look_side)
    from orbit.geodetic import ecef_to_geodetic

    lat0, lon0, _ = (float(x) for x in ecef_to_geodetic(p0))
    sat, _ = platform_state(rd.orbit, rd.epoch_utc, np.array([t0]))
    u = enu_basis(lat0, lon0).T @ (sat[0] - p0)
    h = -u[:2] / np.linalg.norm(u[:2])  # horizontal, away from the radar
    alpha = math.radians(alpha_deg)
    ratio = flattening(rd, la, lr, (n, m), _Plane(lat0, lon0, h[0], h[1], alpha))
    inner = ratio[n // 4: 3 * n // 4, m // 4: 3 * m // 4]
    assert np.isfinite(inner).all()
    theta = float(node_geometry(rd, np.array([t0]), np.array([r0]), 0.0).incidence[0, 0])
    assert np.mean(inner) == pytest.approx(math.tan(theta - alpha), rel=0.02)


@pytest.mark.parametrize("alpha_deg", [45.0, -56.0])
def test_gamma0_masks_layover_and_shadow(rd, alpha_deg):
    """Facing the radar steeper than the incidence (39 deg): layover; facing away steeper than its
    complement (51 deg): shadow. Every interior pixel is nodata."""
    from orbit.geodetic import ecef_to_geodetic
    from sarcli.calibration.products import flattening
    from sarcli.calibration.reflectors import enu_basis
    from sarcli.focus.geolocation import platform_state, zero_doppler_points

    la, lr = 16, 16
    n, m = rd.azimuth_time.size // la, rd.slant_range.size // lr
    t0, r0 = rd.azimuth_time[n * la // 2], rd.slant_range[m * lr // 2]
    p0 = zero_doppler_points(rd.orbit, rd.epoch_utc, t0, r0, rd.radar.wavelength_m, rd.look_side)
    lat0, lon0, _ = (float(x) for x in ecef_to_geodetic(p0))
    sat, _ = platform_state(rd.orbit, rd.epoch_utc, np.array([t0]))
    u = enu_basis(lat0, lon0).T @ (sat[0] - p0)
    h = -u[:2] / np.linalg.norm(u[:2])
    ratio = flattening(rd, la, lr, (n, m), _Plane(lat0, lon0, h[0], h[1], math.radians(alpha_deg)))
    assert np.isnan(ratio[n // 4: 3 * n // 4, m // 4: 3 * m // 4]).all()


def test_nisar_rslc_export_carries_the_luts(rd, cli, tmp_path):
    import h5py

    out = tmp_path / "rslc.h5"
    r = cli("export", rd.parameters["path"], "--format", "nisar-rslc", "-o", out)
    assert r.exit_code == 0, r.stderr
    cal = rd.calibration
    with h5py.File(out) as f:
        ci = f["science/LSAR/RSLC/metadata/calibrationInformation"]
        for name in ("beta0", "sigma0", "gamma0"):
            np.testing.assert_allclose(ci["geometry"][name][()], getattr(cal, name), rtol=1e-6)
        np.testing.assert_allclose(ci["geometry/slantRange"][()], cal.slant_range)
        np.testing.assert_allclose(ci["frequencyA/HH/nes0"][()], cal.nes0, rtol=1e-6)
        assert ci["absoluteCalibrationConstant"][()] == cal.constant


def test_sigma0_geotiff_with_noise_subtraction(raw_path, rd, cli, tmp_path):
    """``focus --geotiff-slant --radiometry sigma0 --noise-subtraction``: band 2 in dB with its units and the
    radiometry in the tags; the mid patch's mean sigma0 (linear mean of the looks, noise subtracted) as stated."""
    import rasterio

    clutter, _, _ = _stated()
    tr = rd.truth
    tif = tmp_path / "s0.tif"
    r = cli("focus", raw_path, "-o", tmp_path / "slc.h5", "--fdc", str(float(np.median(tr["doppler_centroid_hz"]))),
            "--fr", str(float(np.median(tr["doppler_rate_hz_per_s"]))), "--geotiff-slant", tif, "--radiometry",
            "sigma0", "--noise-subtraction", "--looks-az", "4", "--looks-rg", "3")
    assert r.exit_code == 0, r.stderr
    assert "not applied" not in r.stderr
    with rasterio.open(tif) as ds:
        tags = ds.tags()
        assert ds.units == ("1", "dB") and tags["RADIOMETRY"] == "sigma0" and tags["NOISE_SUBTRACTED"] == "yes"
        assert tags["RADIOMETRY_NOT_APPLIED"] == "none" and tags["CALIBRATION_CONSTANT_K"] == "1"
        assert float(tags["NESZ_SIGMA0_DB_MEDIAN"]) == pytest.approx(10 * np.log10(np.nanmedian(rd.calibration.nes0)),
                                                                     abs=0.01)
        db = ds.read(2)
    sin_inc = float(np.nanmedian(rd.calibration.sigma0 / rd.calibration.beta0))
    r0 = _closest_range(rd, clutter[1]["slant_range_m"])
    half = 0.5 * clutter[1]["range_extent_m"] * sin_inc
    cols = np.flatnonzero(np.abs(rd.slant_range[: db.shape[1] * 3].reshape(-1, 3).mean(axis=1) - r0) < 0.6 * half)
    rows = _rows(rd, _target(rd, _closest_range(rd, _stated()[1]["slant_range_m"]))[0])
    lin = 10.0 ** (db[rows.start // 4: rows.stop // 4, cols] / 10.0)
    assert abs(10 * np.log10(np.nanmean(lin)) - clutter[1]["sigma0_db"]) < 0.3


@pytest.mark.parametrize("algorithm", ["csa", "omegak"])
def test_fft_focusers_sigma0_and_point_target(raw_path, algorithm):
    """csa and omegak declare RD's frequency-domain azimuth compression and keep RD's range scale: the same
    radiometric model must then give the stated sigma0 and RCS within the same bars."""
    from sarcli.calibration.radiometry import point_rcs

    slc = _focus(raw_path, algorithm)
    _check_scene(slc)
    _, target, _ = _stated()
    i, j = _target(slc, _closest_range(slc, target["slant_range_m"]))
    assert abs(10 * np.log10(point_rcs(slc, i, j) / target["amplitude"] ** 2)) < 0.3
