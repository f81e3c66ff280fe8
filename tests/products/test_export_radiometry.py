"""``sarcli export --radiometry`` and SICD's Radiometric block, checked against the SLC's look-up tables by
an independent path.

The SLC is the product tests' small simulated RADARSAT-1-like scene (tests/products/conftest.py) with a
``/calibration`` of stated look-up tables of the radar equation's shape: L_beta0(t, R) = c (R / R_0)^3 /
G_el(R)^2 (range spreading and a two-way sinc^2 elevation pattern whose main lobe spans the swath),
sigma0 = L_beta0 sin(theta), gamma0 = L_beta0 tan(theta) with cos(theta) = H / R (flat Earth, H = 790 km),
NES0 = 1e-3 L_sigma0 x (noise power 1e3 |DN|^2), a slow azimuth drift of 0.2 dB, and the last range node
NaN (not calibrated). The expected values are these tables interpolated bilinearly by scipy's
``RegularGridInterpolator`` here, not by sarcli.

Error analysis. ENVI: the dB image is float32 (|dB| < 64: a rounding step of 2^-18 x 64, 4e-6 dB); the
intensity is cast to float32 before the log (relative 6e-8: 3e-7 dB); the bilinear interpolation is the
same operation in both paths (1e-12 relative): 1e-4 dB bounds all of it. SICD: the writer fits on a 48 x 48
grid of pixels and reports its largest misfit there; here every 7th pixel is checked. Between the fit's grid
pixels the bilinear table bends at its nodes (13 range nodes: a node interval holds ~4 grid pixels)
while the polynomial does not; the fit's residual, a smooth function of degree <= 7 of its own, plus the
kinks' departure from linear over one grid interval (h^2 |f''| / 8 with h a quarter of a node interval:
1/16 of the tables' own interpolation error, 0.17 dB here, i.e. 0.011 dB) stays below the reported misfit
+ 0.02 dB. The reported misfit itself is no worse than the tables' bilinear interpolation of the smooth
law they sample (+ 0.02 dB): the polynomial follows the law, not the interpolation's corners.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from sarcli.model.slc import Calibration

H_M = 790e3


def _law(slc, t: np.ndarray, r: np.ndarray) -> dict[str, np.ndarray]:
    """The smooth tables (module docstring) on the axes t x r of ``slc``'s scene."""
    t0, t1, r_lo, r_hi = slc.azimuth_time[0], slc.azimuth_time[-1], slc.slant_range[0], slc.slant_range[-1]
    r0 = 0.5 * (r_lo + r_hi)
    u = 0.9 * (r - r0) / (r_hi - r_lo)  # the swath spans +-0.45 of the elevation main lobe's half width
    drift = 10 ** (0.02 * (t - t0) / (t1 - t0))  # 0.2 dB along the scene
    beta = 1e-3 * drift[:, None] * ((r / r0) ** 3 / np.sinc(u) ** 4)[None, :]
    theta = np.arccos(H_M / r)
    sigma = beta * np.sin(theta)
    return {"beta0": beta, "sigma0": sigma, "gamma0": beta * np.tan(theta), "nes0": 1e-3 * sigma * (r / r0) ** 2}


def _tables(slc) -> Calibration:
    t = np.linspace(slc.azimuth_time[0], slc.azimuth_time[-1], 9)
    r = np.linspace(slc.slant_range[0], slc.slant_range[-1], 13)
    law = _law(slc, t, r)
    for v in law.values():
        v[:, -1] = np.nan  # the last range node: not calibrated
    return Calibration(t, r, law["beta0"], law["sigma0"], law["gamma0"], law["nes0"], 1.0, ("stated tables",),
                       ("absolute calibration constant K (test tables)",),
                       {"compressed_range_m": [float(r[0]), float(r[-1])], "noise_source": "stated"})


@pytest.fixture(scope="module")
def calibrated(small, tmp_path_factory):
    from dataclasses import replace

    from sarcli.io.slc import read_slc, write_slc

    slc = read_slc(small.slc)
    d = tmp_path_factory.mktemp("cal")
    with_cal, without = d / "cal.h5", d / "nocal.h5"
    write_slc(with_cal, replace(slc, calibration=_tables(slc)))
    write_slc(without, replace(slc, calibration=None))
    return with_cal, without


