"""Real data: AFRL GOTCHA pass 1 HH (469 pulses, 424 frequencies at 9.29-9.91 GHz, four files) through
`gbsar import` and grid backprojection. Expected values from theory computed here from the raw files
(scipy.io, not the importer): the -3 dB widths of the point response, the mirror of a conjugated phase
history. The full 100 m x 100 m image and the speed comparison are in bench/bench_gotcha.py."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.io

from sarcli.focus.quality import cut_metrics
from sarcli.gbsar.focus import FocusOptions, focus_scan
from sarcli.io.scan import read_scan
from sarcli.model.constants import C_LIGHT
from sarcli.workflows import gbsar_import

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def gotcha_files(shared_data):
    d = shared_data / "gotcha_pass1_hh"
    files = sorted(d.glob("data_3dsar_pass1_az00?_HH.mat"))
    if len(files) != 4:
        pytest.skip(f"GOTCHA pass 1 HH phase histories not found in {d} (expected 4 data_3dsar_pass1_az00?_HH.mat)")
    return files


@pytest.fixture(scope="module")
def raw(gotcha_files):
    """The files as AFRL describes them (07_Readme.pdf): fp (frequency x pulse), freq, x, y, z, r0."""
    parts = [scipy.io.loadmat(p, squeeze_me=True, struct_as_record=False)["data"] for p in gotcha_files]
    return {k: np.concatenate([np.atleast_1d(getattr(d, k)).astype(np.float64) for d in parts])
            for k in ("x", "y", "z", "r0")} | {"freq": parts[0].freq.astype(np.float64),
                                                "fp": np.concatenate([d.fp for d in parts], axis=1)}


@pytest.fixture(scope="module")
def scan(gotcha_files, tmp_path_factory):
    out = tmp_path_factory.mktemp("gotcha") / "gotcha.h5"
    rep = gbsar_import.run(gbsar_import.Config(inputs=tuple(gotcha_files), output=out))
    assert (rep.n_sweeps, rep.n_frequencies, rep.layout, rep.track) == (469, 424, "frequency x position", "3-D")
    assert rep.polarization == "HH" and rep.polarization_from == "from the file names"
    assert rep.used == {"data": "data.fp", "frequency": "data.freq", "position": "data.x,data.y,data.z",
                        "reference_range": "data.r0"}
    return read_scan(out)


def test_import_keeps_the_phase_history(scan, raw):
    np.testing.assert_array_equal(scan.s21[0], raw["fp"].T)
    np.testing.assert_array_equal(scan.antenna_position, np.stack([raw["x"], raw["y"], raw["z"]], axis=1))
    np.testing.assert_array_equal(scan.reference_range, raw["r0"])
    # float32 frequencies: the uniform sweep within one float32 ulp (1024 Hz at 9.9 GHz)
    np.testing.assert_allclose(scan.frequency, raw["freq"], rtol=0, atol=1024)
    # r0 is the range to the frame origin (the scene centre) to the float32 rounding of the positions
    assert np.abs(np.linalg.norm(scan.antenna_position, axis=1) - raw["r0"]).max() < 1e-3


def _patch(scan, x, y, step, half=1.5, precision="single"):
    opts = FocusOptions(algorithm="bp", grid_m=(x - half, x + half, step, y - half, y + half, step),
                        bp_precision=precision)
    f = focus_scan(scan, opts)
    return f.image[0], f.grid.azimuths, f.grid.ranges


def _brightest(scan, box, n):
    """The n brightest local maxima (4 m apart at least) of a 0.1 m image over box = (x0, x1, y0, y1)."""
    f = focus_scan(scan, FocusOptions(algorithm="bp", grid_m=(box[0], box[1], 0.1, box[2], box[3], 0.1)))
    a = np.abs(f.image[0])
    found = []
    for k in np.argsort(a, axis=None)[::-1]:
        iy, ix = np.unravel_index(k, a.shape)
        p = np.array([f.grid.azimuths[ix], f.grid.ranges[iy]])
        if all(np.hypot(*(p - q)) > 4.0 for q in found):
            found.append(p)
        if len(found) == n:
            return found, a.max()


def _hamming_irw(n: int) -> float:
    """-3 dB (half-power) width of the DTFT of np.hamming(n), in units of 1/(n * sample spacing)."""
    m = 1 << 20
    p = np.abs(np.fft.fft(np.hamming(n), m)) ** 2
    k = int(np.argmax(p[: m // 2] < 0.5 * p[0]))
    return 2 * k / m * n


def test_point_responses_are_sharp(scan, raw):
    """The two brightest isolated returns (the calibration corner of the lot and its neighbour, the
    brightest of the 100 m scene): -3 dB widths on the ground against theory for the windows used."""
    x, y, z = raw["x"], raw["y"], raw["z"]
    phi = np.arctan2(z, np.hypot(x, y)).mean()  # elevation 45.75 deg
    theta = np.unwrap(np.arctan2(y, x))
    f = raw["freq"]
    n_f, n_p = f.size, theta.size
    span_f = (f[-1] - f[0]) * n_f / (n_f - 1)  # N df, the band the N samples stand for (623.8 MHz)
    span_t = (theta[-1] - theta[0]) * n_p / (n_p - 1)  # N dtheta (4.00 deg)
    lam = C_LIGHT / (0.5 * (f[0] + f[-1]))
    # ground range: slant c/(2 B) over cos(phi); cross-range: lam / (2 dtheta cos(phi)) [Jakowatz1996]
    theory_range = _hamming_irw(n_f) * C_LIGHT / (2 * span_f) / np.cos(phi)  # 0.448 m
    theory_azimuth = _hamming_irw(n_p) * lam / (2 * span_t * np.cos(phi))  # 0.417 m
    look = np.arctan2(y, x).mean()  # the ground-range direction is x within 2 deg (cos 2 deg = 0.9994)
    assert abs(np.degrees(look)) < 2.1
    points, _ = _brightest(scan, (-35.0, -10.0, 15.0, 45.0), 2)
    for p in points:
        g, xs, ys = _patch(scan, *p, step=0.01)
        iy, ix = np.unravel_index(np.argmax(np.abs(g)), g.shape)
        along_range = cut_metrics(g[iy, :], 0.01).irw
        along_azimuth = cut_metrics(g[:, ix], 0.01).irw
        assert 0.97 * theory_range < along_range < 1.10 * theory_range, (p, along_range, theory_range)
        assert 0.97 * theory_azimuth < along_azimuth < 1.10 * theory_azimuth, (p, along_azimuth, theory_azimuth)


def test_sign_convention(scan):
    """fp ~ exp(-j 4 pi f (|p - a| - r0)/c), the GB-SAR convention, as in AFRL's backprojection
    [GorhamMoore2010]. At 10 km the conjugate is no defocus but the scene mirrored through its centre
    (p -> -p: dR(-p) = -dR(p) to first order); reversing only the range envelope (the frequency axis)
    against the carrier destroys the focus."""
    (q,), _ = _brightest(scan, (-20.0, -11.0, 17.0, 26.0), 1)
    peak = np.abs(_patch(scan, *q, 0.02, half=1.0)[0]).max()
    mirror = dataclasses.replace(scan, s21=np.conj(scan.s21))
    assert np.abs(_patch(mirror, *(-q), 0.02, half=1.0)[0]).max() == pytest.approx(peak, rel=0.02)
    assert np.abs(_patch(mirror, *q, 0.02, half=1.0)[0]).max() < 0.2 * peak
    flipped = dataclasses.replace(scan, s21=scan.s21[:, :, ::-1])
    assert np.abs(_patch(flipped, *q, 0.02, half=1.5)[0]).max() < 0.1 * peak


def test_single_precision_keeps_the_point_responses(scan):
    """The float32 kernel (the default) against the float64 one at the two brightest returns, 1 cm grids:
    every pixel within the float32 bound of sarcli.focus.phasor (each term w_i v_i P_i has |v_i| <=
    max|P_i| over its profile; per term the recurrence (m <= 15), the float64 ranges, the interpolation and
    products (6 u), the running sum of 469 terms (468 u); both images divided by sum w_i), hence the same
    peak pixel, the peak phase within eps_rel = bound / peak rad, each PSLR within
    20 log10((s + eps_rel) / (s (1 - eps_rel))) dB of a sidelobe s."""
    from sarcli.focus.phasor import ANCHOR_EVERY, U32, range_phase_bound, recurrence_bound
    from sarcli.gbsar.rangecomp import range_compress
    from sarcli.gbsar.windows import taper

    prof = range_compress(scan, "HH", "hamming", 4, centred=True)
    w = taper("hamming", scan.n_stops) * prof.weights
    kc = 4 * np.pi / prof.wavelength_m
    per_term = recurrence_bound(ANCHOR_EVERY - 1) + 2 * range_phase_bound(kc, 2.1e4) + 6 * U32
    terms = float(np.sum(w * np.abs(prof.data.astype(np.complex128)).max(axis=1)))
    bound = terms * (per_term + (scan.n_stops - 1) * U32) / w.sum()
    points, _ = _brightest(scan, (-35.0, -10.0, 15.0, 45.0), 2)
    for p in points:
        single, _, _ = _patch(scan, *p, step=0.01)
        double, _, _ = _patch(scan, *p, step=0.01, precision="double")
        assert np.abs(single.astype(complex) - double).max() <= bound
        iy, ix = np.unravel_index(np.argmax(np.abs(double)), double.shape)
        assert np.unravel_index(np.argmax(np.abs(single)), single.shape) == (iy, ix)
        eps_rel = bound / np.abs(double[iy, ix])
        assert eps_rel < 1e-3
        assert abs(np.angle(single[iy, ix] * np.conj(double[iy, ix]))) <= eps_rel
        for cut_s, cut_d in ((single[iy, :], double[iy, :]), (single[:, ix], double[:, ix])):
            ms, md = cut_metrics(cut_s, 0.01), cut_metrics(cut_d, 0.01)
            side = 10 ** (md.pslr_db / 20)
            assert abs(ms.pslr_db - md.pslr_db) <= 20 * np.log10((side + eps_rel) / (side * (1 - eps_rel)))
