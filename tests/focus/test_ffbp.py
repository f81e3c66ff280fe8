"""Fast factorized backprojection (sarcli.focus.ffbp, the ``ffbp`` focuser) against plain numpy and the exact
backprojection.

Building blocks against plain-numpy references: the interpolation kernels (the Knab-windowed sinc from its
formula, the table lookup, and the error model e_N(beta) against the measured worst case), the polar
sample's placement (an independent root search on the plane), stage 0 (the exact backprojection onto
polar samples). End to end: a point target from a straight track (plain-numpy echo, plain-numpy BP),
whose peak error must stay below the derived bound (S + 1)(e_order(beta) + e_range_order(U)) and fall as
the knobs tighten (a property over the knobs); the stripmap focuser against ``backprojection`` on the
Radarsat-1-like simulated scene (orbit, rotating Earth): peak position within 0.1 pixel and PSLR within
0.5 dB (issue bar), phase within the bound; and blocks that give the same image.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from sarcli.errors import ConfigError
from sarcli.focus.ffbp import (
    ALONG_RAY_SLACK,
    MAX_ORDER,
    TABLE_Q,
    FfbpKnobs,
    _frames,
    _interp,
    _merge_row,
    _polar_point,
    _weights,
    ffbp,
    kernel_error,
    kernel_table,
    peak_error_bound,
    stage0_kernel,
)

C = 299792458.0


def _knab(x, n, beta):
    c = np.pi * (1 - 1 / beta) * n / 2
    return np.sinc(x) * np.cosh(c * np.sqrt(np.clip(1 - (2 * x / n) ** 2, 0, None))) / np.cosh(c) * (np.abs(x) <= n / 2)


@pytest.mark.parametrize("order", [2, 4, 6, 8])
@pytest.mark.parametrize("beta", [1.5, 2.0, 3.0])
def test_kernel_weights_and_error_model(order, beta):
    tab = kernel_table(order, beta)
    out = np.empty(8)
    nodes = np.arange(-order // 2 + 1, order // 2 + 1)
    worst = 0.0
    nus = np.linspace(-1 / (2 * beta), 1 / (2 * beta), 101)
    for mu in np.linspace(0, 1, 41, endpoint=False):
        _weights(order, mu, tab, out)
        ref = np.maximum(0, 1 - np.abs(mu - nodes)) if order == 2 else _knab(mu - nodes, order, beta)
        # the table holds the kernel every 1/512 sample, looked up linearly: error <= |h''| (1/512)^2 / 8 with
        # |h''| <= |sinc''| + 2 |sinc'| |g'| + |g''| <= pi^2/3 + 2 (1.1) (2c/N) + 4c^2/N^2 < pi^2 for the
        # window g of parameter c = pi v N/2 <= 4.2 (v <= 2/3)
        np.testing.assert_allclose(out[:order], ref, atol=np.pi ** 2 / (8 * TABLE_Q ** 2))
        val = np.exp(2j * np.pi * np.outer(nus, nodes)) @ out[:order]
        worst = max(worst, np.abs(val - np.exp(2j * np.pi * nus * mu)).max())
    model = kernel_error(order, beta)
    # linear: the Taylor bound; Knab: the worst case is 0.76 - 1.14 times 1/cosh(pi v N/2) (measured)
    assert worst <= (1.0 if order == 2 else 1.15) * model
    assert worst >= (0.5 if order == 2 else 0.7) * model


def test_interpolation_matches_numpy():
    rng = np.random.default_rng(3)
    nr, nu = 23, 17
    img = (rng.normal(size=(nu, nr)) + 1j * rng.normal(size=(nu, nr))).astype(np.complex64)
    tab_u, tab_r = kernel_table(6, 2.0), kernel_table(4, 3.0)
    wr, wu = np.empty(8), np.empty(8)
    for fr, fu in rng.uniform([2, 2], [nr - 3, nu - 4], size=(20, 2)):
        got = _interp(img.ravel(), 0, nr, nu, fr, fu, 6, 4, tab_u, tab_r, wr, wu)
        ir, iu = int(fr), int(fu)
        rn, un = np.arange(ir - 1, ir + 3), np.arange(iu - 2, iu + 4)
        ref = _knab(fu - un, 6, 2.0) @ img[np.ix_(un, rn)].astype(complex) @ _knab(fr - rn, 4, 3.0)
        assert abs(got - ref) < 1e-5 * np.abs(img).max() * 24
    # a stencil leaving the grid, or a coordinate that is not finite, gives 0 (no read outside)
    assert _interp(img.ravel(), 0, nr, nu, 0.5, 5.0, 6, 4, tab_u, tab_r, wr, wu) == 0
    assert _interp(img.ravel(), 0, nr, nu, np.nan, 5.0, 6, 4, tab_u, tab_r, wr, wu) == 0


def _track(n, curvature=0.0):
    """A track along y at 3 km height, bent by ``curvature`` (1/m) in x (a circular-ish pass)."""
    s = (np.arange(n) - (n - 1) / 2) * 0.5
    return np.stack([curvature * s ** 2 / 2, s, np.full(n, 3000.0)], axis=1)


def test_polar_point_on_the_plane():
    pos = _track(9, 1e-4)
    frames, _ = _frames(pos, np.array([0]), np.array([9]), np.array([4000.0, 0.0, 0.0]))
    fr = frames[0]
    p0, nrm = np.array([4000.0, 0.0, 0.0]), np.array([0.05, 0.0, 1.0]) / np.hypot(0.05, 1.0)
    for r, u in ((5000.0, 0.01), (5100.0, -0.02), (4950.0, 0.0)):
        y = np.array(_polar_point(fr, p0, nrm, r, u))

        def point(phi, r=r, u=u):
            rho = r * np.sqrt(1 - u * u)
            return fr[0] + r * u * fr[1] + rho * (np.cos(phi) * fr[2] + np.sin(phi) * fr[3])

        phi = brentq(lambda p: nrm @ (point(p) - p0), -np.pi / 2, np.pi / 2)
        np.testing.assert_allclose(y, point(phi), atol=1e-6)
        assert abs(np.linalg.norm(y - fr[0]) - r) < 1e-6 and abs(fr[1] @ (y - fr[0]) / r - u) < 1e-12


def test_stage0_matches_numpy():
    rng = np.random.default_rng(1)
    pos = _track(8, 2e-4)
    n_r, r_first, dr = 64, 4990.0, 0.5
    lines = (rng.normal(size=(8, n_r)) + 1j * rng.normal(size=(8, n_r))).astype(np.complex64)
    w = rng.uniform(0.5, 1.0, 8)
    w[3] = 0.0
    ref = rng.uniform(-2, 2, 8)
    start, stop = np.array([0, 4]), np.array([4, 8])
    centroid = np.array([4000.0, 0.0, 0.0])
    frames, _ = _frames(pos, start, stop, centroid)
    p0, nrm = centroid, np.array([0.0, 0.0, 1.0])
    r0, u0, du = np.array([4995.0, 4996.0]), np.array([-0.01, -0.012]), np.array([0.004, 0.005])
    nr, nu = np.array([30, 25]), np.array([5, 6])
    off = np.array([0, 150])
    row_sub = np.repeat([0, 1], nu)
    row_iu = np.r_[np.arange(5), np.arange(6)]
    k = 4 * np.pi / 0.03
    out = np.zeros(300, np.complex64)
    stage0_kernel(lines, r_first, dr, k, pos, ref, w, start, stop, frames, p0, nrm, r0, u0, du, nr, nu, off, 0.2,
                  row_sub, row_iu, out)
    grid = r_first + dr * np.arange(n_r)
    for s in (0, 1):
        for iu in range(nu[s]):
            for ir in range(0, nr[s], 7):
                r, u = r0[s] + ir * 0.2, u0[s] + iu * du[s]
                y = np.array(_polar_point(frames[s], p0, nrm, r, u))
                acc = 0j
                for n in range(start[s], stop[s]):
                    rho = np.linalg.norm(y - pos[n]) - ref[n]
                    v = np.interp(rho, grid, lines[n].real) + 1j * np.interp(rho, grid, lines[n].imag)
                    acc += w[n] * v * np.exp(1j * k * (rho - r))
                assert abs(out[off[s] + iu * nr[s] + ir] - acc) < 1e-5 * 4


def _row_coordinates(fr, p0, nrm, c_frames, r0, u, n, dr):
    """(rc, uc) (4, n): each child's polar coordinates of the parent row's samples (plain numpy)."""
    rc, uc = np.empty((4, n)), np.empty((4, n))
    for i in range(n):
        y = np.array(_polar_point(fr, p0, nrm, r0 + i * dr, u))
        for c in range(4):
            d = y - c_frames[c, 0]
            rc[c, i] = np.linalg.norm(d)
            uc[c, i] = c_frames[c, 1] @ d / rc[c, i]
    return rc, uc


@pytest.mark.parametrize("height, ground", [(1000.0, 3000.0), (2.0, 9.0)])
def test_merge_row_along_ray_and_in_2d_match_numpy(height, ground):
    """A merged parent row (4 children of 16 pulses 0.5 m apart on a straight track at ``height`` over a
    scene ``ground`` m away) against plain numpy: each child's polar image a sum of 5 plane waves in its own
    samples within its band (|nu_r| <= 1/(2U), |nu_u| <= 1/(2 beta), U = beta = 2), the exact sum of the
    children at the row's samples re-referenced; within the kernels' bound e_6(beta) + e_6(U / (1 + slack))
    of the waves' total amplitude, by the along-ray merge and by the 2-D one. Far from the track (3.2 km) the
    rows are separable; 9 m from it they are not, and the merge falls back to 2-D there."""
    rng = np.random.default_rng(5)
    pos = _track(64, 0.0)
    pos[:, 2] = height
    p0, nrm = np.array([ground, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    c_frames, c_len = _frames(pos, np.arange(0, 64, 16), np.arange(16, 65, 16), p0)
    fr = _frames(pos, np.array([0]), np.array([64]), p0)[0][0]
    k, dr, u, n = 4 * np.pi / 0.03, 0.1, 0.003, 40
    c_du = 0.03 / (2 * 2.0 * c_len)
    r0 = np.floor((np.hypot(height, ground) - 2.0) / dr) * dr
    rc, uc = _row_coordinates(fr, p0, nrm, c_frames, r0, u, n, dr)
    # child grids on the range lattice, 10 samples beyond the row's coordinates each way
    c_r0 = np.floor(rc.min(axis=1) / dr - 10) * dr
    c_nr = np.ceil((rc.max(axis=1) - c_r0) / dr + 10).astype(np.int64)
    c_u0 = uc.min(axis=1) - 10 * c_du
    c_nu = np.ceil((uc.max(axis=1) - c_u0) / c_du + 10).astype(np.int64)
    c_off = np.r_[0, np.cumsum(c_nr * c_nu)[:-1]].astype(np.int64)
    waves = [(rng.uniform(-0.25, 0.25, 5), rng.uniform(-0.25, 0.25, 5), rng.normal(size=5) + 1j * rng.normal(size=5))
             for _ in range(4)]

    def child_image(c, r, v):  # r, v: arrays of child ranges and angles
        nu_r, nu_u, a = waves[c]
        ph = nu_r * ((r - c_r0[c]) / dr)[..., None] + nu_u * ((v - c_u0[c]) / c_du[c])[..., None]
        return np.sum(a * np.exp(2j * np.pi * ph), axis=-1)

    child = np.concatenate([child_image(c, *np.meshgrid(c_r0[c] + dr * np.arange(c_nr[c]),
                                                        c_u0[c] + c_du[c] * np.arange(c_nu[c]))).ravel()
                            for c in range(4)]).astype(np.complex64)
    ref = sum(child_image(c, rc[c], uc[c]) * np.exp(1j * k * (rc[c] - (r0 + dr * np.arange(n)))) for c in range(4))
    amp = sum(np.abs(w[2]).sum() for w in waves)
    bound = amp * (kernel_error(6, 2.0) + kernel_error(6, 2.0 / (1 + ALONG_RAY_SLACK)))
    results = {}
    for name, gamma_max in (("along ray", 1e9), ("2-D", 0.0), ("as chosen", ALONG_RAY_SLACK)):
        acc = np.zeros(n, complex)
        width = int(c_nr.max())
        _merge_row(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, 0, 4, fr, p0, nrm, r0, u, n, dr, k, 6, 6,
                   kernel_table(6, 2.0), kernel_table(6, 2.0), gamma_max, np.empty(MAX_ORDER), np.empty(MAX_ORDER),
                   np.empty((n, 3)), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n),
                   np.empty(width, complex), acc)
        results[name] = acc
    # gamma: angle samples per range sample along the row, the largest over the children
    gamma = max(np.abs(np.diff(uc[c])).max() / c_du[c] * dr / np.diff(rc[c]).min() for c in range(4))
    assert np.abs(results["2-D"] - ref).max() <= bound
    if gamma <= ALONG_RAY_SLACK:
        assert height > 100  # far from the track: separable, so the merge as chosen is the along-ray one
        assert np.abs(results["along ray"] - ref).max() <= bound
        np.testing.assert_array_equal(results["as chosen"], results["along ray"])
    else:
        assert height < 10  # near the track the drift is too large for the range kernel: the merge stays 2-D
        np.testing.assert_array_equal(results["as chosen"], results["2-D"])


# --- end to end: a point target from a straight track, plain numpy echo and backprojection ---

LAM_C, B = C / 9.6e9, 300e6


@pytest.fixture(scope="module")
def point_scene():
    """256 pulses 0.4 m apart along y at 1 km height, a target at 3 km ground range; baseband profiles
    of a Hamming-weighted 300 MHz sweep, 8x oversampled; 48 x 48 pixels of 0.125 m x 0.1 m."""
    f = 9.6e9 + (np.arange(128) - 63.5) * B / 128
    pos = np.stack([np.zeros(256), (np.arange(256) - 128) * 0.4, np.full(256, 1000.0)], axis=1)
    target = np.array([3000.0, 1.3, 0.0])
    dr = C / (2 * B) / 8
    grid = 3122.0 + np.arange(int(80 / dr)) * dr  # slant ranges 3162 +- 40 m
    rt = np.linalg.norm(pos - target, axis=1)
    w = np.hamming(f.size)
    lines = (np.exp(-4j * np.pi * np.outer(rt, f) / C) * w) @ np.exp(4j * np.pi * np.outer(f - 9.6e9, grid) / C)
    lines /= w.sum()
    x, y = np.meshgrid(3000.0 + 0.125 * (np.arange(48) - 24), 1.3 + 0.1 * (np.arange(48) - 24), indexing="ij")
    pix = np.stack([x, y, np.zeros_like(x)], axis=-1)
    exact = np.zeros(x.shape, complex)
    for n in range(256):
        rho = np.linalg.norm(pix - pos[n], axis=-1)
        exact += (np.interp(rho, grid, lines[n].real) + 1j * np.interp(rho, grid, lines[n].imag)) \
            * np.exp(4j * np.pi * rho / LAM_C)
    # the exact image peaks at the target with the 256 pulses' unit amplitudes (the profile's 8x
    # oversampling costs < 1 % in linear interpolation)
    assert np.unravel_index(np.argmax(np.abs(exact)), exact.shape) == (24, 24) and np.abs(exact).max() > 0.99 * 256
    return {"lines": lines.astype(np.complex64), "grid": grid, "dr": dr, "pos": pos, "pix": pix, "exact": exact,
            "lam_min": C / f.max()}


def _peak_error(scene, knobs):
    stats: dict = {}
    img, wsum = ffbp(scene["lines"], scene["grid"][0], scene["dr"], C / (2 * B), LAM_C, scene["lam_min"],
                     scene["pos"], np.zeros(256), np.ones(256), scene["pix"], np.zeros(scene["pix"].shape[:2]), knobs,
                     stats=stats)
    ex = scene["exact"]
    i = np.unravel_index(np.argmax(np.abs(ex)), ex.shape)
    assert np.all(wsum == 256)
    # polar range spacing c/(2 B U): U as asked unless the lines are coarser
    u_r = (C / (2 * B)) / max(scene["dr"], C / (2 * B) / knobs.range_oversample)
    return abs(img[i] - ex[i]) / abs(ex[i]), peak_error_bound(knobs, stats["merge_stages"], u_r)


@pytest.mark.slow
@settings(max_examples=12, deadline=None)
@given(order=st.sampled_from([4, 6, 8]), beta=st.floats(1.5, 3.0), base=st.sampled_from([2, 4]),
       range_order=st.sampled_from([4, 6]))
def test_peak_error_within_the_model(point_scene, order, beta, base, range_order):
    err, bound = _peak_error(point_scene, FfbpKnobs(base=base, oversample=beta, order=order, range_order=range_order))
    assert err <= bound, (err, bound)


def test_the_image_does_not_depend_on_the_thread_count(point_scene):
    """Rows and pixel chunks are independent tasks (module docstring): one thread and two give the same
    image bit for bit."""
    import numba

    before = numba.get_num_threads()
    images = []
    try:
        for n in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(n)
            images.append(ffbp(point_scene["lines"], point_scene["grid"][0], point_scene["dr"], C / (2 * B), LAM_C,
                               point_scene["lam_min"], point_scene["pos"], np.zeros(256), np.ones(256),
                               point_scene["pix"], np.zeros(point_scene["pix"].shape[:2]), FfbpKnobs())[0])
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(images[0], images[1])


def test_error_falls_as_the_knobs_tighten(point_scene):
    errs = [_peak_error(point_scene, FfbpKnobs(oversample=b, order=n, range_order=n, range_oversample=b))[0]
            for b, n in ((1.5, 4), (2.0, 6), (3.0, 8))]
    assert errs[0] > errs[1] > errs[2], errs
    assert errs[2] < 2e-3, errs  # -> the exact backprojection


def test_knobs_are_checked():
    for bad in ({"base": 1}, {"oversample": 0.5}, {"order": 5}, {"range_order": 10}, {"aperture_split": 0},
                {"range_oversample": float("nan")}):
        with pytest.raises(ConfigError):
            FfbpKnobs(**bad)


# --- the stripmap focuser against backprojection on the Radarsat-1-like scene ---

@pytest.fixture(scope="module")
def rs1():
    from sarcli.focus.quality import TruthDoppler
    from sarcli.sim.scene import parse_scene
    from sarcli.sim.stripmap import simulate
    from tests.conftest import SAMPLES

    text = (SAMPLES / "rs1_point.toml").read_text()
    text = text.replace('"chirp_replica", "noise", "quantization"]', '"chirp_replica"]')
    raw = simulate(parse_scene(text))
    return raw, TruthDoppler.of(raw)


@pytest.mark.slow
def test_stripmap_ffbp_matches_backprojection(rs1):
    from sarcli.focus.bp_product import focus_bp
    from sarcli.focus.ffbp_product import focus_ffbp
    from sarcli.focus.quality import point_target_metrics, truth_targets
    from sarcli.focus.rda import plan_grid

    raw, dop = rs1
    (tz, r0) = truth_targets(raw.truth)[0]
    g = plan_grid(raw, raw.echo.shape, dop, None)
    t_out = g.zero_doppler_times(raw.azimuth_time)
    row, col = int(round(np.interp(tz, t_out, np.arange(t_out.size)))), int(round((r0 - g.ranges[0]) / (g.ranges[1]
                                                                                                       - g.ranges[0])))
    win = {"lines": (row - 40, row + 40), "samples": (col - 40, col + 40), "range_window": "kaiser:2.5",
           "azimuth_window": "kaiser:2.5"}
    bp = focus_bp(raw, dop, **win)
    ff = focus_ffbp(raw, dop, **win)
    assert ff.algorithm == "ffbp" and ff.parameters["ffbp_top_lines"] == 16
    mb, mf = point_target_metrics(bp.image, 40, 40, half=32), point_target_metrics(ff.image, 40, 40, half=32)
    assert abs(mf["row"] - mb["row"]) < 0.1 and abs(mf["col"] - mb["col"]) < 0.1  # measured 1e-4
    for ax in ("range", "azimuth"):
        assert abs(mf[f"pslr_{ax}_db"] - mb[f"pslr_{ax}_db"]) < 0.5  # measured 0.20 / 0.03 dB
    # the peak's error within the derived bound (one merge stage; lines upsampled 8x: U = 8 fs / B)
    bound = peak_error_bound(FfbpKnobs(), 1, 2.0)
    assert abs(mf["peak_amplitude"] / mb["peak_amplitude"] - 1) < bound
    assert abs(np.angle(np.exp(1j * (mf["peak_phase_rad"] - mb["peak_phase_rad"])))) < bound
    np.testing.assert_array_equal(ff.azimuth_time, bp.azimuth_time)
    np.testing.assert_array_equal(ff.slant_range, bp.slant_range)


@pytest.mark.slow
def test_stripmap_blocks_give_the_same_image(rs1):
    from sarcli.focus.ffbp_product import focus_ffbp
    from sarcli.focus.quality import truth_targets
    from sarcli.focus.rda import plan_grid

    raw, dop = rs1
    (tz, r0) = truth_targets(raw.truth)[0]
    g = plan_grid(raw, raw.echo.shape, dop, None)
    row = int(round(np.interp(tz, g.zero_doppler_times(raw.azimuth_time), np.arange(raw.azimuth_time.size))))
    col = int(round((r0 - g.ranges[0]) / (g.ranges[1] - g.ranges[0])))
    win = {"lines": (row - 24, row + 24), "samples": (col - 16, col + 16)}
    one = focus_ffbp(raw, dop, **win)
    many = focus_ffbp(raw, dop, block_lines=7, **win)
    assert many.parameters["n_blocks"] == 7 and one.parameters["n_blocks"] == 1
    # subapertures aligned to the raw line index, whole top subapertures read, one plane per plan: the
    # same samples and sums; only the polar grids' origins differ, so a sample's range r0 + i dr rounds
    # differently (1 ulp of 1e6 m: 2e-10 m, 5e-8 rad) and the complex64 output (6e-8) rounds with it
    assert np.abs(many.image - one.image).max() <= 1e-5 * np.abs(one.image).max()


@pytest.mark.slow
def test_cli_focus_ffbp(cli, tmp_path):
    """``sarcli focus --algorithm ffbp`` end to end on a window of the e2e scene, its knobs through --set, a
    bad knob refused in one line."""
    from sarcli.io.raw import read_raw
    from sarcli.io.slc import read_slc
    from tests.focus.test_cli import SCENES

    raw = tmp_path / "raw.h5"
    assert cli("simulate", SCENES / "e2e.toml", "-o", raw).exit_code == 0
    truth = read_raw(raw, load_echo=False).truth
    mid = truth["doppler_centroid_hz"].size // 2
    dop = ["--fdc", str(truth["doppler_centroid_hz"][mid]), "--fr", str(truth["doppler_rate_hz_per_s"][mid])]
    r = cli("focus", raw, "-o", tmp_path / "ffbp.h5", "--algorithm", "ffbp", *dop, "--set", "lines=[0,32]",
            "--set", "samples=[0,32]", "--set", "base=8")
    assert r.exit_code == 0, r.stderr
    slc = read_slc(tmp_path / "ffbp.h5")
    assert slc.image.shape == (32, 32) and slc.algorithm == "ffbp" and slc.parameters["base"] == 8
    bad = cli("focus", raw, "-o", tmp_path / "bad.h5", "--algorithm", "ffbp", *dop, "--set", "order=5")
    assert bad.exit_code != 0 and "order must be 2, 4, 6 or 8" in bad.stderr and "Traceback" not in bad.stderr
