"""Hostile inputs found by hand, kept as regressions: inputs whose every number has the right type but no
physical meaning (absurd sizes, overflowing seeds, a rail of 4000 km, a Doppler model that contradicts
the geometry, valid-sample windows outside the record, a chirp of -1 Hz/s), which the commands took
with a traceback or, worse, exit 0 and a wrong product. Each case here is refused in one line
(``sarcli: error: ...``, exit 1 or 2, no output left behind; the promises of tests/fuzz/harness.py),
and its message names the number it refused. The scene-file fuzz (test_fuzz_scenes.py) and the
Doppler check of :func:`~tests.fuzz.harness.check_output` look for the same classes at random."""

from __future__ import annotations

import math

import pytest

from tests.conftest import run_cli
from tests.fuzz.harness import FDC_FR, AttrEdit, DataEdit, NoEdit, TextEdit, check_output, run_case

WALL = ("[[walls]]\nstart_m = [-1.0, 5.0, 1.5]\nend_m = [1.0, 5.0, 1.5]\nspacing_m = 1e-9\nscattering = 1.0\n\n"
        "[effects.noise]")
HUGE_GRID = ("gbsar", "focus", "{IN}", "--algorithm", "bp", "--grid", "-1e6,1e6,0.001,-1e6,1e6,0.001", "-o", "{OUT}")
FOCUS_DOPPLER = ("focus", "{raw}", "--doppler", "{IN}", "-o", "{OUT}")

REFUSED = [
    # (id, damaged input, corruption, command, a word of the one error line)
    # 21: absurd sizes and numbers in scene files: refused before allocating, one line
    ("scene-n-lines-1e8", "rs1_toml", TextEdit("tiny_rs1.toml", "n_lines = 256", "n_lines = 100000000"),
     ("simulate", "{IN}", "-o", "{OUT}"), "memory"),
    ("scene-n-samples-2e9", "rs1_toml", TextEdit("tiny_rs1.toml", "n_samples = 162", "n_samples = 2000000000"),
     ("simulate", "{IN}", "-o", "{OUT}"), "receive window"),
    ("scene-seed-overflow", "rs1_toml", TextEdit("tiny_rs1.toml", "seed = 20020616", "seed = 99999999999999999999"),
     ("simulate", "{IN}", "-o", "{OUT}"), "seed"),
    ("scene-snr-1e308", "rs1_toml", TextEdit("tiny_rs1.toml", "snr_db = 10.0", "snr_db = 1e308"),
     ("simulate", "{IN}", "-o", "{OUT}"), "snr_db"),
    ("gbsar-points-1e9", "gbsar_toml", TextEdit("tiny_gbsar.toml", "points = 41", "points = 1000000000"),
     ("gbsar", "simulate", "{IN}", "-o", "{OUT}"), "memory"),
    ("gbsar-wall-spacing-1e-9", "gbsar_toml", TextEdit("tiny_gbsar.toml", "[effects.noise]", WALL),
     ("gbsar", "simulate", "{IN}", "-o", "{OUT}"), "memory"),
    ("gbsar-seed-overflow", "gbsar_toml", TextEdit("tiny_gbsar.toml", "seed = 1", "seed = 99999999999999999999"),
     ("gbsar", "simulate", "{IN}", "-o", "{OUT}"), "seed"),
    ("gbsar-grid-1mm-1000km", "scan", NoEdit(), HUGE_GRID, "pixels"),
    # 22: wrong answers with exit 0
    ("doppler-fdc-x-power-minus-3", "doppler", AttrEdit("/fdc_poly", "x_power", -3), FOCUS_DOPPLER, "centroid"),
    ("doppler-fr-times-1e6", "doppler", DataEdit("/fr_poly/coef", "scale", factor=1e6), FOCUS_DOPPLER,
     "Doppler rate"),
    ("doppler-ambiguity-false", "doppler", AttrEdit("/", "ambiguity_resolved", False), FOCUS_DOPPLER, "ambiguity"),
    ("doppler-ambiguity-maybe", "doppler", AttrEdit("/", "ambiguity_resolved", "maybe"), FOCUS_DOPPLER,
     "ambiguity_resolved"),
    ("simulate-ceos-pulse-1s", "rs1_toml", TextEdit("tiny_rs1.toml", "pulse_length_s = 2.0e-6", "pulse_length_s = 1.0"),
     ("simulate", "{IN}", "--format", "ceos", "-o", "{OUT}"), "pulse"),
    ("gbsar-noise-nan", "gbsar_toml", TextEdit("tiny_gbsar.toml", "power_db = -50.0", "power_db = nan"),
     ("gbsar", "simulate", "{IN}", "-o", "{OUT}"), "power_db"),
    ("gbsar-rail-4000-km", "scan", DataEdit("/rail_position", "scale", factor=1e6),
     ("gbsar", "focus", "{IN}", "-o", "{OUT}"), "rail"),
    # 11: a GeoTIFF with no valid pixel (the tiny scene's 256 lines are shorter than its 708-line aperture)
    ("geotiff-no-full-line", "raw", NoEdit(), ("focus", "{IN}", *FDC_FR, "-o", "{OUT}", "--geotiff", "{OUT_TIF}"),
     "longer than the scene"),
]


