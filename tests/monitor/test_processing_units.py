"""APS fit, unwrapping, velocity / acceleration weights, inverse velocity, alarms, meteo: each against
values built by construction, an independent numpy computation or published figures."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.monitor import aps
from sarcli.monitor.alarms import AlarmState, csv_header, csv_line, level_of, run_hook, step
from sarcli.monitor.config import AreaEntry
from sarcli.monitor.kinematics import acceleration_weights, inverse_velocity_forecast, slope_weights
from sarcli.monitor.meteo import MeteoFile, refractivity_ppm
from sarcli.monitor.unwrap import unwrap_increment

LAM = 299792458.0 / 5.3e9


# -- APS ---------------------------------------------------------------------------------------------
@given(a=st.floats(-3, 3), dn=st.floats(-40, 40), c=st.floats(-1e-5, 1e-5))
@settings(max_examples=30)
def test_aps_fit_recovers_the_model_despite_outliers(a, dn, c):
    rng = np.random.default_rng(1)
    r = rng.uniform(100, 300, 400)
    dz = rng.uniform(-5, 60, 400)
    b = -4 * np.pi * 1e-6 * dn / LAM  # a refractivity change dN is a range slope -4 pi 1e-6 dN / lam
    phase = a + b * r + c * r * dz + rng.normal(0, 0.01, 400)
    phase[:40] += rng.uniform(-3, 3, 40)  # 10 % of moving or noisy points in the "stable" set
    m = aps.fit(phase, r, dz, "range-height")
    # Huber's psi bounds each outlier's pull to k s = 1.345 x 0.01 rad: 40 of them shift the fit by at
    # most ~1.3e-3 rad overall, i.e. ~2e-5 rad/m on b (std of R ~ 58 m) and ~2e-7 rad/m^2 on c (std of
    # R dz ~ 6000 m^2); tolerances are 3-5 times those
    assert m.a == pytest.approx(a, abs=0.02) and m.b == pytest.approx(b, abs=2e-4)
    assert m.c == pytest.approx(c, abs=1e-6)
    assert m.refractivity_ppm(LAM) == pytest.approx(dn, abs=1.0)
    np.testing.assert_allclose(m.evaluate(r, dz), a + b * r + c * r * dz, atol=0.03)


def test_aps_fit_wrapped_increment_spanning_several_cycles():
    rng = np.random.default_rng(2)
    r = rng.uniform(100, 900, 500)
    b = -4 * np.pi * 1e-6 * 12.0 / LAM  # 12 ppm in one interval: 21 rad across 800 m, many wraps
    w = aps.wrap(0.7 + b * r + rng.normal(0, 0.05, 500))
    m = aps.fit_wrapped(w, r, None, "range", LAM)
    assert m.b == pytest.approx(b, abs=4e-5)  # 4 sigma: 0.05 rad / (std(R) 231 m * sqrt(500)) = 9.7e-6
    assert np.abs(aps.wrap(m.evaluate(r, None) - (0.7 + b * r))).max() < 0.02


def test_aps_model_choice():
    assert aps.choose_kind(0, 20, True) == "none"
    assert aps.choose_kind(5, 20, True) == "constant"
    assert aps.choose_kind(50, 20, False) == "range" and aps.choose_kind(50, 20, True) == "range-height"


# -- unwrapping ---------------------------------------------------------------------------------------
def _grid(n=60):
    yy, xx = np.mgrid[0:n, 0:n]
    return yy, xx


def test_temporal_unwrapping_around_the_prediction():
    yy, xx = _grid()
    true = 0.02 * xx + 2.5  # within a quarter cycle of the prediction 2.5
    ok = np.ones(true.shape, bool)
    inc = unwrap_increment(aps.wrap(true), np.full(true.shape, 2.5), ok, ok, ok, 0.1, True, 10.0)
    assert inc.accepted and inc.method == "temporal"
    np.testing.assert_allclose(inc.delta, true, atol=1e-9)


def test_spatial_unwrapping_where_the_temporal_check_fails():
    """A body moving by up to 1.3 cycles (smooth in space) in one interval, stable ground around it."""
    yy, xx = _grid()
    body = (xx > 20) & (xx < 45) & (yy > 10) & (yy < 50)
    bump = np.where(body, 2 * np.pi * 1.3 * np.sin(np.pi * (xx - 20) / 25) * np.sin(np.pi * (yy - 10) / 40), 0.0)
    ok = np.ones(bump.shape, bool)
    stable = ~body
    inc = unwrap_increment(aps.wrap(bump), np.zeros(bump.shape), ok, stable, ok, 0.05, True, 10.0)
    assert inc.accepted and inc.method == "spatial" and inc.implausible_fraction > 0.05
    np.testing.assert_allclose(inc.delta, bump, atol=1e-6)
    no = unwrap_increment(aps.wrap(bump), np.zeros(bump.shape), ok, stable, ok, 0.05, False, 10.0)
    assert not no.accepted and "quarter cycle" in no.reason


def test_random_phase_is_rejected():
    rng = np.random.default_rng(3)
    w = rng.uniform(-np.pi, np.pi, (60, 60))
    ok = np.ones(w.shape, bool)
    inc = unwrap_increment(w, np.zeros(w.shape), ok, ok, ok, 0.1, True, 1.0)
    assert not inc.accepted and "maximum velocity" in inc.reason


# -- kinematics -----------------------------------------------------------------------------------------
@given(st.lists(st.floats(0, 10), min_size=4, max_size=12, unique=True), st.integers(0, 10_000))
def test_velocity_and_acceleration_weights_equal_polyfit(times, seed):
    t = np.sort(np.array(times))
    if np.ptp(t) < 0.1 or np.min(np.diff(t)) < 1e-3:
        return
    d = np.random.default_rng(seed).normal(0, 1, t.size)
    assert slope_weights(t) @ d == pytest.approx(np.polyfit(t, d, 1)[0], rel=1e-6, abs=1e-6)
    assert acceleration_weights(t) @ d == pytest.approx(2 * np.polyfit(t, d, 2)[0], rel=1e-5, abs=1e-5)


def test_inverse_velocity_forecast_of_fukuzono_law():
    t = np.linspace(2.0, 5.0, 12)
    v = 0.5 * 6.0 / (7.0 - t)  # 1/v linear, zero at t_f = 7 h
    tf, m, r2 = inverse_velocity_forecast(t, v)
    assert tf == pytest.approx(7.0, abs=1e-9) and m == pytest.approx(-1 / 3.0) and r2 == pytest.approx(1.0)
    assert inverse_velocity_forecast(t, np.full(t.size, 0.3)) is None  # no acceleration: no forecast


# -- alarms -------------------------------------------------------------------------------------------------
AREA = AreaEntry(name="a", polygon=((0, 0), (1, 0), (1, 1)), velocity_mm_per_h=(1.0, 2.0, 4.0),
                 acceleration_mm_per_h2=(4.0, 16.0, 64.0), hysteresis=0.2, clear_scans=3)


def test_levels_rise_at_once_and_fall_with_hysteresis():
    s = AlarmState()
    levels, events = [], []
    for v in (0.5, 2.1, 2.1, 1.9, 1.7, 1.5, 1.5, 1.5, float("nan"), 0.1, 0.1, 0.1):
        s, ev = step(s, AREA, v, 0.0)
        levels.append(s.level)
        events.append(ev and ev["event"])
    # 1.9 and 1.7 stay above 0.8 * 2 = 1.6: pre-alarm kept; 1.5 x 3 scans: back to attention
    assert levels == [0, 2, 2, 2, 2, 2, 2, 1, 1, 1, 1, 0]
    assert events[1] == "raised" and events[7] == "lowered" and events[11] == "lowered"


def test_acceleration_counts_along_the_velocity():
    s, ev = step(AlarmState(), AREA, -0.5, -20.0)  # moving toward the radar and speeding up
    assert s.level == 2 and ev["trigger"] == "acceleration"
    s, ev = step(AlarmState(), AREA, -0.5, 20.0)  # slowing down: nothing
    assert s.level == 0 and ev is None
    assert level_of(3.0, (1.0, 2.0, 4.0)) == 2 and level_of(3.0, None) == 0


def test_alarm_csv_and_hook(tmp_path):
    ev = {"time_utc": "2026-05-01T12:00:00Z", "scan": 3, "area": "a", "event": "raised", "level": "alarm",
          "previous_level": "none", "trigger": "velocity", "value": 5.0, "threshold": 4.0,
          "velocity_mm_per_h": 5.0, "acceleration_mm_per_h2": float("nan"), "forecast_failure_utc": None}
    line = csv_line(ev)
    assert len(line.split(",")) == len(csv_header().split(",")) and ",5.0000,4.0000," in line
    out = tmp_path / "got.json"
    assert run_hook(f"{sys.executable} -c 'import sys; open(\"{out}\", \"w\").write(sys.stdin.read())'", ev, 20) is None
    got = json.loads(out.read_text())
    assert got["level"] == "alarm" and got["acceleration_mm_per_h2"] is None
    assert "exit status 3" in run_hook("exit 3", ev, 20)
    assert "timed out" in run_hook("sleep 5", ev, 0.2)


# -- meteo ----------------------------------------------------------------------------------------------------
def test_refractivity_published_values():
    # dry air at 15 C, 1013.25 hPa: N = 77.6 P / T = 272.9 (Smith & Weintraub's dry term)
    assert refractivity_ppm(15.0, 0.0, 1013.25) == pytest.approx(77.6 * 1013.25 / 288.15, rel=1e-12)
    # saturation vapour pressure 23.39 hPa at 20 C (WMO tables): the wet term 3.73e5 e / T^2
    wet = refractivity_ppm(20.0, 100.0, 0.0)
    assert wet * 293.15 ** 2 / 3.73e5 == pytest.approx(23.39, rel=2e-3)


def test_meteo_file_interpolates_and_reads_appended_rows(tmp_path):
    p = tmp_path / "m.csv"
    p.write_text("time_utc,temperature_c,humidity_percent,pressure_hpa,wind\n2026-05-01T06:00:00Z,10,50,850,3\n")
    m = MeteoFile(p)
    t0 = 1777615200.0  # 2026-05-01T06:00:00Z
    assert m.at(t0)["temperature_c"] == 10 and m.at(t0 + 7200) is None
    with open(p, "a") as fh:
        fh.write("2026-05-01T07:00:00Z,14,70,852,1\n2026-05-01T08:0")  # a row being written
    got = m.at(t0 + 900)
    assert got["temperature_c"] == pytest.approx(11.0) and got["humidity_percent"] == pytest.approx(55.0)
    assert got["refractivity_ppm"] == pytest.approx(refractivity_ppm(11.0, 55.0, 850.5))
    bad = tmp_path / "b.csv"
    bad.write_text("time,t\n")
    from sarcli.errors import ProductError

    with pytest.raises(ProductError, match="needs the columns"):
        MeteoFile(bad).at(t0)
