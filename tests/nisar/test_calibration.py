"""Corner-reflector CSV files, survey selection and plate motion, the theoretical IRW of windows, the
propagation corrections, and the corner-reflector workflow (report, records, plots)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import quad

from sarcli.calibration.irf import band_grid, window_irw_factor
from sarcli.calibration.predict import (
    ionosphere_slant_delay_per_tecu_m,
    troposphere_slant_delay_m,
    zenith_hydrostatic_delay_m,
)
from sarcli.calibration.reflectors import CornerReflector, parse_reflectors, position_at, select
from sarcli.errors import FormatError, ProductError

NISAR_HEADER = ("Corner reflector ID,Latitude (deg),Longitude (deg),Height above ellipsoid (m),Azimuth (deg),"
                "Tilt / Elevation (deg),Side length (m),Survey Date,Validity,Velocity East (m/s),Velocity North (m/s),"
                "Velocity Up (m/s)")


def _csv(tmp_path, text, name="cr.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_nisar_csv_history_validity_and_comments(tmp_path):
    p = _csv(tmp_path, NISAR_HEADER + """
N01K,  35.59190388,  -98.93222547,  480.0800,  359.25, 14.26, 2.8000, 2021-06-04T00:00:00.0000, 7, -4.7e-10, -1.3e-10, 0
N01K,  35.59190457,  -98.93222591,  480.1540,  359.50, 13.68, 2.8000, 2022-09-28T00:00:00.0000, 7, -4.7e-10, -1.3e-10, 0
# a comment line
N02K,  35.58689743,  -99.26711946,  491.0526,  180.00, 12.55, 2.8000, 2021-12-17T00:00:00.0000,  0, 0, 0, 0
N03K,  35.58880508,  -98.93568049,  479.2867,  178.50, 14.33, 2.8000, 2021-06-04T00:00:00.0000,  2, 0, 0, 0
N04K,  35.58365554,  -99.26716650,  491.4040,  359.00, 16.60, 2.8000, 2023-12-17T00:00:00.0000,  7, 0, 0, 0
""")
    crs = parse_reflectors(p)
    assert [c.id for c in crs] == ["N01K", "N01K", "N02K", "N03K", "N04K"]
    assert crs[0].survey_utc == "2021-06-04T00:00:00.000000Z" and crs[0].line == 2
    kept, notes = select(crs, "2022-10-01T00:00:00Z")
    assert [(c.id, c.height_m) for c in kept] == [("N01K", 480.154), ("N03K", 479.2867)]
    assert any("N02K" in n and "validity 0" in n for n in notes)
    assert any("N04K" in n and "after the acquisition" in n for n in notes)
    kept, notes = select(crs, "2022-01-01T00:00:00Z", need=4)  # geometry
    assert [c.id for c in kept] == ["N01K"] and kept[0].height_m == 480.08  # the 2021 survey
    assert any("N03K" in n and "lacks flag 4" in n for n in notes)


def test_uavsar_csv_quoted_header(tmp_path):
    p = _csv(tmp_path, '"Corner reflector ID","Latitude (deg)","Longitude (deg)","Height above ellipsoid (m)",'
                       '"Azimuth (deg)","Tilt / Elevation angle (deg)","Side length (m)"\n'
                       "CR1,-9.71311741457592,-68.1728216904995,-2.06853152580805E-05,180.0,0.0,2.5\n")
    (cr,) = parse_reflectors(p)
    assert cr.id == "CR1" and cr.side_length_m == 2.5 and cr.survey_utc is None and cr.validity == 7
    assert cr.height_m == pytest.approx(-2.06853152580805e-05)
    assert position_at(cr, "2006-07-20T03:15:55Z")[1] == 0.0


@pytest.mark.parametrize("header", [
    "ID,lat,lon,hae,az,el,side",
    "id, latitude_deg, longitude_deg, height_m, azimuth_deg, tilt_deg, side_length_m",
    "# reflectors of the site\nID,Lat (deg),Lon (deg),Height (m),Az,Tilt,Side\nname,deg,deg,m,deg,deg,m",
])
def test_any_header_rows_before_the_data_are_skipped(tmp_path, header):
    """docs/nisar.md: header rows are skipped, whatever their words (a row whose six numeric columns hold no
    number, before the first reflector); a bad number in a reflector's row is still refused."""
    (cr,) = parse_reflectors(_csv(tmp_path, header + "\nCR1,-9.7,-68.2,120.5,180.0,0.0,2.5\n"))
    assert (cr.id, cr.latitude_deg, cr.height_m, cr.side_length_m) == ("CR1", -9.7, 120.5, 2.5)
    with pytest.raises(FormatError, match="line 3: latitude_deg 'x' is not a number"):
        parse_reflectors(_csv(tmp_path, "ID,lat,lon,hae,az,el,side\nCR1,1,2,3,4,5,6\nCR2,x,2,3,4,5,6\n"))
    with pytest.raises(FormatError, match="line 3: latitude_deg 'lat' is not"):  # a header after the data: bad
        parse_reflectors(_csv(tmp_path, "CR1,1,2,3,4,5,6\nCR2,1,2,3,4,5,6\nID,lat,lon,hae,az,el,side\n"))


