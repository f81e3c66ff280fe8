"""What the estimate refuses, and what it says when it cannot decide the ambiguity (docs/doppler.md): in-memory
products with broken times or radar parameters (one ProductError line each, never a confident number),
a narrow swath without an orbit (ambiguity not resolved: in the model, the product, the JSON and one
warning line), and the input left untouched."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

from sarcli.doppler.api import estimate_doppler
from sarcli.doppler.options import DopplerOptions
from sarcli.errors import ConfigError, ProductError
from sarcli.io.doppler_product import read_doppler
from sarcli.io.raw import write_raw
from sarcli.model.doppler_summary import DopplerSummary
from sarcli.model.raw import RawProduct

OPTS = DopplerOptions(az_block=512, rg_block=96)


def _radar(raw: RawProduct, **kw) -> RawProduct:
    return dataclasses.replace(raw, radar=dataclasses.replace(raw.radar, **kw))


def _times(raw: RawProduct, t: np.ndarray) -> RawProduct:
    return dataclasses.replace(raw, azimuth_time=t)


@pytest.mark.parametrize("case,match", [
    ("inf_time", "azimuth_time has 1 non-finite value"),
    ("nan_time", "azimuth_time has 1 non-finite value"),
    ("tiny_prf", "PRF 1e-09 Hz does not match the azimuth times"),
    ("prf_x2", "PRF 2513.97 Hz does not match the azimuth times"),
    ("zero_prf", "PRF must be a positive number"),
    ("gap", "line 200 comes 2 pulse intervals after line 199"),
    ("jitter", "not a regular pulse train"),
    ("reversed", "azimuth times do not increase"),
    ("short_times", "azimuth_time has shape"),
    ("long_pulse", "the pulse is longer than the pulse repetition interval"),
    ("wavelength", "wavelength .* and carrier .* disagree"),
    ("nan_wavelength", "radar wavelength_m must be a positive number"),
])
def test_implausible_products_are_refused(clutter_raw, case, match):
    raw = clutter_raw
    t = raw.azimuth_time.copy()
    prf = raw.radar.prf_hz
    if case == "inf_time":
        t[-1] = np.inf  # was: fdc +3839 Hz, ambiguity +3, exit 0 (truth about -6690 Hz)
        bad = _times(raw, t)
    elif case == "nan_time":
        t[7] = np.nan
        bad = _times(raw, t)
    elif case == "tiny_prf":
        bad = _radar(raw, prf_hz=1e-9)  # was: ambiguity -6.7e12, exit 0
    elif case == "prf_x2":
        bad = _radar(raw, prf_hz=2 * prf)
    elif case == "zero_prf":
        bad = _radar(raw, prf_hz=0.0)
    elif case == "gap":  # line 200 lost (a CEOS gap ingested with --missing keep)
        keep = np.r_[0:200, 201:t.size]
        bad = dataclasses.replace(raw, echo=raw.echo[keep], azimuth_time=t[keep])
    elif case == "jitter":
        t[100:] += 0.02 / prf  # 2 % of a pulse interval at one line
        bad = _times(raw, t)
    elif case == "reversed":
        bad = _times(raw, t[::-1].copy())
    elif case == "short_times":
        bad = _times(raw, t[:-1])
    elif case == "long_pulse":
        bad = _radar(raw, pulse_length_s=1.0 / prf)
    elif case == "wavelength":
        bad = _radar(raw, wavelength_m=raw.radar.wavelength_m * 1.01)
    else:
        bad = _radar(raw, wavelength_m=float("nan"))
    with pytest.raises(ProductError, match=match):
        estimate_doppler(bad, OPTS)


def test_spacing_tolerance_is_one_percent_of_a_pulse(clutter_raw):
    """0.9 % of a pulse interval at one line passes (0.5 % PRF of centroid at most, module docstring),
    1.1 % does not."""
    prf = clutter_raw.radar.prf_hz
    for frac, ok in ((0.009, True), (0.011, False)):
        t = clutter_raw.azimuth_time.copy()
        t[300:] += frac / prf
        raw = _times(clutter_raw, t)
        if ok:
            assert estimate_doppler(raw, OPTS).summary.ambiguity_resolved
        else:
            with pytest.raises(ProductError, match="1 irregular spacing"):
                estimate_doppler(raw, OPTS)


def test_a_forced_ambiguity_beyond_any_doppler_is_refused(clutter_raw):
    """|fdc| <= 2V/lam (V the orbit's ground speed, 7.55 km/s: 267 kHz, 212 PRFs); 300 PRFs - 410 Hz of
    baseband is 376.7 kHz. A wrong but possible ambiguity (-6, truth -5) is the user's to give."""
    with pytest.raises(ConfigError, match=r"centroid 3766\d\d Hz \(ambiguity 300\) is beyond the largest Doppler"):
        estimate_doppler(clutter_raw, dataclasses.replace(OPTS, ambiguity_value=300))
    assert estimate_doppler(clutter_raw, dataclasses.replace(OPTS, ambiguity_value=-6)).summary.ambiguity == -6


def test_the_input_is_not_modified(clutter_raw):
    raw = dataclasses.replace(_radar(clutter_raw, quantization_bits=4),
                              agc_db=np.linspace(0.0, 3.0, clutter_raw.echo.shape[0]),
                              echo=clutter_raw.echo.copy(), azimuth_time=clutter_raw.azimuth_time.copy())
    echo, t, agc = raw.echo.copy(), raw.azimuth_time.copy(), raw.agc_db.copy()
    estimate_doppler(raw, dataclasses.replace(OPTS, gain_steps="on"))
    np.testing.assert_array_equal(raw.echo, echo)
    np.testing.assert_array_equal(raw.azimuth_time, t)
    np.testing.assert_array_equal(raw.agc_db, agc)


@pytest.fixture(scope="module")
def narrow(clutter_raw):
    """No orbit and fewer range samples than the pulse: nothing can decide the ambiguity."""
    r = clutter_raw.radar
    n_pulse = int(round(r.pulse_length_s * r.range_sampling_rate_hz))  # 162 (the scene has no replica)
    return dataclasses.replace(clutter_raw, orbit=None, attitude=None, echo=clutter_raw.echo[:, :n_pulse - 10])


def test_unresolved_ambiguity_is_said_by_the_model(narrow):
    with pytest.warns(UserWarning, match=r"Doppler ambiguity not resolved \(no orbit, and the swath is not longer"):
        m = estimate_doppler(narrow, OPTS)
    s = m.summary
    assert s.ambiguity_source == "none" and not s.ambiguity_resolved and not m.ambiguity_resolved
    assert s.ambiguity == 0 and s.ambiguity_confidence == 0.0
    with pytest.warns(UserWarning, match=r"not resolved \(ambiguity mode none\)"):
        assert not estimate_doppler(narrow, dataclasses.replace(OPTS, ambiguity="none")).ambiguity_resolved
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a given ambiguity is resolved: no warning
        assert estimate_doppler(narrow, dataclasses.replace(OPTS, ambiguity_value=-5)).ambiguity_resolved


def test_unresolved_ambiguity_in_the_product_json_and_one_warning_line(cli, narrow, tmp_path):
    raw, out = tmp_path / "narrow.h5", tmp_path / "doppler.h5"
    write_raw(raw, narrow)
    r = cli("doppler", raw, "--json", "-o", out, "--az-block", "512", "--rg-block", "96")
    assert r.exit_code == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["ambiguity_resolved"] is False and d["ambiguity_source"] == "none"
    assert len(d["warnings"]) == 1 and "not resolved" in d["warnings"][0]
    lines = r.stderr.strip().splitlines()
    assert sum(x.startswith("sarcli: warning: Doppler ambiguity not resolved") for x in lines) == 1
    m = read_doppler(out)
    assert not m.ambiguity_resolved
    import h5py

    with h5py.File(out) as f:
        assert int(f.attrs["ambiguity_resolved"]) == 0 and f.attrs["ambiguity_source"] == "none"
    r = cli("doppler", raw, "--ambiguity-value", "-5")
    assert r.exit_code == 0 and "warning" not in r.stderr and "NOT RESOLVED" not in r.stderr
    r = cli("doppler", raw)
    assert "[none, NOT RESOLVED" in r.stderr


def test_products_of_the_old_bug_read_as_unresolved(narrow):
    """doppler.h5 written before the fix said ``ambiguity_resolved: true`` with source "none"."""
    with pytest.warns(UserWarning):
        d = estimate_doppler(narrow, OPTS).summary.to_dict()
    d["ambiguity_resolved"] = True
    assert DopplerSummary.from_dict(d).ambiguity_resolved is False
    with pytest.raises(ProductError, match="cannot be resolved"):
        dataclasses.replace(DopplerSummary.from_dict(d), ambiguity_resolved=True)
