"""The focused image does not depend on the block size (docs/focusing.md).

Scene (plain numpy, tests/focus/synth.py): flat hyperbolic geometry, V = 7000 m/s, a centroid of
-3.4 PRF that moves by 150 Hz along the 3000-line scene (the beam is steered: the exposure, 1400 Hz
wide, follows fdc(t)); five targets spread over the scene. Two Doppler models:

- the geometry's own (consistent: fdc(t) and fr = -2 V^2 cos^2(theta) / (lam R_c), so V is the same
  at every time): the peak phase must be -4 pi R0 / lam (0.05 rad: the measured error of the
  squinted point-target test is 0.02 rad, and the window's centre follows the centroid only per
  block: second order, below 0.02 rad here);
- an estimate-like model (fr held at its scene-centre value while fdc moves): the derived V then
  varies by 0.09 m/s along the scene, which moves the peak phase by 11 rad per m/s at this squint
  (sarcli.focus.rda docstring) -- the block-centre model alone gave up to 0.5 rad between block sizes.

Across block sizes 512 (the shortest block the aperture allows), 2048 and the whole scene, phases
agree to 0.01 rad and amplitudes to 0.1 % (the bar of docs/focusing.md) with the consistent model. With the
estimate-like one the model contradicts the data (by up to 0.04 m/s of V: 0.4 rad at the peak),
and where that residual lands at the peak depends on the centre of the processed band (its
tangent's intercept moves by 2 E2 f_c = 2 E0 / f_c, 1.6e-4 rad per Hz), which is the block's
centroid, up to 45 Hz from a target's: a few 1e-3 rad, measured up to 0.014 rad; bar 0.02 rad.

The measured phase needs the absolute carrier of the target's processed spectrum (:func:`carrier`):
the azimuth window is centred on the block's centroid, so the spectrum of a target sits between
that and its own centroid, and a carrier off by df moves the phase measured at a fractional peak
by 2 pi df / PRF x the sub-pixel offset.
"""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.focus.quality import point_target_metrics
from sarcli.focus.rda import (
    apply_line_phase,
    apply_line_phase_numpy,
    correct_lines,
    correct_lines_numpy,
    focus_rd,
    velocity_correction,
)

from .synth import C, scene

PRF, FS, LAM, V = 1500.0, 24e6, 0.0566, 7000.0
DR = C / (2 * FS)
N = 3000
FDC0, SLOPE = -3.4 * PRF, 75.0  # Hz, Hz/s: 150 Hz over the 2 s scene
# exposure band: the processed 1000 Hz, centred on a block's centroid (up to 45 Hz from a target's),
# stay 150 Hz inside it, clear of the Fresnel ripple of its edges (sqrt(|fr|) = 45 Hz wide)
EXPOSURE = 1400.0
R0 = 850e3 + 256.3 * DR


def fdc_of_t(t):
    return FDC0 + SLOPE * (np.asarray(t, float) - 1.0)


def sin_squint(t):
    return -LAM * fdc_of_t(t) / (2 * V)


class Geometry:
    """The scene's Doppler: the steered centroid and the rate of the same geometry."""

    def fdc(self, r, t):
        r, t = np.broadcast_arrays(np.asarray(r, float), np.asarray(t, float))
        return fdc_of_t(t) + 0 * r

    def fr(self, r, t):
        r, t = np.broadcast_arrays(np.asarray(r, float), np.asarray(t, float))
        return -2 * V**2 * (1 - sin_squint(t) ** 2) / (LAM * r)


class RateHeld(Geometry):
    """The same centroid with the rate frozen at scene centre (as a fit of a constant rate would give)."""

    def fr(self, r, t):
        r, t = np.broadcast_arrays(np.asarray(r, float), np.asarray(t, float))
        return -2 * V**2 * (1 - sin_squint(1.0) ** 2) / (LAM * r)


