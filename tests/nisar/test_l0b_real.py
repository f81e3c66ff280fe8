"""The real ALOS-1 PALSAR L0B cut (../shared/data/alos_palsar_l0b): decoding, calibration lines, timing,
chirp, orbit and attitude, Doppler (data vs orbit + attitude quaternions), partial focusing.

Expected values come from the file itself read with plain h5py, from scipy's quaternion algebra and
pyproj (independent of sarcli.io.nisar), or from stated physics; never from the reader's output.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation, Slerp

C = 299_792_458.0
TX = "science/LSAR/RRSD/swaths/frequencyA/txH"
TEL = "science/LSAR/RRSD/lowRateTelemetry"


@pytest.fixture(scope="module")
def f(l0b_path):
    with h5py.File(l0b_path, "r") as fh:
        yield fh


def test_samples_are_a_plain_lookup_of_the_codes(f, l0b_raw):
    codes = f[f"{TX}/rxH/HH"][()]
    lut = f[f"{TX}/rxH/BFPQLUT"][()]
    plain = lut[codes["r"]] + 1j * lut[codes["i"]]
    cal = f[f"{TX}/calType"][()] != 0
    assert l0b_raw.echo.dtype == np.complex64
    np.testing.assert_array_equal(l0b_raw.echo[~cal], plain[~cal])
    # ALOS 5-bit: the LUT maps the codes 0..31 to -15.5..15.5 (DC bias removed by ISCE3's repackaging)
    assert set(np.unique(codes["r"])) <= set(range(32)) and l0b_raw.radar.quantization_bits == 5


def test_calibration_lines_kept_apart_and_never_echoes(f, l0b_raw):
    cal_type = f[f"{TX}/calType"][()]
    lines = np.flatnonzero(cal_type != 0)
    assert lines.size == 2  # ISCE3's repackaging flags one BYPASS and one LNA line per 1000
    c = l0b_raw.auxiliary
    np.testing.assert_array_equal(c["calibration/line"], lines)
    np.testing.assert_array_equal(c["calibration/cal_type"], cal_type[lines])
    codes = f[f"{TX}/rxH/HH"][lines]
    lut = f[f"{TX}/rxH/BFPQLUT"][()]
    np.testing.assert_array_equal(c["calibration/echo"][:, 0], lut[codes["r"]] + 1j * lut[codes["i"]])
    assert not np.any(l0b_raw.echo[lines]), "a calibration line's slot in the echo must be zero"
    others = np.setdiff1d(np.arange(l0b_raw.shape[0]), lines)
    assert np.all(np.any(l0b_raw.echo[others] != 0, axis=1))
    assert l0b_raw.extra_attrs["nisar_calibration_lines"] == 2


def test_times_and_epoch_as_in_the_file(f, l0b_raw):
    ds = f[f"{TX}/UTCtime"]
    assert ds.attrs["units"] == "seconds since 2011-01-13 00:00:00"
    assert l0b_raw.epoch_utc == "2011-01-13T00:00:00.000000Z"
    T = f[f"{TX}/chirpDuration"][()]
    # pulse-centre convention (module docstring of sarcli.io.nisar.l0b): UTCtime is the pulse start
    np.testing.assert_array_equal(l0b_raw.azimuth_time, ds[()] + T / 2)
    prf = f[f"{TX}/nominalAcquisitionPRF"][()]
    assert l0b_raw.radar.prf_hz == pytest.approx(prf, rel=1e-6)  # PRF from the 465 us line spacing
    assert l0b_raw.prf_per_line is None  # one PRF


def test_chirp_range_axis_and_carrier_as_in_the_file(f, l0b_raw):
    g = f[TX]
    K, T, fc = g["chirpSlope"][()], g["chirpDuration"][()], g["centerFrequency"][()]
    sr, dr = g["slantRange"][()], g["slantRangeSpacing"][()]
    r = l0b_raw.radar
    assert (r.chirp_rate_hz_per_s, r.pulse_length_s, r.carrier_frequency_hz) == (K, T, fc)
    assert r.chirp_rate_hz_per_s < 0  # ALOS down-chirp
    assert abs(K) * T == pytest.approx(g["rangeBandwidth"][()], rel=1e-12)  # 14 MHz
    assert r.range_sampling_rate_hz == pytest.approx(C / (2 * dr), rel=1e-15)  # 16 MHz
    assert r.range_sampling_rate_hz == pytest.approx(16e6, rel=1e-9)
    assert r.first_range_m == pytest.approx(sr[0] - C * T / 4, abs=1e-6)
    np.testing.assert_allclose(l0b_raw.slant_range() + C * T / 4, sr, rtol=0, atol=1e-6)
    n = int(round(T * r.range_sampling_rate_hz))
    t = (np.arange(n) - (n - 1) / 2) / r.range_sampling_rate_hz
    np.testing.assert_allclose(l0b_raw.replica, np.exp(1j * np.pi * K * t * t), atol=2e-7)


def test_orbit_look_side_and_pass(f, l0b_raw):
    o = l0b_raw.orbit
    assert o.frame == "ECEF" and o.time.size == 28
    np.testing.assert_array_equal(o.position, f[f"{TEL}/orbit/position"][()])
    np.testing.assert_array_equal(o.time, f[f"{TEL}/orbit/time"][()])  # same epoch as UTCtime
    assert l0b_raw.look_side == "right"
    assert l0b_raw.extra_attrs["pass_direction"] == "ascending"  # the identification says ASCEND
    assert f[f"{TEL}/orbit/velocity"][10, 2] > 0


def test_attitude_plane_matches_the_quaternions(f, l0b_raw):
    """The model's pitch/yaw give back the antenna's along-track axis of each quaternion (scipy), and
    agree with the file's Euler angles: yaw exactly, pitch up to the angle between the geodetic (sarcli
    flight frame) and geocentric (ALOS TCN frame) verticals, 0.1924 deg |sin 2 phi| (+ 0.001 deg rounding)."""
    from orbit.frames import eci_to_ecef
    from orbit.pointing import control_rotation, flight_frame
    from orbit.statevectors import StateVectors

    a = l0b_raw.attitude
    q = f[f"{TEL}/attitude/quaternions"][()]
    m = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    sv = StateVectors.from_record(l0b_raw.orbit, l0b_raw.epoch_utc).to_eci()
    r, v, _ = sv.interpolate(a.time)
    w = (flight_frame(r, v) @ control_rotation(a.pitch, a.yaw))[:, :, 0]
    np.testing.assert_allclose(eci_to_ecef(l0b_raw.epoch_utc, a.time, w), -m[:, :, 1], atol=1e-12)
    e = f[f"{TEL}/attitude/eulerAngles"][()]
    np.testing.assert_allclose(np.degrees(a.yaw), e[:, 2], atol=1e-4)
    re, _, _ = StateVectors.from_record(l0b_raw.orbit, l0b_raw.epoch_utc).interpolate(a.time)
    phi = np.arctan2(re[:, 2], np.hypot(re[:, 0], re[:, 1]))
    bound = 0.1924 * np.abs(np.sin(2 * phi)) + 0.001
    assert np.all(np.abs(np.degrees(a.pitch) - e[:, 1]) <= bound)


def _fdc_from_quaternions(f, l0b_raw, t, rho):
    """Independent prediction: the RCS x-z plane of the slerped quaternion in ECEF (scipy), the point of
    that plane at slant range rho on the WGS-84 ellipsoid (pyproj heights, Brent), fdc = 2/lam v.(p-r)/rho."""
    from pyproj import Transformer

    from orbit.statevectors import StateVectors

    geo = Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)
    ta = f[f"{TEL}/attitude/time"][()]
    q = f[f"{TEL}/attitude/quaternions"][()]
    rot = Slerp(ta, Rotation.from_quat(q[:, [1, 2, 3, 0]]))
    sv = StateVectors.from_record(l0b_raw.orbit, l0b_raw.epoch_utc)
    lam = C / f[f"{TX}/centerFrequency"][()]
    out = []
    for ti, ri in zip(t, rho, strict=True):
        r, v, _ = sv.interpolate(np.array([ti]))
        r, v = r[0], v[0]
        n = rot([ti]).as_matrix()[0][:, 1]
        down = -r / np.linalg.norm(r)
        e1 = down - np.dot(down, n) * n
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)  # n = -w (backward) for a right-looking RCS: n x down points right
        if np.dot(e2, np.cross(down, v)) < 0:
            e2 = -e2

        def height(beta, r=r, ri=ri, e1=e1, e2=e2):
            p = r + ri * (np.cos(beta) * e1 + np.sin(beta) * e2)
            return geo.transform(*p)[2]

        beta = brentq(height, 0.0, 1.2, xtol=1e-14)
        p = r + ri * (np.cos(beta) * e1 + np.sin(beta) * e2)
        out.append(2.0 / lam * np.dot(v, p - r) / ri)
    return np.array(out)


@pytest.fixture(scope="module")
def doppler_model(l0b_raw):
    from sarcli.doppler.api import estimate_doppler
    from sarcli.doppler.options import DopplerOptions

    return estimate_doppler(l0b_raw, DopplerOptions(az_block=250, ambiguity="data"))


def test_predicted_centroid_equals_an_independent_quaternion_computation(f, l0b_raw, doppler_model):
    b = doppler_model.blocks
    idx = [0, 8, 16, 40, 67]
    ref = _fdc_from_quaternions(f, l0b_raw, b["azimuth_time_s"][idx], b["range_m"][idx])
    # error budget: attitude interpolation (linear pitch/yaw vs slerp over 1 s records, the attitude
    # changing by 1e-5 rad/s: < 1e-9 rad), Hermite orbit ECI vs ECEF (< 1 mm), plane solves (0.1 mm):
    # all far below 0.01 Hz at 2 v / lam = 6.4e4 Hz per rad
    np.testing.assert_allclose(b["fdc_orbit_hz"][idx], ref, atol=0.01)


def test_baseband_centroid_with_its_uncertainty(l0b_raw, doppler_model):
    from sarcli.calibration.pointing import centroid_comparison

    c = centroid_comparison(doppler_model)
    e = l0b_raw.echo
    prf = l0b_raw.radar.prf_hz
    plain = prf * np.angle(np.sum(e[1:] * np.conj(e[:-1]))) / (2 * np.pi)  # whole-scene lag-1 phase
    assert 0.1 < c["sigma_scatter_hz"] < 3.0 and c["sigma_model_hz"] > 0
    assert c["n_blocks"] == 68
    # the pipeline drops the 3 x 2200 pairs across its 250-line block boundaries: same estimate
    assert doppler_model.summary.fdc_baseband_hz == pytest.approx(plain, abs=c["sigma_scatter_hz"])
    assert c["data_minus_predicted_hz"] == pytest.approx(c["fdc_baseband_data_hz"] - c["fdc_baseband_predicted_hz"],
                                                         abs=1e-6)
    # the attitude predicts the centroid to 0.05 PRF (0.2 deg of pitch would be 0.08 PRF at L-band)
    assert abs(c["data_minus_predicted_hz"]) < 0.05 * prf
    # ambiguity: zero from the orbit + attitude and from the data (MLCC) with high confidence
    assert c["ambiguity_prediction"] == 0 and c["ambiguity"] == 0
    assert c["ambiguity_source"] == "data" and c["ambiguity_confidence"] > 0.99


@pytest.mark.slow
def test_partial_focus_marks_no_full_line(l0b_raw, doppler_model):
    """1000 lines (0.465 s) against a synthetic aperture of 0.8 PRF / |fr| (~3.4 s): no line is whole."""
    import warnings

    from sarcli.focus.rda import focus_rd

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        slc = focus_rd(l0b_raw, doppler_model)
    prf = l0b_raw.radar.prf_hz
    r_mid = float(l0b_raw.slant_range()[1100])
    fr = float(doppler_model.fr(r_mid, float(np.mean(l0b_raw.azimuth_time))))
    assert slc.parameters["aperture_lines"] == pytest.approx(0.8 * prf / abs(fr) * prf, rel=0.02)
    assert slc.parameters["aperture_lines"] > 7 * l0b_raw.shape[0]
    assert slc.first_full_line > slc.last_full_line
    assert np.all(np.isfinite(slc.image.view(np.float32)))
    # an image of it would hold no valid pixel: refused, saying why; the tag says none (it read "3644..999")
    from sarcli.errors import ProductError
    from sarcli.focus.geocode import full_rows, slc_tags

    with pytest.raises(ProductError, match="longer than the scene's 1000 lines"):
        full_rows(slc, slc.image.shape[0], 1)
    assert slc_tags(slc)["FULLY_FOCUSED_LINES"].startswith("none of 1000")
