"""The float32 grid backprojection kernel (:func:`sarcli.gbsar.backprojection.bp_grid_kernel32`): its
phasor recurrence against exp(j k rho) in float64 numpy, the whole kernel against the complex128 numpy
reference, both within the error bounds derived in :mod:`sarcli.focus.phasor` (hypothesis over range
10 m .. 1000 km and wavelength 3 .. 24 cm), and the image bit-identical across thread counts and tiles."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import ConfigError
from sarcli.focus.backprojection import lerp_pairs
from sarcli.focus.phasor import ANCHOR_EVERY, EPS_MAX, U32, range_phase_bound, recurrence_bound
from sarcli.gbsar.backprojection import backproject_grid, bp_grid_kernel32, bp_grid_reference, grid_anchor_interval
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.model.constants import C_LIGHT

ranges = st.floats(10.0, 1e6).map(lambda r: float(r))
wavelengths = st.floats(0.03, 0.24)


def test_recurrence_bound_values():
    """The bound of the module docstring by hand at m = 15: 16 eta_a + 120 (eta_e + sqrt5 u) + 15 sqrt5 u."""
    u = 2.0 ** -24
    eta_a, eta_e = u + 3e-9, 3 * u + 0.125 ** 6 / 720
    assert recurrence_bound(15) == pytest.approx(16 * eta_a + 120 * (eta_e + 5 ** 0.5 * u) + 15 * 5 ** 0.5 * u)
    assert recurrence_bound(0) == pytest.approx(eta_a)
    assert recurrence_bound(ANCHOR_EVERY - 1) < 4.2e-5  # the figure the docstring quotes


@settings(max_examples=40, deadline=None)
@given(r=ranges, lam=wavelengths, frac=st.floats(0.05, 1.0), squint=st.floats(-0.5, 0.5), h=st.floats(0.0, 0.9))
def test_phasor_recurrence_within_its_bound(r, lam, frac, squint, h):
    """One sweep, a constant profile (1 + 0 j, slope 0: the interpolation gives 1 exactly, weight 1): the
    image is the kernel's phasor itself, 48 rows down each column (three anchors). Against
    exp(j k rho) with rho in float64 numpy, the error stays below recurrence_bound(row mod 16) plus the
    float64 range rounding of both computations (2 x range_phase_bound), row by row."""
    kc = 4 * np.pi / lam
    step = frac * math.sqrt(EPS_MAX * r / kc) / 1.5  # kc step^2 / rho_min <= EPS_MAX with margin
    ant = np.array([[0.0, 0.0, h * r]])
    ground = r * math.sqrt(1 - h * h)
    xs = ground + step * np.arange(3)
    ys = squint * r + step * np.arange(48)
    ref = np.array([r])
    assert grid_anchor_interval(ant, xs, ys, 0.0, kc) == ANCHOR_EVERY
    out = np.zeros((ys.size, xs.size), np.complex64)
    used = np.zeros(out.shape)
    pairs = lerp_pairs(np.ones((1, 4), np.complex64))
    span = 10 * (r + 1.0)  # the profile covers every relative range: u = (rho + span) / span in [0, 3)
    bp_grid_kernel32(pairs, -span, span, ant, ref, np.ones(1), xs, ys, 0.0, kc, ANCHOR_EVERY, 16, 2, out, used)
    gx, gy = np.meshgrid(xs, ys)
    rho = np.sqrt(gx ** 2 + gy ** 2 + (h * r) ** 2) - r
    exact = np.exp(1j * kc * rho)
    err = np.abs(out - exact)
    rows = np.arange(ys.size) % ANCHOR_EVERY
    bound = recurrence_bound(rows)[:, None] + 2 * range_phase_bound(kc, 3 * r + 100 * step)
    assert np.all(used == 1.0)
    assert np.all(err <= bound), float((err / bound).max())


def _scene(seed, r, lam, n_s=7, n_r=64, ny=40, nx=24, zeros=False):
    """A short arc of antenna positions at range ~r about the origin (reference ranges |a|, as GOTCHA's r0),
    random profiles covering the grid's relative ranges, a grid about the origin."""
    rng = np.random.default_rng(seed)
    kc = 4 * np.pi / lam
    theta = np.radians(rng.uniform(-3, 3)) + np.linspace(0, 0.02, n_s) * rng.uniform(0.2, 1)
    elev = rng.uniform(0.1, 1.2)
    ant = r * np.stack([np.cos(theta) * np.cos(elev), np.sin(theta) * np.cos(elev),
                        np.full(n_s, np.sin(elev))], axis=1)
    ant += rng.normal(0, 1e-3 * lam, ant.shape)  # positions off a smooth arc (like float32-stored ones)
    ref = np.linalg.norm(ant, axis=1)
    step = min(0.2, rng.uniform(0.3, 1.0) * math.sqrt(EPS_MAX * r / kc) / 2)
    xs = step * (np.arange(nx) - nx / 2) + rng.uniform(-1, 1) * step
    ys = step * (np.arange(ny) - ny / 2)
    dr = 2.2 * step * (nx + ny) / n_r
    r_first = -0.5 * n_r * dr
    prof = (rng.standard_normal((n_s, n_r)) + 1j * rng.standard_normal((n_s, n_r))).astype(np.complex64)
    w = rng.uniform(0.1, 1, n_s) * ((rng.uniform(size=n_s) > 0.3) if zeros else 1.0)
    return prof, r_first, dr, ant, ref, w, xs, ys, kc


def _bound(prof, w, every, kc, r_max):
    """Per-pixel bound on |float32 kernel - complex128 reference|: each term w_i v_i P_i has |v_i| <= A_i =
    max|prof_i| (linear interpolation is a convex combination). Its error: the phasor (recurrence_bound at
    m = every - 1, the float64 ranges 2 x range_phase_bound), the interpolation (t rounded to float32,
    the slope and the two operations: 3 u A_i), the products v P (sqrt5 u) and w (v P) (u); the float32
    running sum of n terms adds (n - 1) u sum |terms| (first order)."""
    a = np.abs(prof.astype(np.complex128)).max(axis=1)
    terms = float(np.sum(np.abs(w) * a))
    per_term = recurrence_bound(every - 1) + 2 * range_phase_bound(kc, r_max) + (3 + 5 ** 0.5 + 1) * U32
    return terms * (per_term + (prof.shape[0] - 1) * U32)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), r=ranges, lam=wavelengths, zeros=st.booleans())