def _targets():
    out = []
    for k, tc in enumerate((0.45, 0.8, 1.05, 1.33, 1.6)):
        r0 = R0 + 10 * k * DR
        s = sin_squint(tc)
        out.append((r0, tc - r0 * s / np.sqrt(1 - s * s) / V, 1.0))
    return out


@pytest.fixture(scope="module")
def raw():
    return scene(_targets(), n_lines=N, n_samples=512, fdc=fdc_of_t, pulse=10e-6, chirp_rate=-2e12,
                 exposure_bw_hz=EXPOSURE)


def carrier(slc, row: float, col: float) -> float:
    """The target's absolute azimuth carrier (cycles per line): the phase of the lag-1 azimuth
    correlation over 17 x 17 pixels around it (the centre of its processed spectrum, known modulo 1),
    with the whole cycles of the centroid used for its block (the SLC's Doppler table)."""
    nv = slc.parameters["block_output_lines"]
    r, c = int(round(row)), int(round(col))
    b = min(r // nv, slc.doppler.block_time.size - 1)
    chip = slc.image[r - 8:r + 9, c - 8:c + 9].astype(complex)
    est = np.angle(np.sum(chip[1:] * np.conj(chip[:-1]))) / (2 * np.pi)
    used = slc.doppler.fdc_hz[b, c] / slc.prf_hz
    return est + np.round(used - est)


def _measure(slc):
    out = []
    for r0, eta0, _ in _targets():
        row = float(np.interp(eta0, slc.azimuth_time, np.arange(N)))
        col = (r0 - slc.slant_range[0]) / DR
        m = point_target_metrics(slc.image, row, col, azimuth_carrier=carrier(slc, row, col))
        out.append((m["peak_amplitude"], m["peak_phase_rad"], r0))
    return np.array(out)


@pytest.mark.slow
@pytest.mark.parametrize("model", [Geometry(), RateHeld()], ids=["consistent", "rate-held"])
def test_block_size_does_not_change_the_image(raw, model):
    res = {}
    for bl in (512, 2048, 8192):
        slc = focus_rd(raw, model, block_lines=bl, azimuth_bandwidth_hz=1000.0)
        res[bl] = (_measure(slc), slc.parameters["n_blocks"])
    assert [res[b][1] for b in (512, 2048, 8192)] == [4, 3, 1]  # three different layouts
    ref = res[8192][0]
    tol = 0.02 if isinstance(model, RateHeld) else 0.01
    for bl in (512, 2048):
        m = res[bl][0]
        dphi = np.angle(np.exp(1j * (m[:, 1] - ref[:, 1])))
        assert np.max(np.abs(dphi)) < tol, (bl, dphi)
        assert np.max(np.abs(m[:, 0] / ref[:, 0] - 1)) < 1e-3, (bl, m[:, 0] / ref[:, 0])
    if isinstance(model, RateHeld):
        return
    for bl in res:
        m = res[bl][0]
        err = np.angle(np.exp(1j * (m[:, 1] + 4 * np.pi * m[:, 2] / LAM)))
        assert np.max(np.abs(err)) < 0.05, (bl, err)


def test_velocity_correction_matches_a_numerical_irf():
    """The phase at the peak of a target whose spectrum carries E(f) = (4 pi R0/lam)(D(f, Vb) - D(f, Vl)),
    computed by an inverse DFT of the processed band and a fine search for the peak: the phase
    correction is its negative up to the curvature term the linearization leaves, E2 (f - fc)^2
    averaged over the (rect) band: |E2| Ba^2 / 12 = 2.1e-3 rad here, E2 from a quadratic fit of E;
    the peak lands where the correction says (to the 1 ns search step)."""
    r0, vb, vl, fc, ba = 990e3, 7072.30, 7072.25, -6690.0, 1000.0
    f = fc + np.linspace(-ba / 2, ba / 2, 4001)

    def d(v):
        return np.sqrt(1 - (LAM * f / (2 * v)) ** 2)

    e = 4 * np.pi * r0 / LAM * (d(vb) - d(vl))
    def irf(tau):
        return np.exp(1j * (e[None, :] + 2 * np.pi * f[None, :] * tau[:, None])).sum(axis=1)

    tau = np.linspace(-2e-3, 2e-3, 4001)  # s around the nominal peak (the shift is ~0.05 ms)
    t0 = tau[int(np.argmax(np.abs(irf(tau))))]
    tau = t0 + np.linspace(-2e-6, 2e-6, 4001)  # 1 ns steps: 4e-5 rad of carrier phase per step
    v = irf(tau)
    k = int(np.argmax(np.abs(v)))
    phase_at_peak = np.angle(v[k])
    corr, late = velocity_correction(np.array(r0), np.array(fc), np.array(vb), np.array(vl), LAM)
    assert abs(tau[k] - late) < 2e-9 and abs(late) > 1e-5
    e2 = np.polyfit(f - fc, e, 2)[0]
    bound = abs(e2) * ba**2 / 12 + 2e-4  # + the 1 ns search step (4e-5 rad) and the DFT's sampling
    assert abs(np.angle(np.exp(1j * (phase_at_peak + corr)))) < bound
    assert abs(corr) > 0.5  # the effect is large: 0.05 m/s is 1.1 rad at this squint


def test_apply_line_phase_matches_numpy():
    rng = np.random.default_rng(3)
    img = (rng.standard_normal((70, 100)) + 1j * rng.standard_normal((70, 100))).astype(np.complex64)
    lines_c = np.array([200, 216, 232, 248, 264, 270], np.int64)
    cols_c = np.array([0, 32, 64, 96, 99], np.int64)
    phi = rng.uniform(-3, 3, (lines_c.size, cols_c.size))
    ref = apply_line_phase_numpy(img.astype(np.complex128), 200, lines_c, cols_c, phi)
    out = img.copy()
    apply_line_phase(out, 200, lines_c, cols_c, phi)
    np.testing.assert_allclose(out, ref, rtol=0, atol=2e-6 * np.abs(img).max())


def demo_scene_target_rows(slc, truth) -> np.ndarray:
    """Per truth target of a focused demo scene (samples/rs1_point.toml): (peak amplitude, peak phase rad,
    closest range m, azimuth position minus the truth's, lines), the phase at the target's absolute carrier
    (:func:`carrier`)."""
    from sarcli.focus.quality import truth_targets

    rows = []
    for tz, r0 in truth_targets(truth):
        row = (tz - slc.azimuth_time[0]) * slc.prf_hz
        col = (r0 - slc.slant_range[0]) / slc.range_spacing_m
        m = point_target_metrics(slc.image, row, col, azimuth_carrier=carrier(slc, row, col))
        rows.append((m["peak_amplitude"], m["peak_phase_rad"], r0, m["row"] - row))
    return np.array(rows)


@pytest.mark.slow
def test_block_size_on_the_simulated_orbit_scene():
    """The demo scene (samples/rs1_point.toml: rotating Earth, antenna pattern, 4-bit data) with the
    Doppler estimated by sarcli.doppler (its model and the orbit's V vary along azimuth) and the
    orbit-timing correction: before the per-line model, blocks of 1024/2048/4096 lines moved the
    phases by up to 0.56 rad and the positions by up to 0.05 line. Bar: 0.01 rad, 0.1 %;
    the peak phase within 0.05 rad of -4 pi R0 / lam + the target's own phase (90 deg for the third)."""
    from pathlib import Path

    from sarcli.doppler.api import estimate_doppler
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    raw = simulate(load_scene(Path(__file__).resolve().parents[2] / "samples" / "rs1_point.toml"))
    dop = estimate_doppler(raw)
    lam = raw.radar.wavelength_m
    tg = raw.truth["targets"]
    own = np.angle(tg["reflectivity_re"] + 1j * tg["reflectivity_im"])
    res = {}
    for bl in (1024, 2048, 4096):
        slc = focus_rd(raw, dop, block_lines=bl)
        res[bl] = (demo_scene_target_rows(slc, raw.truth), slc.parameters["n_blocks"])
    assert sorted({res[b][1] for b in res}) == [1, 2, 3]
    ref = res[4096][0]
    for bl in (1024, 2048):
        m = res[bl][0]
        assert np.max(np.abs(np.angle(np.exp(1j * (m[:, 1] - ref[:, 1]))))) < 0.01
        assert np.max(np.abs(m[:, 0] / ref[:, 0] - 1)) < 1e-3
    for bl in res:
        m = res[bl][0]
        err = np.angle(np.exp(1j * (m[:, 1] + 4 * np.pi * m[:, 2] / lam - own)))
        assert np.max(np.abs(err)) < 0.05, (bl, err)
        # the per-line time shift: azimuth position against the truth to 0.01 line (it was 0.02-0.05
        # line at the block edges with the block's timing alone; measured now: < 0.001)
        assert np.max(np.abs(m[:, 3])) < 0.01, (bl, m[:, 3])


@pytest.mark.parametrize("name", ["rd", "csa"])
def test_blocks_are_pure_functions_of_the_plan(name):
    """Blocks run in any order (as a Dask graph would) give the serial image bit for bit (rd, csa; omegak:
    tests/focus/test_omegak.py)."""
    from sarcli.focus import FOCUSERS
    from sarcli.focus.base import make_plan, run_blocks

    focuser = FOCUSERS.get(name)
    raw = scene(_targets()[1:3], n_lines=2400, n_samples=300, fdc=fdc_of_t, pulse=10e-6, chirp_rate=-2e12,
                exposure_bw_hz=EXPOSURE)
    plan = make_plan(focuser, raw, raw.echo.shape, RateHeld(), {"block_lines": 512, "azimuth_bandwidth_hz": 1000.0},
                     None)
    assert plan.n_blocks == 3
    serial = np.empty(plan.output_shape, np.complex64)

    def sink(first, block):
        serial[first:first + block.shape[0]] = block

    run_blocks(focuser, plan, lambda a, b: raw.echo[a:b], sink)
    for b in reversed(range(plan.n_blocks)):
        s, e = plan.block_rows(b)
        np.testing.assert_array_equal(focuser.focus_block(plan, b, lambda a, z: raw.echo[a:z].copy()), serial[s:e])


def test_correct_lines_matches_numpy_and_shifts_a_band_pass_signal():
    """The per-line shift kernel against its numpy reference, and against the exact shift of a
    band-limited signal at the absolute carrier (0.8 PRF of band, Kaiser 2.5 weighted as the azimuth
    window does, around -5.3 cycles per line: the Radarsat-1 squint), for shifts up to 0.1 line (the
    block-edge residual of 4096-line blocks is 0.07 line on Radarsat-1). Bound: the rms error is at
    most max |H_mu(f) - 1| over the band and the shifts, H_mu the frequency response of the 16-tap
    windowed sinc (from the exact weights): 0.7 % at the band edge."""
    from sarcli.focus.interp import sinc_weights, table_for
    from sarcli.focus.windows import window

    rng = np.random.default_rng(5)
    n, nr, c, mu_max = 512, 40, -5.3, 0.1
    f = np.fft.fftfreq(n)
    base = np.mod(f - c + 0.5, 1.0) - 0.5  # frequency relative to the carrier, aliased to [-0.5, 0.5)
    spec = rng.standard_normal((n, nr)) + 1j * rng.standard_normal((n, nr))
    spec *= window("kaiser:2.5", base / 0.8)[:, None]
    img = np.fft.ifft(spec, axis=0)
    lines_c = np.array([100, 116, 132, 148, 160], np.int64)
    cols_c = np.array([0, 20, 39], np.int64)
    mu = rng.uniform(-mu_max, mu_max, (lines_c.size, cols_c.size))
    phi = rng.uniform(-1, 1, mu.shape)
    carrier = np.full(nr, c)
    ref = correct_lines_numpy(img, 100, 100, 60, lines_c, cols_c, phi, mu, carrier, "sinc16")
    out = np.empty((60, nr), complex)
    correct_lines(img.copy(), 100, 100, out, lines_c, cols_c, phi, mu, carrier, table_for("sinc16")[1])
    rms = np.sqrt(np.mean(np.abs(img) ** 2))
    assert np.max(np.abs(out - ref)) < 1e-3 * rms  # the kernel's table of 2048 phases vs exact weights
    lines = 100 + np.arange(60)

    def px(v):
        by_col = np.stack([np.interp(lines, lines_c, v[:, k]) for k in range(cols_c.size)], axis=1)
        return np.stack([np.interp(np.arange(nr), cols_c, row) for row in by_col])

    tpos = lines[:, None] + px(mu)
    fa = c + base  # the absolute frequency of each bin
    exact = np.stack([np.exp(2j * np.pi * fa[None, :] * tpos[:, k:k + 1]) @ spec[:, k] / n for k in range(nr)], 1)
    k = np.arange(-7, 9)
    fb = np.linspace(-0.4, 0.4, 81)
    bound = max(np.max(np.abs(np.exp(-2j * np.pi * fb[:, None] * (k - m)[None, :]) @ sinc_weights(16, np.array(m))
                              - 1)) for m in np.linspace(0, mu_max, 11))
    err = np.sqrt(np.mean(np.abs(out - exact * np.exp(1j * px(phi))) ** 2))
    assert err < bound * rms, (err / rms, bound)


def test_correct_lines_single_precision_equals_its_complex128_reference_to_round_off():
    """The complex64 kernel (demodulated in place, real-weighted taps, remodulation advanced line by
    line) against the complex128 numpy reference with the SAME tabulated weights, on a block like the
    pipeline's (carrier across the swath around -5.3 cycles per line, shifts up to 0.1 line, a
    first line not on the block start, taps reaching past the block's ends). Round-off bound: the
    input (2^-24 relative), its demodulation (one more rounding), 16 complex64 multiply-adds and the
    output rounding: |error| <= (taps + 3) 2^-24 sum|h| max|s| with sum|h| < 2.1 (the sinc16 table at
    half-integer shifts)."""
    from sarcli.focus.interp import table_for

    rng = np.random.default_rng(11)
    n_in, nr, pad, n_out = 300, 70, 40, 220
    img = (rng.standard_normal((n_in, nr)) + 1j * rng.standard_normal((n_in, nr))).astype(np.complex64)
    lines_c = np.r_[np.arange(1000, 1000 + n_out, 16), 1000 + n_out].astype(np.int64)
    cols_c = np.r_[np.arange(0, nr - 1, 32), nr - 1].astype(np.int64)
    mu = rng.uniform(-0.1, 0.1, (lines_c.size, cols_c.size))
    mu[-1] += 40.0  # the last lines read past the block's end (taps skipped there, as in the reference)
    phi = rng.uniform(-3, 3, mu.shape)
    carrier = np.linspace(-5.35, -5.25, nr)
    table = table_for("sinc16")[1].astype(np.float32)
    out = np.empty((n_out, nr), np.complex64)
    correct_lines(img.copy(), pad, 1000, out, lines_c, cols_c, phi, mu, carrier, table)
    ref = correct_lines_numpy(img.astype(np.complex128), pad, 1000, n_out, lines_c, cols_c, phi, mu, carrier,
                              "sinc16", table=table)
    assert np.sum(np.abs(table), axis=1).max() < 2.1
    bound = (16 + 3) * 2.0**-24 * 2.1 * np.max(np.abs(img))
    assert np.max(np.abs(out - ref)) < bound, (np.max(np.abs(out - ref)), bound)
