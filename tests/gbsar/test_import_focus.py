"""Imported scans through `gbsar focus`: backprojection on a grid from a 3-D track with reference ranges,
the grid kernel against its numpy reference, and focusing in a medium (`--permittivity`)."""

from __future__ import annotations

import dataclasses

import h5py
import numpy as np
import pytest
import scipy.io
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import ConfigError, ProductError
from sarcli.gbsar.backprojection import bp_grid_kernel, bp_grid_reference, cis
from sarcli.gbsar.focus import FocusOptions, focus_scan
from sarcli.io.gbsar_image import read_gbsar_image
from sarcli.io.scan import read_scan, write_scan
from sarcli.model.constants import C_LIGHT
from sarcli.workflows import gbsar_focus, gbsar_import
from tests.gbsar.helpers import peak_near, scan_of


def test_cis_against_numpy():
    ph = np.r_[np.linspace(-50.0, 50.0, 100001), np.random.default_rng(1).uniform(-3e5, 3e5, 100000)]
    c, s = np.empty_like(ph), np.empty_like(ph)
    for k, p in enumerate(ph):
        c[k], s[k] = cis(p)
    err = np.abs(c + 1j * s - np.exp(1j * ph))
    assert err.max() < 3e-9  # the documented bound: Taylor truncation 7e-10, doubled by the double angle


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31), n_r=st.integers(4, 60), zeros=st.booleans())
def test_grid_kernel_matches_numpy_reference(seed, n_r, zeros):
    rng = np.random.default_rng(seed)
    n_s = 9
    prof = rng.standard_normal((n_s, n_r)) + 1j * rng.standard_normal((n_s, n_r))
    ant = rng.uniform(-20, 20, (n_s, 3))
    ref = rng.uniform(0, 30, n_s)
    w = rng.uniform(0.1, 1, n_s) * ((rng.uniform(size=n_s) > 0.3) if zeros else 1.0)
    xs, ys = np.sort(rng.uniform(-5, 5, 11)), np.sort(rng.uniform(-5, 5, 6))
    r_first, dr, z, kc = -0.5 * n_r * 0.3, 0.3, float(rng.uniform(-2, 2)), 400.0
    out, used = np.zeros((6, 11), complex), np.zeros((6, 11))
    bp_grid_kernel(prof.real.copy(), prof.imag.copy(), r_first, dr, ant, ref, w, xs, ys, z, kc, out, used)
    ref_out, ref_used = bp_grid_reference(prof, r_first, dr, ant, ref, w, xs, ys, z, kc)
    # float64 throughout; the kernel's cis is good to 3e-9 per term, summed over 9 terms of |w P| < ~4
    np.testing.assert_allclose(out, ref_out, rtol=0, atol=1e-7)
    np.testing.assert_allclose(used, ref_used, rtol=1e-12, atol=0)


# --- a point target seen from a 3-D track with reference ranges, through import and focus ---

F = 9.5e9 + 5e6 * np.arange(121)  # 600 MHz, R_max = c / (4 * 5 MHz) = 15 m about the reference
THETA = np.radians(np.linspace(-10.0, 10.0, 101))
TRACK = np.stack([40 * np.cos(THETA), 40 * np.sin(THETA), np.full(THETA.size, 30.0)], axis=1)  # 45 deg look
TARGET = np.array([1.2, -0.8, 0.3])
AMPLITUDE = 0.7 * np.exp(1.1j)


def _interp_loss_bound(n_f: int, df: float, oversample: int) -> float:
    """Worst shortfall of the linearly interpolated range profile at its peak, from the exact profile
    W(r) = sum_k w_k exp(j 4 pi (k - kc) df r / c) / sum w_k of the Hamming window (numpy, independent)."""
    n = oversample * int(2 ** np.ceil(np.log2(n_f)))
    dr = C_LIGHT / (2 * n * df)
    w = np.hamming(n_f)
    k = np.arange(n_f) - (n_f - 1) / 2

    def big_w(r):
        return np.real(np.exp(4j * np.pi * np.outer(r, k) * df / C_LIGHT) @ w) / w.sum()

    t = np.linspace(0, 1, 201)
    return float(1 - np.min((1 - t) * big_w(-t * dr) + t * big_w((1 - t) * dr)))