def test_grid_kernel32_matches_complex128_reference(seed, r, lam, zeros):
    prof, r_first, dr, ant, ref, w, xs, ys, kc = _scene(seed, r, lam, zeros=zeros)
    every = grid_anchor_interval(ant, xs, ys, 0.0, kc)
    out = np.zeros((ys.size, xs.size), np.complex64)
    used = np.zeros(out.shape)
    bp_grid_kernel32(lerp_pairs(prof), r_first, dr, ant, ref, w, xs, ys, 0.0, kc, every, 16, 8, out, used)
    ref_out, ref_used = bp_grid_reference(prof.astype(np.complex128), r_first, dr, ant, ref, w, xs, ys, 0.0, kc)
    assert every == ANCHOR_EVERY  # the scene's steps keep eps within EPS_MAX: the recurrence is what is tested
    np.testing.assert_allclose(used, ref_used, rtol=1e-12, atol=0)
    err = np.abs(out - ref_out).max()
    assert err <= _bound(prof, w, every, kc, 2.1 * r), (err, _bound(prof, w, every, kc, 2.1 * r))


def test_coarse_grid_near_the_antenna_anchors_every_row():
    """A 0.5 m grid 10 m from the antenna at 3 cm: k step^2 / rho = 419 x 0.25 / 10 = 10 rad >> EPS_MAX, so
    the recurrence would be wrong; the kernel anchors every row (the float64 phasor) and still matches."""
    prof, r_first, dr, ant, ref, w, _, _, kc = _scene(3, 10.0, 0.03)
    xs = 0.5 * np.arange(-4, 5)
    ys = 0.5 * np.arange(-6, 7)
    dr = 0.5 * 30 / prof.shape[1]
    r_first = -0.5 * prof.shape[1] * dr
    assert grid_anchor_interval(ant, xs, ys, 0.0, kc) == 1
    out = np.zeros((ys.size, xs.size), np.complex64)
    used = np.zeros(out.shape)
    bp_grid_kernel32(lerp_pairs(prof), r_first, dr, ant, ref, w, xs, ys, 0.0, kc, 1, 4, 4, out, used)
    ref_out, _ = bp_grid_reference(prof.astype(np.complex128), r_first, dr, ant, ref, w, xs, ys, 0.0, kc)
    assert np.abs(out - ref_out).max() <= _bound(prof, w, 1, kc, 30.0)


