"""A real Radarsat-1 block in relative radiometry. A Cumming & Wong MATLAB block has no antenna
description, no absolute calibration and no state vectors: the radiometry applies what it can (the
processing gain, the range spreading loss), and says in the product and on stderr which terms it could
not apply; without an orbit there is no incidence angle, so the product offers relative beta0 and no
sigma0 (NaN), never an uncalibrated number under that name."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.slow
def test_block_in_relative_radiometry_names_the_terms_not_applied(rs1_pass, cli, tmp_path):
    from sarcli.calibration.radiometry import calibrated_intensity
    from sarcli.io.slc import read_slc

    data, params, line, cell = rs1_pass["blocks"]["block1"]
    raw = tmp_path / "raw.h5"
    extra = [] if line is None else ["--first-line", str(line), "--first-cell", str(cell)]
    r = cli("ingest", "--matlab", data, "--params", params, "--agc", rs1_pass["agc"], *extra, "-o", raw)
    assert r.exit_code == 0, r.stderr
    r = cli("focus", raw, "--fdc", "-6900", "--fr", "-1733", "-o", tmp_path / "slc.h5")
    assert r.exit_code == 0, r.stderr
    for term in ("antenna elevation pattern", "antenna azimuth pattern", "absolute calibration constant K",
                 "no incidence angle"):
        assert term in r.stderr
    slc = read_slc(tmp_path / "slc.h5")
    cal = slc.calibration
    assert any("antenna elevation pattern" in t for t in cal.not_applied)
    assert any(t.startswith("range spreading loss") for t in cal.applied)
    assert np.isnan(cal.nes0).all()  # no noise lines, no stated receiver noise: no noise floor claimed
    assert np.isnan(cal.sigma0).all() and np.isnan(cal.gamma0).all()
    la, lr = 4, 2
    n, m = slc.image.shape[0] // la, slc.image.shape[1] // lr
    inten = (np.abs(slc.image[: n * la, : m * lr]) ** 2).reshape(n, la, m, lr).mean(axis=(1, 3))
    beta0 = calibrated_intensity(slc, inten, la, lr, "beta0")
    ok = np.isfinite(beta0)
    # finite inside the fully range-compressed span (the swath less c T / 4 = 3.1 km at either end)
    assert 0.2 < ok.mean() < 1.0 and not ok[:, 0].any() and not ok[:, -1].any()
    # relative: the lut varies across the swath only as (R / R_ref)^4 / (E_a(R)) with E_a ~ 1 / |f_R| ~ R,
    # i.e. as R^3: between the calibrated span's ends (R_hi / R_lo)^3
    lo, hi = cal.details["compressed_range_m"]
    lut = cal.beta0[cal.beta0.shape[0] // 2]
    fin = np.isfinite(lut)
    assert lut[fin][-1] / lut[fin][0] == pytest.approx((cal.slant_range[fin][-1] / cal.slant_range[fin][0]) ** 3,
                                                        rel=2e-3)
    assert lo > slc.slant_range[0] and hi < slc.slant_range[-1]