def _gotcha_like_file(path, samples):
    """The layout of an AFRL phase-history file: struct data with fp (frequency x pulse), freq, x, y, z, r0."""
    a = TRACK
    scipy.io.savemat(path, {"data": {"fp": samples.T.astype(np.complex64), "freq": F[:, None], "x": a[:, 0][None],
                                     "y": a[:, 1][None], "z": a[:, 2][None],
                                     "r0": np.linalg.norm(a, axis=1)[None]}})


def test_round_trip_3d_track_point_target(tmp_path):
    r0 = np.linalg.norm(TRACK, axis=1)
    d = np.linalg.norm(TRACK - TARGET, axis=1) - r0  # dR = |p - a| - r0, S21 ~ exp(-j 4 pi f dR / c)
    _gotcha_like_file(tmp_path / "track.mat", AMPLITUDE * np.exp(-4j * np.pi * np.outer(d, F) / C_LIGHT))
    gbsar_import.run(gbsar_import.Config(inputs=(tmp_path / "track.mat",), output=tmp_path / "scan.h5"))
    grid = (1.0, 1.4, 0.01, -1.0, -0.6, 0.005, TARGET[2])  # the target is the node (20, 40)
    rep = gbsar_focus.run(gbsar_focus.Config(scan=tmp_path / "scan.h5", output=tmp_path / "img.h5", algorithm="bp",
                                             grid_m=grid, quicklook=tmp_path / "img.png"))
    assert rep.focus["track"] == "3-D" and rep.focus["full_aperture_fraction"] == 1.0
    img = read_gbsar_image(tmp_path / "img.h5")
    assert img.grid_z_m == TARGET[2] and (tmp_path / "img.png").stat().st_size > 0
    g = img.image[0]
    iy, ix = np.unravel_index(np.argmax(np.abs(g)), g.shape)
    # resolution: range c/(2B) = 0.25 m (0.35 m on the ground at 45 deg, along x), azimuth
    # lam/(2 dtheta cos 45) = 0.062 m (along y): the peak is within one pixel, 1/35 and 1/12 of them
    assert abs(img.azimuth_m[ix] - TARGET[0]) <= 0.01 + 1e-9 and abs(img.range_m[iy] - TARGET[1]) <= 0.005 + 1e-9
    at = g[40, 20]
    assert img.azimuth_m[20] == pytest.approx(TARGET[0]) and img.range_m[40] == pytest.approx(TARGET[1])
    # the complex amplitude: phase exact (the profile's W is real); magnitude short of |a| by at most the
    # linear interpolation's loss at the profile peak, plus complex64 rounding
    assert abs(np.angle(at / AMPLITUDE)) < 1e-5
    loss = _interp_loss_bound(F.size, 5e6, 4)
    assert 0.7 * (1 - loss) - 1e-6 <= abs(at) <= 0.7 + 1e-6
    # a wrong sign defocuses: the conjugate data (or dR with the reference subtracted the other way)
    # focuses the point mirrored through the origin, nothing is left at the target
    sc = read_scan(tmp_path / "scan.h5")
    wrong = focus_scan(dataclasses.replace(sc, s21=np.conj(sc.s21)), FocusOptions(algorithm="bp", grid_m=grid))
    assert np.abs(wrong.image[0]).max() < 0.05 * abs(at)


