"""The emulated AOD/CCD processor ([KimAODCCD]) against theory, its coefficients and the digital RD."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from orbit.constants import C_LIGHT
from sarcli.errors import SarcliError
from sarcli.optical.compare import measure
from sarcli.optical.devices import AOD, CCD, OpticalSettings, mask_phase, seed_mask_coefficients
from sarcli.optical.emulator import emulate

SCENE = Path(__file__).resolve().parents[2] / "samples" / "aod_ccd_scene.toml"
R0 = 10000.0  # slant range of the bright target


@pytest.fixture(scope="module")
def raw():
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    return simulate(load_scene(SCENE))


def run(raw, lims, **kw):
    centre = kw.pop("centre_range_m", R0)
    out = emulate(raw, lims, OpticalSettings(**kw), centre_range_m=centre)
    return out, measure(out.image, out.azimuth_time, out.slant_range, raw, 250.0)


def test_seed_mask_coefficients():
    """u0 = 16210 (printed; dnu = 10 MHz), b2 = 385.56 (printed, computed with c = 3e8)."""
    u0, b2 = seed_mask_coefficients(10e9, 250.0, 15734.0, 10e6)
    assert u0 == pytest.approx(16210.0, rel=3e-4)
    assert b2 * (C_LIGHT / 3e8) ** 2 == pytest.approx(385.56, abs=0.01)


@settings(max_examples=50, deadline=None)
@given(v=st.floats(50, 400), prf=st.floats(500, 20000), f0=st.floats(1e9, 20e9), R=st.floats(1e3, 5e4),
       rows=st.integers(-300, 300))
def test_mask_phase_is_pi_b2_y2_over_x(v, prf, f0, R, rows):
    """The mask term of [KimAODCCD, eq. 12], with the factor pi it drops, is our azimuth matched phase."""
    _, b2 = seed_mask_coefficients(f0, v, prf, 1e6)
    y = rows * CCD().pitch_y_m
    x = AOD().acoustic_velocity_mps * 2 * R / C_LIGHT
    psi = mask_phase(2 * R / C_LIGHT, rows, v, C_LIGHT / f0, prf)
    assert -math.pi * b2 * y * y / x == pytest.approx(psi, rel=1e-10, abs=1e-12)


def test_ideal_optical_equals_digital_rd(raw):
    from sarcli.design.params import doppler_bandwidth
    from sarcli.focus.rda import focus_rd
    from sarcli.model.doppler import GeometricDoppler

    slc = focus_rd(raw, GeometricDoppler(250.0, 0.0, raw.radar.wavelength_m), azimuth_window="rect",
                   range_window="rect", azimuth_bandwidth_hz=doppler_bandwidth(raw.echo, raw.radar.prf_hz))
    rd = measure(slc.image, slc.azimuth_time, slc.slant_range, raw, 250.0)
    _, opt = run(raw, "")
    assert abs(opt["range_error_m"]) < 0.5 and abs(opt["azimuth_error_m"]) < 0.05
    assert opt["irw_range_m"] == pytest.approx(rd["irw_range_m"], rel=0.05)
    assert opt["irw_azimuth_m"] == pytest.approx(rd["irw_azimuth_m"], rel=0.05)
    assert abs(opt["pslr_azimuth_db"] - rd["pslr_azimuth_db"]) < 1.0
    assert abs(opt["dynamic_range_db"] - rd["dynamic_range_db"]) < 3.0


def test_ideal_range_resolution_is_the_chirp_band(raw):
    _, m = run(raw, "")
    assert m["irw_range_m"] == pytest.approx(0.886 * C_LIGHT / (2 * 10e6), rel=0.10)
    assert m["pslr_range_db"] == pytest.approx(-13.26, abs=1.0)


def test_finite_ccd_rows_set_the_azimuth_resolution(raw):
    """A rectangular aperture of T = 489 / PRF seconds: IRW = 0.886 lam R / (2 v T) (4.27 m here)."""
    out, m = run(raw, "ccd_size")
    assert out.report["rows_integrated"] == 489  # 491 rows, odd aperture
    lam, prf = C_LIGHT / 10e9, 3934.0
    assert m["irw_azimuth_m"] == pytest.approx(0.886 * lam * R0 / (2 * 250.0 * 489 / prf), rel=0.10)
    assert m["pslr_azimuth_db"] == pytest.approx(-13.26, abs=1.0)
    assert out.image.shape[1] == 384 - 2 * (out.report["columns"] - out.report["image_columns"]) // 2


def test_light_pulse_and_pixel_gains_match_their_sincs(raw):
    """The recorded term A g e^{-j theta} carries the reference carrier dnu. The flash averages it over
    tau_L: gain sinc(dnu tau_L). A pixel integrates the masked charge I e^{-j theta} — carrier 2 dnu,
    since the mask's e^{-j theta} multiplies the intensity's own e^{-j theta} before read-out — over its
    delay width d: gain sinc(2 dnu d). Here dnu = B = 10 MHz, tau_L = 20 ns, d = 1/(2 (2 dnu + B/2)) = 20 ns."""
    base, mb = run(raw, "ccd_size")
    dnu, d = 10e6, 1.0 / (2 * (2 * 10e6 + 10e6 / 2))
    assert base.design.pixel_delay_s == pytest.approx(d)
    _, ml = run(raw, "ccd_size,light_pulse")
    _, mp = run(raw, "ccd_size,ccd_pixels")
    assert ml["peak_amplitude"] / mb["peak_amplitude"] == pytest.approx(np.sinc(dnu * 20e-9), rel=0.03)
    assert mp["peak_amplitude"] / mb["peak_amplitude"] == pytest.approx(np.sinc(2 * dnu * d), rel=0.03)


def test_aod_bandwidth_narrower_than_the_chirp_widens_the_range_response(raw):
    _, wide = run(raw, "ccd_size")
    _, narrow = run(raw, "ccd_size,aod_bandwidth", aod=AOD(bandwidth_hz=6e6))
    assert narrow["irw_range_m"] / wide["irw_range_m"] == pytest.approx(10 / 6, rel=0.10)
    _, same = run(raw, "ccd_size,aod_bandwidth")  # 30 MHz passband holds the 10 MHz chirp
    assert same["irw_range_m"] == pytest.approx(wide["irw_range_m"], rel=1e-3)


def test_aod_aperture_cuts_chirps_that_do_not_fit(raw):
    small = AOD(aperture_m=0.015)  # 24.3 us: less than the CCD span (7.7 us) plus the 20 us pulse
    _, centred = run(raw, "ccd_size", aod=small)
    _, centred_cut = run(raw, "ccd_size,aod_aperture", aod=small)
    assert centred_cut["peak_amplitude"] == pytest.approx(centred["peak_amplitude"], rel=0.01)
    _, edge = run(raw, "ccd_size", aod=small, centre_range_m=R0 + 500)
    _, edge_cut = run(raw, "ccd_size,aod_aperture", aod=small, centre_range_m=R0 + 500)
    assert edge_cut["peak_amplitude"] < 0.95 * edge["peak_amplitude"]


def test_seed_reference_offset_puts_the_detector_self_term_in_band(raw):
    """dnu = B (the u0 of [KimAODCCD]) lets detection products reach the image band: the range response widens
    and its sidelobes rise; dnu = 2B (offset-reference holography asks dnu >= 1.5 B) brings both back
    to the ideal processor's (a residual product at the band edge, -0.6 B, narrows the IRW by ~7 %)."""
    _, ideal = run(raw, "ccd_size")
    _, seed = run(raw, "ccd_size,detector_intensity,mask", remove_bias=True)
    _, offset = run(raw, "ccd_size,detector_intensity,mask", remove_bias=True, reference_offset_hz=20e6)
    assert seed["irw_range_m"] > 1.08 * ideal["irw_range_m"]
    assert seed["pslr_range_db"] > ideal["pslr_range_db"] + 2.0
    assert offset["irw_range_m"] == pytest.approx(ideal["irw_range_m"], rel=0.10)
    assert abs(offset["pslr_range_db"] - ideal["pslr_range_db"]) < 1.0