@pytest.mark.parametrize("product, corruption, command, word", [k[1:] for k in REFUSED], ids=[k[0] for k in REFUSED])
def test_implausible_input_is_refused(pristine, product, corruption, command, word):
    out = run_case(pristine.paths, product, command, corruption, check_output)
    assert out.exit_code in (1, 2), f"exit {out.exit_code}: {out.case}\n{out.stderr}"
    assert word.lower() in out.stderr.lower(), out.stderr


def test_yaw_turned_180_is_refused(pristine):
    """The attitude says the beam looks 180 degrees off the flight direction (the orbit/attitude then
    predict fdc +5980 Hz where the echo holds -6590 Hz, the tiny scene's truth): a side-looking beam
    cannot, so the attitude is refused before its prediction is trusted. (The data-only cross-check,
    :func:`sarcli.doppler.pipeline._orbit_agrees_with_data`, cannot decide on the tiny scene: its
    data-only estimate has a 4.5 kHz standard error.)"""
    out = run_case(pristine.paths, "raw", ("doppler", "{IN}", "-o", "{OUT}"),
                   DataEdit("/attitude/yaw", "add", factor=math.pi), check_output)
    assert out.exit_code == 1 and "yaw" in out.stderr, out.stderr


def test_orbit_and_data_disagreeing_is_not_resolved(caplog):
    """The cross-check itself: an orbit centroid 10 PRFs from a data-only estimate of 50 Hz standard
    error (20 sigma) is not resolved and says so; one within 3 sigma is."""
    import numpy as np

    from sarcli.doppler.pipeline import _orbit_agrees_with_data
    from sarcli.model.doppler_summary import DataOnlyEstimate

    est = [DataOnlyEstimate("combined", -6590.0, 50.0, -5, 0.99, np.zeros(1))]
    assert not _orbit_agrees_with_data(lambda: (-5, 0.99), est, 5980.0, 140.0, 1257.0)
    assert "disagree" in caplog.text and "NOT resolved" in caplog.text
    # 3 sigma of hypot(140, 50) = 446 Hz: 400 Hz apart agrees
    assert _orbit_agrees_with_data(lambda: (-5, 0.99), est, -6190.0, 140.0, 1257.0)


def _nisar_l0b(path, window):
    import h5py

    from tests.nisar.synth import write_l0b

    write_l0b(path, n_lines=16, n_samples=48, pols=("HH",), cal_lines=(0,), window=(4, 40), fill_at=())
    with h5py.File(path, "r+") as f:
        ds = f["science/LSAR/RRSD/swaths/frequencyA/txH/validSamplesSubSwath1"]
        ds[...] = window


@pytest.mark.parametrize("window", [(40, 4), (10**12, 2 * 10**12), (-5, 40)], ids=["swapped", "1e12", "negative"])
def test_nisar_valid_samples_outside_the_record_refused(tmp_path, window):
    src = tmp_path / "l0b.h5"
    _nisar_l0b(src, window)
    r = run_cli("ingest", src, "-o", tmp_path / "raw.h5")
    assert r.exit_code == 1 and r.stderr.count("sarcli: error:") == 1, r.stderr
    assert "validSamplesSubSwath1" in r.stderr and not (tmp_path / "raw.h5").exists()