def test_rail_scan_on_a_grid_matches_the_simulators_frame():
    """A rail scan's grid frame is the simulator's: antenna at (x_i, 0, h), scatterer (x, y, z)."""
    s = scan_of([(0.4, 12.0)], height=2.0, rail=2.0, step=0.05)
    f = focus_scan(s, FocusOptions(algorithm="bp", grid_m=(0.0, 0.8, 0.02, 11.5, 12.5, 0.02)))
    g = f.image[0]
    iy, ix = np.unravel_index(np.argmax(np.abs(g)), g.shape)
    assert f.grid.azimuths[ix] == pytest.approx(0.4) and f.grid.ranges[iy] == pytest.approx(12.0)
    assert abs(np.angle(g[iy, ix])) < 1e-3 and abs(g[iy, ix]) > 0.95


# --- focusing in a medium ---

EPS, DEPTH, XT = 6.0, 0.6, 0.1


def _gpr_npz(tmp_path):
    """A rail on the surface of a medium (eps = 6), a point 0.6 m deep under its centre:
    S21 ~ exp(-j 4 pi f sqrt(eps) R/c)."""
    f = 1e9 + 10e6 * np.arange(201)
    x = np.linspace(XT - 0.5, XT + 0.5, 51)
    r = np.hypot(x - XT, DEPTH)
    s = np.exp(-4j * np.pi * np.outer(r, f) * np.sqrt(EPS) / C_LIGHT)
    np.savez(tmp_path / "gpr.npz", s21=s, frequency=f, position=x)
    gbsar_import.run(gbsar_import.Config(inputs=(tmp_path / "gpr.npz",), output=tmp_path / "gpr.h5",
                                         antenna_length_m=0.02))
    return tmp_path / "gpr.h5"


@pytest.mark.parametrize("algorithm", ["bp", "auto"])
def test_permittivity_focuses_at_depth(tmp_path, algorithm):
    scan = _gpr_npz(tmp_path)
    out = {}
    for eps in (EPS, 1.0):
        o = tmp_path / f"{algorithm}_{eps}.h5"
        gbsar_focus.run(gbsar_focus.Config(scan=scan, output=o, algorithm=algorithm, permittivity=eps,
                                           max_range_m=2.0))
        out[eps] = read_gbsar_image(o)
    img = out[EPS]
    assert img.permittivity == EPS and img.wavelength_m == pytest.approx(C_LIGHT / (2e9 * np.sqrt(EPS)))
    g = img.image[0]
    iy, ix = np.unravel_index(np.argmax(np.abs(g)), g.shape)
    dr = img.range_m[1] - img.range_m[0]  # range bins of v / (2 N df) in the medium: 6 mm
    assert abs(img.range_m[iy] - DEPTH) <= dr and abs(img.azimuth_m[ix] - XT) <= 0.01
    assert abs(g[iy, ix]) > 0.9
    # the permittivity ignored: the peak at the electrical depth d sqrt(eps) = 1.47 m (within a range bin
    # of air, 1.5 cm), defocused: the data's hyperbola sqrt(eps) sqrt(u^2 + d^2) is no free-space one
    g1 = out[1.0].image[0]
    iy1, _ = np.unravel_index(np.argmax(np.abs(g1)), g1.shape)
    assert abs(out[1.0].range_m[iy1] - DEPTH * np.sqrt(EPS)) <= out[1.0].range_m[1]
    assert np.abs(g1).max() < 0.5 * abs(g[iy, ix])


def test_permittivity_below_one_and_grid_option_errors():
    with pytest.raises(ConfigError, match="--permittivity must be"):
        FocusOptions(permittivity=0.5)
    with pytest.raises(ConfigError, match="six or seven finite numbers"):
        FocusOptions(grid_m=(0, 1, 0.1))
    with pytest.raises(ConfigError, match="the step must be > 0"):
        FocusOptions(grid_m=(0, 1, 0.0, 0, 1, 0.1))
    with pytest.raises(ConfigError, match="use --algorithm bp, not rd"):
        FocusOptions(algorithm="rd", grid_m=(0, 1, 0.1, 0, 1, 0.1))
    with pytest.raises(ConfigError, match="--max-range shape the slant-plane grid"):
        FocusOptions(grid_m=(0, 1, 0.1, 0, 1, 0.1), max_range_m=3.0)
    with pytest.raises(ConfigError, match="more than"):
        FocusOptions(grid_m=(0, 1e4, 0.01, 0, 1e4, 0.01))