@pytest.mark.parametrize("dnu", [None, 20e6])
def test_bias_removal_recovers_what_the_readout_range_predicts(raw, dnu):
    """With an n-bit read-out spanning the charge, removing the bias pedestal (complementary mask,
    before the converter) doubles the useful swing relative to the span: gain = 20 log10(2 S_b / S_r)."""
    lims = "ccd_size,detector_intensity,mask"
    spans, dr = [], []
    for rb in (False, True):
        clean, _ = run(raw, lims, remove_bias=rb, reference_offset_hz=dnu)
        spans.append(float(np.ptp(clean.charge)))
        _, m = run(raw, lims + ",adc", remove_bias=rb, reference_offset_hz=dnu)
        dr.append(m["dynamic_range_db"])
    predicted = 20 * math.log10(2 * spans[0] / spans[1])
    assert dr[1] - dr[0] == pytest.approx(predicted, abs=0.3)
    # the pedestal is real: without removal the charge span is more than half the removed one's double
    assert 0.0 < predicted < 6.0


def test_unknown_limitation_and_wrong_geometry(raw):
    with pytest.raises(SarcliError, match="unknown optical limitation"):
        emulate(raw, "ccd_size,lens_flare")
    orbital = type(raw)(**{**raw.__dict__})
    orbital.radar = type(raw.radar)(**{**raw.radar.__dict__, "platform_velocity_mps": None})
    orbital.orbit = type(raw.orbit)(raw.orbit.time, raw.orbit.position, raw.orbit.velocity, "ECI")
    with pytest.raises(SarcliError, match="airborne"):
        emulate(orbital, "")


