"""``sarcli gbsar focus``/``plan``: impossible range intervals and criteria are refused in one line before
any focusing, and no image is written."""

from __future__ import annotations

import pytest

from .test_cli import _scan


def _one_line_error(r, needle: str) -> None:
    assert r.exit_code != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: ") and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr + r.stdout


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    from tests.conftest import run_cli

    return _scan(run_cli, tmp_path_factory.mktemp("scan"), "a")


@pytest.mark.parametrize("args, needle", [
    (["--max-range", "-3"], "max_range_m (--max-range) must be a positive"),
    (["--max-range", "0"], "max_range_m (--max-range) must be a positive"),
    (["--max-range", "nan"], "max_range_m (--max-range) must be a positive"),
    # 200 MHz, 201 points: range bins of c / (2 * 256 * 1 MHz) = 0.5855 m; 0.1 m holds one bin (rd crashed)
    (["--algorithm", "rd", "--max-range", "0.1"], "fewer than 4 range bins of 0.586 m"),
    (["--max-range", "2.0"], "fewer than 4 range bins"),
    (["--min-range", "10", "--max-range", "11"], "fewer than 4 range bins"),
    (["--min-range", "-1"], "min_range_m (--min-range) must be a finite range >= 0"),
    (["--min-range", "100"], "below the unambiguous range R_max = 74.95 m"),  # c / (4 * 1 MHz)
    (["--width", "0"], "width_m (--width) must be a positive"),
    (["--width", "0.01"], "holds no azimuth pixel of 0.3 m"),  # pixel round(0.5855/2 / 0.05) = 6 steps
    (["--n-xfft", "0"], "n_xfft (--n-xfft) must be a positive"),
    (["--criterion-deg", "400"], "--criterion-deg must be in (0, 180]"),
    (["--criterion-deg", "0"], "--criterion-deg must be in (0, 180]"),
])
def test_focus_bad_range_or_criterion(cli, scan, tmp_path, args, needle):
    out = tmp_path / "img.h5"
    _one_line_error(cli("gbsar", "focus", scan, "-o", out, *args), needle)
    assert not out.exists()


def test_focus_smallest_accepted_interval_and_plan_criterion(cli, scan, tmp_path):
    # 4 bins of 0.5855 m: 2.35 m is accepted and gives at least 4 range rows
    r = cli("gbsar", "focus", scan, "-o", tmp_path / "img.h5", "--algorithm", "rd", "--max-range", "2.4")
    assert r.exit_code == 0, r.stderr
    _one_line_error(cli("gbsar", "plan", scan, "--criterion-deg", "-5"), "--criterion-deg")


def test_focus_missing_output_folder_leaves_no_image(cli, scan, tmp_path):
    out = tmp_path / "img.h5"
    for extra in (["--quicklook", tmp_path / "nope" / "q.png"], ["--geotiff", tmp_path / "nope" / "a.tif"]):
        _one_line_error(cli("gbsar", "focus", scan, "-o", out, *extra), "does not exist")
        assert not out.exists()