def _matlab_block(folder, kr):
    import numpy as np
    import scipy.io

    rng = np.random.default_rng(0)
    data = (rng.integers(-7, 8, (64, 96)) * 2 + 1 + 1j * (rng.integers(-7, 8, (64, 96)) * 2 + 1)).astype(np.complex64)
    scipy.io.savemat(folder / "block.mat", {"data": data})
    scipy.io.savemat(folder / "params.mat", {"f0": 5.3e9, "Fr": 32.317e6, "Kr": kr, "Tr": 41.75e-6, "PRF": 1256.98,
                                             "R0": 988647.462, "c": 2.9979e8})


def test_matlab_chirp_of_minus_one_hz_per_s_refused(tmp_path):
    _matlab_block(tmp_path, 0.72135e12)
    ok = run_cli("ingest", "--matlab", tmp_path / "block.mat", "--params", tmp_path / "params.mat",
                 "-o", tmp_path / "ok.h5")
    assert ok.exit_code == 0, ok.stderr
    _matlab_block(tmp_path, -1.0)
    r = run_cli("ingest", "--matlab", tmp_path / "block.mat", "--params", tmp_path / "params.mat",
                "-o", tmp_path / "raw.h5")
    assert r.exit_code == 1 and r.stderr.count("sarcli: error:") == 1, r.stderr
    assert "chirp" in r.stderr and not (tmp_path / "raw.h5").exists()


def test_gbsar_import_zip_garbage_and_all_nan(tmp_path):
    import numpy as np

    bad = tmp_path / "scan.npz"
    bad.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 4)
    r = run_cli("gbsar", "import", bad, "-o", tmp_path / "a.h5")
    assert r.exit_code == 1 and r.stderr.count("sarcli: error:") == 1, r.stderr
    nan = tmp_path / "nan.npz"
    np.savez(nan, s21=np.full((8, 5), np.nan, np.complex64), frequency=np.linspace(5e9, 6e9, 5),
             x=np.arange(8) * 0.1)
    r = run_cli("gbsar", "import", nan, "-o", tmp_path / "b.h5")
    assert r.exit_code == 1 and r.stderr.count("sarcli: error:") == 1, r.stderr
    assert "NaN" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["nan.npz", "scan.npz"]


WRITERS = [  # every command writing a product named by -o (23: a folder there is refused before any work)
    ("focus", "{raw}", "--fdc", "-6590", "--fr", "-1787", "-o", "{DIR}"),
    ("doppler", "{raw}", "-o", "{DIR}"),
    ("simulate", "{rs1_toml}", "-o", "{DIR}"),
    ("export", "{slc}", "-o", "{DIR}"),
    ("gbsar", "simulate", "{gbsar_toml}", "-o", "{DIR}"),
    ("gbsar", "focus", "{scan}", "-o", "{DIR}"),
    ("gbsar", "interfere", "{image}", "{image2}", "-o", "{DIR}"),
    ("focus", "{raw}", "--fdc", "-6590", "--fr", "-1787", "-o", "{OUT}", "--quicklook", "{DIR}"),
]


@pytest.mark.parametrize("command", WRITERS, ids=[f"{c[0]}-{c[1]}-{i}" for i, c in enumerate(WRITERS)])
def test_output_that_is_a_folder_is_refused_without_leftovers(pristine, tmp_path, command):
    folder = tmp_path / "adir"
    folder.mkdir()
    names = {"{DIR}": folder, "{OUT}": tmp_path / "o.h5", **{f"{{{k}}}": v for k, v in pristine.paths.items()}}
    r = run_cli(*[str(names.get(a, a)) for a in command])
    assert r.exit_code == 2 and r.stderr.count("sarcli: error:") == 1, r.stderr
    assert "folder" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir"] and not any(folder.iterdir())


def test_geotiff_tag_of_an_slc_without_a_fully_focused_line():
    """The tag said "3644..999" for the ALOS cut (first 3644, last -2645: the -1 "no span recorded"
    default of the model was read into every negative last line); now the recorded span, or none."""
    import numpy as np

    from sarcli.focus.geocode import full_span

    class S:
        azimuth_time = np.zeros(1000)

    for first, last, want in ((3644, -2645, (3644, -2645)), (0, -1, (0, 999)), (10, 989, (10, 989))):
        s = S()
        s.first_full_line, s.last_full_line = first, last
        assert full_span(s) == want