def test_3d_scans_refuse_the_rail_focusers_and_the_rail_only_commands(cli, tmp_path):
    d = np.linalg.norm(TRACK - TARGET, axis=1) - np.linalg.norm(TRACK, axis=1)
    _gotcha_like_file(tmp_path / "t.mat", np.exp(-4j * np.pi * np.outer(d, F) / C_LIGHT))
    scan = tmp_path / "t.h5"
    assert cli("gbsar", "import", tmp_path / "t.mat", "-o", scan).exit_code == 0
    r = cli("gbsar", "focus", scan, "-o", tmp_path / "i.h5")
    assert r.exit_code == 2 and "focus it on a grid with --algorithm bp --grid" in r.stderr
    assert cli("gbsar", "plan", scan).exit_code == 2
    grid = ("--grid", "-1,1,0.1,-1,1,0.1")
    r = cli("gbsar", "focus", scan, "-o", tmp_path / "g.h5", *grid, "--geotiff", tmp_path / "g.tif")
    assert r.exit_code == 2 and "no map geometry" in r.stderr
    r = cli("gbsar", "focus", scan, "-o", tmp_path / "g.h5", "--grid", "-1,1,a,-1,1,0.1")
    assert r.exit_code == 2 and "comma-separated numbers" in r.stderr
    r = cli("gbsar", "focus", scan, "-o", tmp_path / "g.h5", *grid, "--json")
    assert r.exit_code == 0, r.stderr
    r = cli("gbsar", "interfere", tmp_path / "g.h5", tmp_path / "g.h5", "-o", tmp_path / "ifg.h5")
    assert r.exit_code == 1 and "is a grid image" in r.stderr


def test_track_with_a_nan_position_is_refused(tmp_path):
    s = scan_of([(0.0, 10.0)], rail=0.5)
    bad = dataclasses.replace(s, antenna_position=np.stack([s.rail_position, np.zeros(s.n_stops), s.rail_height], 1))
    bad.antenna_position[3, 1] = np.nan
    with pytest.raises(ProductError, match=r"sweep\(s\) 3 is not finite"):
        focus_scan(bad, FocusOptions(algorithm="bp", grid_m=(0, 1, 0.1, 9, 11, 0.1)))


def test_schema_2_round_trip_and_schema_1_unchanged(tmp_path):
    s = scan_of([(0.0, 10.0)], rail=0.5)
    write_scan(tmp_path / "rail.h5", s)
    with h5py.File(tmp_path / "rail.h5") as f:
        assert f.attrs["schema_version"] == "1" and "antenna_position" not in f
    track = dataclasses.replace(s, antenna_position=np.stack([s.rail_position, np.ones(s.n_stops), s.rail_height], 1),
                                reference_range=np.full(s.n_stops, 9.5))
    write_scan(tmp_path / "track.h5", track)
    back = read_scan(tmp_path / "track.h5")
    np.testing.assert_array_equal(back.antenna_position, track.antenna_position)
    np.testing.assert_array_equal(back.reference_range, track.reference_range)
    assert read_scan(tmp_path / "rail.h5").is_rail and not back.is_rail


def test_rail_focus_unchanged_by_the_permittivity_default():
    """eps = 1 is the air every rail image was focused in: the same bits with and without the option."""
    s = scan_of([(0.3, 8.0)], rail=1.0)
    a = focus_scan(s, FocusOptions(algorithm="auto", max_range_m=12.0))
    b = focus_scan(s, FocusOptions(algorithm="auto", max_range_m=12.0, permittivity=1.0))
    np.testing.assert_array_equal(a.image, b.image)
    r, c, _ = peak_near(a.image[0], a.grid.ranges, a.grid.azimuths, 8.0, 0.3)
    assert abs(a.grid.ranges[r] - 8.0) < 0.2
