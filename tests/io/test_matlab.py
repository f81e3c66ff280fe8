"""``sarcli ingest --matlab`` on the real Cumming & Wong Vancouver block (shared data, never copied)."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import scipy.io

from sarcli.io.h5common import sha256_file
from sarcli.io.raw import read_raw


def test_matlab_block_ingest(cli, shared_data, tmp_path):
    data = shared_data / "rs1_vancouver_block1.mat"
    params = shared_data / "rs1_vancouver_run_params.mat"
    before = (sha256_file(data), sha256_file(params))
    out = tmp_path / "van.h5"
    r = cli("ingest", "--matlab", data, "--params", params, "-o", out)
    assert r.exit_code == 0, r.stderr
    assert (sha256_file(data), sha256_file(params)) == before
    p = read_raw(out)
    assert p.shape == (1536, 2048) and p.source == "matlab" and p.orbit is None
    r_ = p.radar
    assert (r_.carrier_frequency_hz, r_.range_sampling_rate_hz, r_.prf_hz) == (5.3e9, 32.317e6, 1256.98)
    assert r_.chirp_rate_hz_per_s == -0.72135e12 and r_.pulse_length_s == 41.75e-6
    # placed where its parameter file says (first_rg_line 7321, first_rg_cell 760; for this block they are
    # another extraction's, tests/realdata settle 7769 / 1050): window 6.5956 ms at cell 1, 759 cells later
    assert r_.window_start_s == pytest.approx(6.5956e-3 + 759 / 32.317e6, rel=1e-12) and r_.quantization_bits == 4
    assert r_.first_range_m == pytest.approx(299792458 * r_.window_start_s / 2, rel=1e-12)
    np.testing.assert_allclose(p.azimuth_time, (7320 + np.arange(1536)) / 1256.98, rtol=0, atol=1e-12)
    assert "block placed at line 7321" in r.stderr and "cell 760" in r.stderr
    with h5py.File(out) as f:
        assert "orbit" not in f and "agc_db" not in f["radar"]
        assert f.attrs["pass_first_line"] == 7321 and f.attrs["pass_first_cell"] == 760
        assert f.attrs["published_doppler_centroid_hz"] == -6900.0
        assert f.attrs["published_effective_velocity_mps"] == 7062.0
        assert f.attrs["published_azimuth_fm_rate_hz_per_s"] == 1733.0
        assert "not measured" in f.attrs["published_note"] and "no state vectors" in f.attrs["orbit_note"]
        assert f.attrs["published_first_range_m"] == pytest.approx(988647.462)
    # The samples are the file's samples (independent load with scipy).
    ref = scipy.io.loadmat(data)["data"]
    assert np.array_equal(p.echo, ref.astype(np.complex64))
    # Baseband Doppler centroid from the lag-one azimuth correlation (plain numpy, format notes §4):
    # +487 Hz, i.e. -7055 Hz at ambiguity -6.
    x = p.echo.astype(np.complex128)
    fdc = np.angle(np.sum(x[1:] * np.conj(x[:-1]))) * r_.prf_hz / (2 * np.pi)
    assert fdc == pytest.approx(487.0, abs=3.0)
    assert fdc - 6 * r_.prf_hz == pytest.approx(-7055.0, abs=3.0)
    s = json.loads(cli("info", out, "--json").stdout)
    assert s["product_type"] == "raw" and s["shape"] == [1536, 2048]
    assert s["n_state_vectors"] == 0 and s["orbit_frame"] is None
    assert s["azimuth_start_utc"] == "2002-06-16T00:00:05.823482Z"  # line 7321: 7320 / PRF after line 1


def test_matlab_epoch_override_and_bad_inputs(cli, shared_data, tmp_path):
    data = shared_data / "rs1_vancouver_block1.mat"
    params = shared_data / "rs1_vancouver_run_params.mat"
    out = tmp_path / "v.h5"
    r = cli("ingest", "--matlab", data, "--params", params, "--epoch", "2002-06-16T14:50:00Z", "-o", out)
    assert r.exit_code == 0
    with h5py.File(out) as f:
        assert f.attrs["epoch_utc"] == "2002-06-16T14:50:00.000000Z"
        assert f.attrs["epoch_note"] == "given by the user (time of line 1 of the pass)"
    for args, needle in [
        (("--matlab", params, "--params", params), "no variable 'data'"),
        (("--matlab", data, "--params", data), "lacks f0"),
        (("--matlab", tmp_path / "none.mat", "--params", params), "no such file"),
        (("--matlab", out, "--params", params), "not a readable MATLAB"),
        (("--matlab", data, "--params", params, "--epoch", "yesterday"), "ISO-8601"),
        (("--matlab", data, "--params", params, "--first-line", "auto"), "give the table"),
        (("--matlab", data, "--params", params, "--first-line", "0"), "line number >= 1"),
        (("--matlab", data, "--params", params, "--first-line", "x"), "line number or auto"),
        (("--matlab", data, "--params", params, "--first-line", "19000"), "runs past the 19432 lines"),
        (("--matlab", data, "--params", params, "--first-cell", "8000"), "runs past the 9288 cells"),
        (("--matlab", data, "--params", params, "--agc", params), "no AGC variable"),
        (("--matlab", data, "--params", params, "--agc", tmp_path / "none.mat"), "no such file"),
    ]:
        r = cli("ingest", *args, "-o", tmp_path / "x.h5")
        assert r.exit_code != 0 and r.stderr.startswith("sarcli: error: ") and needle in r.stderr, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1
    # placement given instead of the file's, and the product's times and range follow
    r = cli("ingest", "--matlab", data, "--params", params, "--first-line", "7769", "--first-cell", "1050",
            "-o", out)
    assert r.exit_code == 0, r.stderr
    p = read_raw(out)
    assert p.azimuth_time[0] == pytest.approx(7768 / 1256.98, abs=1e-12)
    assert p.radar.window_start_s == pytest.approx(6.5956e-3 + 1049 / 32.317e6, rel=1e-12)