def _expected(cal: Calibration, kind: str, t: np.ndarray, r: np.ndarray) -> np.ndarray:
    from scipy.interpolate import RegularGridInterpolator

    f = RegularGridInterpolator((cal.azimuth_time, cal.slant_range), getattr(cal, kind), method="linear")
    tt, rr = np.meshgrid(t, r, indexing="ij")
    return f(np.stack([tt, rr], axis=-1))


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["beta0", "sigma0", "gamma0"])
def test_envi_radiometry_is_10log10_of_dn2_times_the_lut(cli, calibrated, tmp_path, kind):
    import rasterio

    from sarcli.io.slc import read_slc

    out = tmp_path / f"{kind}.img"
    r = cli("export", calibrated[0], "--format", "envi", "--radiometry", kind, "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    assert "not applied: absolute calibration constant K" in r.stderr  # relative backscatter, said so
    details = json.loads(r.stdout)["details"]
    assert details["radiometry"] == kind and details["units"] == "dB"
    slc = read_slc(calibrated[0])
    want = 10 * np.log10(np.abs(slc.image.astype(np.complex128)) ** 2
                         * _expected(slc.calibration, kind, slc.azimuth_time, slc.slant_range))
    with rasterio.open(out) as ds:
        got = ds.read(1)
        assert ds.dtypes[0] == "float32" and kind in ds.descriptions[0]
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    assert np.isnan(got).any() and not np.isnan(got).all()
    ok = np.isfinite(want)
    assert np.max(np.abs(got[ok] - want[ok])) < 1e-4
    hdr = (tmp_path / f"{kind}.hdr").read_text()
    assert "data units = {dB}" in hdr and "data type = 4" in hdr
    assert f"band names = {{\n{kind} in dB" in hdr or f"band names = {{{kind} in dB" in hdr
    assert "not applied: absolute calibration constant K (test tables)" in hdr


@pytest.mark.slow
def test_sicd_radiometric_polynomials_reproduce_the_luts(cli, calibrated, tmp_path):
    import sarkit.sicd as sksicd
    import sarkit.verification as skver

    from sarcli.io.slc import read_slc
    from tests.products.test_export import KNOWN_WARNINGS

    out = tmp_path / "x.nitf"
    r = cli("export", calibrated[0], "--format", "sicd", "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    fit = json.loads(r.stdout)["details"]["radiometric_fit_db"]
    assert set(fit) == {"beta0", "sigma0", "gamma0", "noise"}
    with open(out, "rb") as f:
        con = skver.SicdConsistency.from_file(f)
        con.check()
    assert set(con.failures()) <= KNOWN_WARNINGS, {k: str(v)[:300] for k, v in con.failures().items()}
    with open(out, "rb") as f:
        tree = sksicd.NitfReader(f).metadata.xmltree
    xml = sksicd.XmlHelper(tree)
    slc = read_slc(calibrated[0])
    cal = slc.calibration
    # SICD image coordinates of every 7th pixel: xrow, ycol = (pixel - SCPPixel) x SS (right-looking: columns
    # are the lines in time order)
    assert slc.look_side == "right"
    scp = xml.load("./{*}ImageData/{*}SCPPixel")
    row_ss, col_ss = xml.load("./{*}Grid/{*}Row/{*}SS"), xml.load("./{*}Grid/{*}Col/{*}SS")
    rows, cols = np.arange(0, slc.image.shape[1], 7), np.arange(0, slc.image.shape[0], 7)
    xrow, ycol = np.meshgrid((rows - scp[0]) * row_ss, (cols - scp[1]) * col_ss, indexing="ij")
    for kind, name in (("beta0", "BetaZero"), ("sigma0", "SigmaZero"), ("gamma0", "GammaZero")):
        sf = np.polynomial.polynomial.polyval2d(xrow, ycol, xml.load(f"./{{*}}Radiometric/{{*}}{name}SFPoly"))
        want = _expected(cal, kind, slc.azimuth_time[cols], slc.slant_range[rows]).T
        ok = np.isfinite(want)
        assert ok.mean() > 0.9
        assert np.max(np.abs(10 * np.log10(sf[ok] / want[ok]))) < fit[kind] + 0.02, kind
        # the stated misfit is no worse than the tables' own bilinear interpolation of the smooth law
        law = _law(slc, slc.azimuth_time[cols], slc.slant_range[rows])[kind].T
        assert fit[kind] < np.max(np.abs(10 * np.log10(law[ok] / want[ok]))) + 0.02, kind
    bw = xml.load("./{*}Grid/{*}Row/{*}ImpRespBW") * xml.load("./{*}Grid/{*}Col/{*}ImpRespBW")
    np.testing.assert_allclose(xml.load("./{*}Radiometric/{*}RCSSFPoly") * bw,
                               xml.load("./{*}Radiometric/{*}BetaZeroSFPoly"), rtol=1e-12)
    assert xml.load("./{*}Radiometric/{*}NoiseLevel/{*}NoiseLevelType") == "ABSOLUTE"
    noise_db = np.polynomial.polynomial.polyval2d(xrow, ycol, xml.load("./{*}Radiometric/{*}NoiseLevel/{*}NoisePoly"))
    want = 10 * np.log10(_expected(cal, "nes0", slc.azimuth_time[cols], slc.slant_range[rows])
                         / _expected(cal, "sigma0", slc.azimuth_time[cols], slc.slant_range[rows])).T
    ok = np.isfinite(want)
    assert np.max(np.abs(noise_db[ok] - want[ok])) < fit["noise"] + 0.02


@pytest.mark.slow
def test_radiometry_refusals(cli, calibrated, tmp_path):
    with_cal, without = calibrated
    for fmt in ("nisar-rslc", "sicd"):
        r = cli("export", with_cal, "--format", fmt, "--radiometry", "sigma0", "-o", tmp_path / f"x.{fmt}")
        assert r.exit_code == 2 and r.stderr.startswith("sarcli: error:") and "no meaning" in r.stderr
        assert len(r.stderr.strip().splitlines()) == 1
    r = cli("export", without, "--format", "envi", "--radiometry", "beta0", "-o", tmp_path / "x.img")
    assert r.exit_code == 2 and "carries no radiometric calibration" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "x.img").exists()
    r = cli("export", with_cal, "--format", "envi", "--radiometry", "sigma", "-o", tmp_path / "x.img")
    assert r.exit_code == 2 and r.stderr.startswith("sarcli: error:")
    # without calibration the SICD has no Radiometric block (nothing invented)
    r = cli("export", without, "--format", "sicd", "-o", tmp_path / "n.nitf", "--json")
    assert r.exit_code == 0 and "radiometric_fit_db" not in json.loads(r.stdout)["details"]