@pytest.mark.parametrize("line, message", [
    ("CR1,1,2,3,4,5", "6 columns"),
    ("CR1,north,2,3,4,5,6", "latitude_deg 'north' is not a number"),
    ("CR1,91,2,3,4,5,6", "outside [-90, 90]"),
    ("CR1,1,2,3,4,5,0", "side length"),
    ("CR1,1,2,3,4,5,6,yesterday,7,0,0,0", "survey date"),
    ("CR1,1,2,3,4,5,6,2020-01-01,9,0,0,0", "validity 9"),
    ("CR1,1,2,3,4,5,6,2020-01-01,7,0,nan,0", "not a finite number"),
    (",1,2,3,4,5,6", "empty corner reflector ID"),
])
def test_bad_rows_one_line(tmp_path, line, message):
    p = _csv(tmp_path, NISAR_HEADER + "\n" + line + "\n")
    with pytest.raises(FormatError) as e:
        parse_reflectors(p)
    assert message in str(e.value) and "line 2" in str(e.value) and "\n" not in str(e.value)


def test_empty_missing_and_binary_files(tmp_path):
    with pytest.raises(FormatError, match="no corner reflector"):
        parse_reflectors(_csv(tmp_path, NISAR_HEADER + "\n# nothing\n"))
    with pytest.raises(ProductError, match="no such file"):
        parse_reflectors(tmp_path / "absent.csv")
    b = tmp_path / "bin.csv"
    b.write_bytes(b"\xff\xfe\x00\x81")
    with pytest.raises(FormatError, match="UTF-8"):
        parse_reflectors(b)


def test_plate_motion_moves_the_surveyed_point(tmp_path):
    """1 cm/yr east and 2 cm/yr up over ten years: the ECEF displacement is 0.1 m east + 0.2 m up
    (independently: pyproj geodetic heights and the east direction from a 1e-7 deg longitude step)."""
    from orbit.geodetic import ecef_to_geodetic, geodetic_to_ecef

    yr = 365.25 * 86400.0
    cr = CornerReflector("X", 35.5, -98.9, 480.0, 0, 0, 2.8, "2010-01-01T00:00:00.000000Z", 7,
                         (0.01 / yr, 0.0, 0.02 / yr))
    p, dt = position_at(cr, "2020-01-01T00:00:00Z")
    assert dt == pytest.approx((3652) * 86400.0)  # 2010-01-01 .. 2020-01-01: 3652 days
    p0 = np.asarray(geodetic_to_ecef(35.5, -98.9, 480.0))
    east = np.asarray(geodetic_to_ecef(35.5, -98.9 + 1e-7, 480.0)) - p0
    east /= np.linalg.norm(east)
    s = dt / yr
    assert np.dot(p - p0, east) == pytest.approx(0.01 * s, abs=1e-6)
    assert float(ecef_to_geodetic(p)[2]) - 480.0 == pytest.approx(0.02 * s, abs=1e-6)


def test_window_irw_factors_against_published_values():
    """rect: half-power width of sinc^2, 0.8858929 (2 x 0.44294647); Hamming 0.54: 1.30 bins (Harris 1978,
    table 1); Kaiser beta 2.5: the half-power point of int I0(b sqrt(1 - 4u^2)) cos(2 pi u x) du
    found by scipy quad + brentq (an independent quadrature)."""
    from scipy.optimize import brentq

    from sarcli.calibration.irf import window_values

    u = band_grid()
    assert window_irw_factor(window_values("rect", u)) == pytest.approx(2 * 0.44294647, abs=1e-6)
    assert window_irw_factor(window_values("hamming:0.54", u)) == pytest.approx(1.30, abs=0.005)

    def h(x):
        return quad(lambda v: np.i0(2.5 * math.sqrt(max(0.0, 1 - 4 * v * v))) * math.cos(2 * math.pi * v * x),
                    -0.5, 0.5, limit=200)[0]

    half = brentq(lambda x: h(x) ** 2 / h(0) ** 2 - 0.5, 0.3, 0.7, xtol=1e-10)
    assert window_irw_factor(window_values("kaiser:2.5", u)) == pytest.approx(2 * half, abs=2e-6)