def test_all_zero_echo_is_refused(raw):
    empty = type(raw)(**{**raw.__dict__})
    empty.echo = np.zeros_like(raw.echo)
    with pytest.raises(SarcliError, match="all zero"):
        emulate(empty, "")


def test_cli_compare_quick_json(cli, tmp_path):
    r = cli("simulate", SCENE, "-o", tmp_path / "aod.h5")
    assert r.exit_code == 0, r.stderr
    r = cli("optical", "compare", tmp_path / "aod.h5", "--quick", "--json", "--plot", tmp_path / "c.png")
    assert r.exit_code == 0, r.stderr
    rep = json.loads(r.stdout)
    names = [row["processor"] for row in rep["rows"]]
    assert names == ["digital RD", "optical ideal", "optical all", "optical all, bias removed"]
    assert rep["design"]["rows_integrated"] == 489
    assert (tmp_path / "c.png").stat().st_size > 10_000


def test_focus_plugin_registered():
    from sarcli.focus import FOCUSERS

    assert "optical" in FOCUSERS.names()


def test_cli_focus_algorithm_optical(cli, tmp_path):
    """`sarcli focus --algorithm optical` writes an SLC whose brightest pixel is the bright target."""
    from sarcli.io.slc import read_slc

    assert cli("simulate", SCENE, "-o", tmp_path / "aod.h5").exit_code == 0
    r = cli("focus", tmp_path / "aod.h5", "--algorithm", "optical", "-o", tmp_path / "opt.h5", "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["algorithm"] == "optical"
    slc = read_slc(tmp_path / "opt.h5")
    a = np.abs(slc.image)
    k, j = np.unravel_index(np.argmax(a), a.shape)
    assert abs(slc.slant_range[j] - R0) < 3.0
    # within a tenth of the CCD-limited azimuth cell (4.27 m = 67 lines; the 8-bit read-out is noisy)
    assert abs(slc.azimuth_time[k] - slc.truth["targets"]["zero_doppler_time_s"][0]) * 250.0 < 0.43


@pytest.mark.parametrize("opt", ["0", "-5"])
def test_cli_refuses_a_non_positive_reference_offset_before_any_work(cli, tmp_path, opt):
    r = cli("optical", "compare", tmp_path / "missing.h5", "--reference-offset-hz", opt)
    assert r.exit_code == 2 and r.stderr.strip().splitlines() == [
        f"sarcli: error: reference offset must be a positive frequency (Hz), got {float(opt)}"]
