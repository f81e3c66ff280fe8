"""The pieces of the radiometric model against closed forms and independent plain-numpy references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sarcli.errors import SarcliError


def _trihedral_closed_form(a: float, lam: float, u: np.ndarray) -> float:
    """RCS of a triangular trihedral from the direction cosines c1 <= c2 <= c3 of the look direction in its
    plate frame (physical optics, Doerry 2008 / Garthwaite 2017 eqs. 2-3):
    (4 pi a^4 / lam^2) (4 c1 c2 / (c1 + c2 + c3))^2 if c1 + c2 < c3, else
    (4 pi a^4 / lam^2) (c1 + c2 + c3 - 2 / (c1 + c2 + c3))^2."""
    c1, c2, c3 = np.sort(np.abs(u) / np.linalg.norm(u))
    s = c1 + c2 + c3
    f = 4.0 * c1 * c2 / s if c1 + c2 < c3 else s - 2.0 / s
    return 4.0 * math.pi * a**4 / lam**2 * f**2


@given(st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0))
def test_trihedral_ray_counting_matches_the_closed_form(x, y, z):
    from sarcli.calibration.radiometry import trihedral_rcs

    u = np.array([x, y, z]) / math.sqrt(x * x + y * y + z * z)
    lam, a = 0.0566, 1.3
    want = _trihedral_closed_form(a, lam, u)
    assert trihedral_rcs(a, lam, u) == pytest.approx(want, rel=1e-9, abs=1e-9 * 4 * math.pi * a**4 / lam**2)


def test_trihedral_boresight_and_outside_the_octant():
    from sarcli.calibration.radiometry import trihedral_rcs

    a, lam = 2.0, 0.24
    assert trihedral_rcs(a, lam) == pytest.approx(4 * math.pi * a**4 / (3 * lam**2), rel=1e-12)
    assert trihedral_rcs(a, lam, np.array([1.0, 1.0, -0.1])) == 0.0


@pytest.mark.parametrize("az, el", [(0.0, 35.26), (123.0, 50.0), (281.5, 20.0)])
def test_plate_frame_points_the_boresight(az, el):
    from sarcli.calibration.radiometry import plate_frame

    m = plate_frame(az, el)
    np.testing.assert_allclose(m.T @ m, np.eye(3), atol=1e-12)
    b = m @ np.full(3, 1 / math.sqrt(3))  # boresight in east-north-up
    want = np.array([math.sin(math.radians(az)) * math.cos(math.radians(el)),
                     math.cos(math.radians(az)) * math.cos(math.radians(el)), math.sin(math.radians(el))])
    np.testing.assert_allclose(b, want, atol=1e-12)


@pytest.mark.parametrize("spec, want", [("rect", 1.0), ("hamming", 0.54**2 + 0.46**2 / 2),
                                        ("hamming:0.6", 0.6**2 + 0.4**2 / 2)])
def test_window_mean_square_closed_forms(spec, want):
    from sarcli.calibration.radiometry import window_mean_square

    assert window_mean_square(spec) == pytest.approx(want, rel=1e-9)


def test_kaiser_mean_square_against_quadrature():
    from scipy.integrate import quad
    from scipy.special import i0

    from sarcli.calibration.radiometry import window_mean_square

    beta = 2.5
    want = quad(lambda u: (i0(beta * math.sqrt(1 - 4 * u * u)) / i0(beta)) ** 2, -0.5, 0.5)[0]
    assert window_mean_square("kaiser:2.5") == pytest.approx(want, rel=1e-8)


@pytest.mark.parametrize("window, frac", [("rect", 1.0), ("kaiser:2.5", 1.0), ("hamming", 0.7)])
def test_range_gains_against_a_plain_numpy_matched_filter(window, frac):
    """E_r and G_r against a plain-numpy time-domain matched filter of the same spectrum, and within the
    Fresnel ripple (a few % at a time-bandwidth product of 72) of their stationary-phase values
    fs a <W^2> / B and a <W^2> / N_r."""
    from sarcli.calibration.radiometry import range_gains, window_mean_square
    from sarcli.focus.windows import window as win
    from sarcli.model.raw import Radar

    fs, k, tau = 32.317e6, -0.72135e12, 10e-6
    radar = Radar(5.3e9, 299792458 / 5.3e9, 1257.0, fs, k, tau, 0.0066, 989e3)
    e_r, g_r = range_gains(radar, window, frac)
    n_r = int(round(tau * fs))
    t = (np.arange(n_r) - 0.5 * (n_r - 1)) / fs
    ref = np.exp(1j * np.pi * k * t * t)
    n = 8192
    f = np.fft.fftfreq(n, 1 / fs)
    spec = np.fft.fft(ref, n) * np.exp(2j * np.pi * f * 0.5 * (n_r - 1) / fs)
    h = np.conj(spec) * win(window, f / (frac * abs(k) * tau)) / n_r
    y = np.fft.ifft(np.fft.fft(ref, n) * h)
    # the window's edge falls between frequency bins of either FFT length: up to one bin of the shorter
    # (fs / 1356 = 24 kHz) in a 7.2 MHz band, 0.33 % of a rect window's integral
    assert e_r == pytest.approx(np.sum(np.abs(y) ** 2), rel=5e-3)
    assert g_r == pytest.approx(np.sum(np.abs(np.fft.ifft(h)) ** 2), rel=5e-3)
    w2 = window_mean_square(window)
    assert e_r == pytest.approx(fs * frac * w2 / (abs(k) * tau), rel=0.05)
    assert g_r == pytest.approx(frac * w2 / n_r, rel=0.05)


def test_unknown_algorithm_is_refused_in_one_line():
    from sarcli.calibration.radiometry import compression_kind, register_algorithm

    with pytest.raises(SarcliError, match="not modelled"):
        compression_kind("no-such-focuser")
    with pytest.raises(SarcliError, match="frequency' or 'time"):
        register_algorithm("x", "hybrid")
    assert compression_kind("rd") == "frequency" and compression_kind("backprojection") == "time"


def _calibration():
    from sarcli.model.slc import Calibration

    t = np.linspace(0.0, 2.0, 3)
    r = np.linspace(9.9e5, 9.92e5, 4)
    b = np.arange(12.0).reshape(3, 4) + 1.0
    return Calibration(t, r, b, 0.6 * b, 0.8 * b, 0.01 * b, 1.0, ("a",), ("absolute calibration constant K (x)",),
                       {"compressed_range_m": [9.9e5, 9.92e5], "noise_source": "stated"})


def test_lut_on_is_bilinear_and_masks_outside_the_compressed_span():
    from sarcli.calibration.radiometry import lut_on

    cal = _calibration()
    got = lut_on(cal, "beta0", np.array([0.5, 1.0]), np.array([9.9e5 + 1000.0, 9.93e5]))
    # bilinear by hand: along range at 1000 m (index 1.5), along time at 0.5 s (index 0.5)
    want = 0.5 * ((2.5) + (6.5))
    assert got[0, 0] == pytest.approx(want)
    assert np.isnan(got[:, 1]).all()


def test_rescaled_divides_every_lut_and_moves_the_constant_to_applied():
    from sarcli.calibration.radiometry import rescaled

    cal = _calibration()
    new = rescaled(cal, 4.0, "measured")
    np.testing.assert_allclose(new.beta0, cal.beta0 / 4.0)
    np.testing.assert_allclose(new.nes0, cal.nes0 / 4.0)
    assert new.constant == 4.0 and not new.not_applied and new.applied[-1].endswith("(measured)")
    with pytest.raises(SarcliError):
        rescaled(cal, -1.0, "x")


def test_noise_power_from_noise_lines_else_stated_else_none():
    from types import SimpleNamespace

    from sarcli.calibration.radiometry import noise_power

    rng = np.random.default_rng(0)
    lines = (rng.standard_normal((3, 500)) + 1j * rng.standard_normal((3, 500))).astype(np.complex64)
    lines[:, 450:] = 0  # padding to the widest line is not noise
    raw = SimpleNamespace(auxiliary={"s1/noise": lines}, radar=SimpleNamespace(noise_power=5.0))
    p, how = noise_power(raw)
    v = lines[:, :450].astype(complex)
    assert p == pytest.approx(np.mean(np.abs(v - v.mean()) ** 2), rel=1e-12)
    assert "noise line" in how
    assert noise_power(SimpleNamespace(auxiliary={}, radar=SimpleNamespace(noise_power=5.0)))[0] == 5.0
    assert noise_power(SimpleNamespace(auxiliary={}, radar=SimpleNamespace(noise_power=None)))[0] is None


def test_calibration_round_trips_through_the_slc_product(tmp_path):
    import h5py

    from sarcli.io.slc import read_calibration, write_calibration

    cal = _calibration()
    with h5py.File(tmp_path / "c.h5", "w") as f:
        write_calibration(f, cal, "seconds since 2002-06-16T15:41:00Z")
        write_calibration(f, cal, "seconds since 2002-06-16T15:41:00Z")  # replaces
    with h5py.File(tmp_path / "c.h5") as f:
        got = read_calibration(f["calibration"], "c.h5")
    for name in ("azimuth_time", "slant_range", "beta0", "sigma0", "gamma0", "nes0"):
        np.testing.assert_array_equal(getattr(got, name), getattr(cal, name))
    assert (got.constant, got.applied, got.not_applied, got.details) == (cal.constant, cal.applied,
                                                                         cal.not_applied, cal.details)


def test_quantized_simulation_states_its_noise_in_the_stored_units():
    """Behind the simulated 4-bit quantizer the product's stated receiver noise is in the stored units: the
    variance of the AGC-undone echo of a noise-dominated scene equals it, within what a near-Max-loaded
    4-bit quantizer takes (its output's variance is the input's less the error's, SQNR about 20 dB, and
    some clipping: -1.5 % measured), the AGC's 1 dB steps and the estimate's 0.4 % (128 x 600 samples)."""
    from sarcli.sim.scene import parse_scene
    from sarcli.sim.stripmap import simulate
    from tests.sim.conftest import linear_scene_text

    text = linear_scene_text(effects=("range_migration", "noise", "quantization"), n_lines=128, n_samples=600,
                             targets="[[targets]]\nx_m = 5095.3\ny_m = 0.0\namplitude = 0.001\n",
                             extra="[noise]\nnoise_power = 2.0\n\n[quantization]\nbits = 4\n")
    raw = simulate(parse_scene(text))
    x = raw.echo.astype(np.complex128) * 10.0 ** (raw.agc_db.astype(np.float64)[:, None] / 20.0)
    assert np.var(x) == pytest.approx(raw.radar.noise_power, rel=0.04)