def test_propagation_corrections_against_published_numbers():
    # Saastamoinen ZHD at the standard sea-level pressure 1013.25 hPa, 45 deg latitude: 2.3070 m
    assert zenith_hydrostatic_delay_m(45.0, 0.0) == pytest.approx(2.2768 * 1.01325, abs=1e-4)
    # standard atmosphere at 1000 m: 898.7 hPa (ISO 2533) -> 2.0462 m at 45 deg
    assert zenith_hydrostatic_delay_m(45.0, 1000.0) == pytest.approx(0.0022768 * 898.75 / (1 - 0.00028), abs=2e-4)
    # slant = zenith / cos(incidence): 40 deg, ZWD 0.1 m
    assert troposphere_slant_delay_m(45.0, 0.0, 40.0, 0.1) == pytest.approx((2.3070 + 0.1) / math.cos(
        math.radians(40)), abs=2e-4)
    # ionosphere: 40.3e16 / f^2 per TECU vertically (0.2499 m at 1.27 GHz); at nadir the slant factor is 1
    assert ionosphere_slant_delay_per_tecu_m(1.27e9, 0.0) == pytest.approx(40.3e16 / 1.27e9**2, rel=1e-12)
    assert ionosphere_slant_delay_per_tecu_m(5.405e9, 30.0) < 0.02  # C-band: centimetres


@pytest.fixture(scope="module")
def cr_report(sim_rslc, sim_reflectors_csv, tmp_path_factory):
    from sarcli.config import from_mapping
    from sarcli.workflows.corner_reflectors import Config, run

    plots = tmp_path_factory.mktemp("plots")
    cfg = from_mapping(Config, {"slc": str(sim_rslc), "reflectors": str(sim_reflectors_csv), "plots": str(plots)})
    return run(cfg), plots


def test_workflow_records_have_exactly_the_keys(cr_report):
    from sarcli.calibration.analysis import RECORD_KEYS

    report, plots = cr_report
    recs = report.records()
    assert [r["id"] for r in recs] == ["T0", "T1", "T2"]
    assert all(tuple(r) == RECORD_KEYS for r in recs)
    json.dumps(recs)
    json.dumps(report.to_dict())
    assert report.theory["range_window"] == "kaiser:2.5"
    assert sorted(p.name for p in plots.iterdir()) == ["cr_T0.png", "cr_T1.png", "cr_T2.png"]
    assert all((plots / n).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for n in ("cr_T0.png",))
    text = "\n".join(report.lines())
    assert "T1: offset rg" in text and "troposphere" in text and "ionosphere" in text


def test_workflow_refusals(sim_rslc, sim_reflectors_csv, tmp_path):
    from sarcli.config import from_mapping
    from sarcli.errors import ConfigError
    from sarcli.workflows.corner_reflectors import Config, run

    with pytest.raises(ConfigError, match="search_px"):
        from_mapping(Config, {"slc": "a", "reflectors": "b", "search_px": 0})
    (tmp_path / "a_file").write_text("")
    with pytest.raises(ConfigError, match="plot folder .*a_file is not a folder"):
        run(Config(sim_rslc, sim_reflectors_csv, plots=tmp_path / "a_file"))
    with pytest.raises(ConfigError, match="has polarizations HH, not VV"):
        run(Config(sim_rslc, sim_reflectors_csv, polarization="VV"))


def test_quality_cli_with_corner_reflectors_and_on_an_rslc(cli, sim_rslc, sim_reflectors_csv, tmp_path):
    """``sarcli quality --corner-reflectors --json``: one object per reflector with exactly the documented keys
    (same values as the workflow) and one IRF picture per reflector with ``--plots``."""
    from sarcli.calibration.analysis import RECORD_KEYS
    from sarcli.workflows.corner_reflectors import Config, run

    r = cli("quality", sim_rslc, "--corner-reflectors", sim_reflectors_csv, "--json")
    assert r.exit_code == 0, r.stderr
    recs = json.loads(r.stdout)
    assert [tuple(x) for x in recs] == [RECORD_KEYS] * 3
    assert recs == json.loads(json.dumps(run(Config(sim_rslc, sim_reflectors_csv)).records()))
    plots = tmp_path / "plots"  # created by the command
    r = cli("quality", sim_rslc, "--corner-reflectors", sim_reflectors_csv, "--plots", plots)
    assert r.exit_code == 0 and sorted(p.name for p in plots.iterdir()) == ["cr_T0.png", "cr_T1.png", "cr_T2.png"]
    r = cli("quality", sim_rslc, "--plots", plots)
    assert r.exit_code == 2 and r.stderr.strip() == "sarcli: error: --plots goes with --corner-reflectors"