def test_bit_identical_across_threads_and_tiles():
    """Each pixel is one tile's, its sweeps summed in order, the anchors on global rows and no FMA
    contraction: the image does not depend on the tiling or the number of threads, bit for bit."""
    prof, r_first, dr, ant, ref, w, xs, ys, kc = _scene(11, 1e4, 0.031, n_s=9, ny=70, nx=37)
    pairs = lerp_pairs(prof)
    results = []
    threads = numba.get_num_threads()
    try:
        for n_threads in sorted({1, numba.config.NUMBA_NUM_THREADS}):
            numba.set_num_threads(n_threads)
            for ty, tx in ((16, 8), (32, 64), (48, 5), (80, 37)):
                out = np.zeros((ys.size, xs.size), np.complex64)
                used = np.zeros(out.shape)
                bp_grid_kernel32(pairs, r_first, dr, ant, ref, w, xs, ys, 0.0, kc, ANCHOR_EVERY, ty, tx, out, used)
                results.append(out)
    finally:
        numba.set_num_threads(threads)
    for other in results[1:]:
        np.testing.assert_array_equal(other, results[0])


def test_backproject_grid_precisions_agree():
    """The public entry point: single (default) vs double on the same profiles, within the float32 bound
    (both normalized by the same sum of weights), and an unknown precision refused in one line."""
    prof, r_first, dr, ant, ref, w, xs, ys, kc = _scene(5, 5e3, 0.0566)
    n_s = prof.shape[0]
    rp = RangeProfiles(data=prof, dr_m=dr, center_frequency_hz=C_LIGHT * kc / (4 * np.pi), frequency_step_hz=1e6,
                       n_freq=prof.shape[1], positions_m=np.zeros(n_s), heights_m=np.zeros(n_s),
                       weights=np.ones(n_s), skipped=[], first_range_m=r_first)
    single, frac1 = backproject_grid(rp, ant, ref, xs, ys, 0.0, "rect")
    double, frac2 = backproject_grid(rp, ant, ref, xs, ys, 0.0, "rect", precision="double")
    assert single.dtype == np.complex64
    np.testing.assert_array_equal(frac1, frac2)
    # the kernels' sums within _bound, divided by the same total (n_s); each result rounded once more to
    # complex64 (u of the value, both sides)
    bound = _bound(prof, np.ones(n_s), ANCHOR_EVERY, kc, 2.1 * 5e3) / n_s + 3 * U32 * np.abs(double).max()
    assert np.abs(single.astype(complex) - double).max() <= bound
    with pytest.raises(ConfigError, match="precision"):
        backproject_grid(rp, ant, ref, xs, ys, 0.0, "rect", precision="half")


def test_cli_double_selects_the_float64_kernel(cli, tmp_path):
    """``gbsar focus --grid ... --double``: the report names the kernel, and the two products of an
    imported unit point target agree within the float32 bound: its profiles are exp(-j kc rho) W with
    |W| <= W(0) = 1, so sum_i w_i |v_i| / sum_i w_i <= 1 and the normalized error is at most the per-term
    bound (phasor, ranges, 6 u) plus the sum's (n - 1) u, plus the float32 division by sum w and the
    complex64 rounding of the float64 image (u each)."""
    import json

    from sarcli.io.gbsar_image import read_gbsar_image
    from tests.gbsar.test_import_focus import TARGET, TRACK, F, _gotcha_like_file

    d = np.linalg.norm(TRACK - TARGET, axis=1) - np.linalg.norm(TRACK, axis=1)
    _gotcha_like_file(tmp_path / "t.mat", np.exp(-4j * np.pi * np.outer(d, F) / C_LIGHT))
    scan = tmp_path / "t.h5"
    assert cli("gbsar", "import", tmp_path / "t.mat", "-o", scan).exit_code == 0
    grid = ("--grid", "0.6,1.8,0.05,-1.4,-0.2,0.05,0.3")
    images = {}
    for name, extra in (("single", ()), ("double", ("--double",))):
        r = cli("gbsar", "focus", scan, "-o", tmp_path / f"{name}.h5", *grid, "--json", *extra)
        assert r.exit_code == 0, r.stderr
        assert json.loads(r.stdout)["bp_precision"] == name
        images[name] = read_gbsar_image(tmp_path / f"{name}.h5").image[0].astype(complex)
    kc = 4 * np.pi * F.mean() / C_LIGHT
    bound = (recurrence_bound(ANCHOR_EVERY - 1) + 2 * range_phase_bound(kc, 200.0)
             + (6 + TRACK.shape[0] - 1) * U32 + 2 * U32)
    assert np.abs(images["double"]).max() == pytest.approx(1.0, abs=0.05)  # the unit target is on the grid
    assert np.abs(images["single"] - images["double"]).max() <= bound
