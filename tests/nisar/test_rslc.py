"""NISAR RSLC out and in: a simulated SLC written in the RSLC layout, read back (sarcli's reader and
plain h5py), its targets found by the corner-reflector analysis; an RSLC in ISCE3's older variants;
damaged files."""

from __future__ import annotations

import dataclasses

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sarcli.errors import ConfigError, ProductError, SarcliError
from sarcli.io.nisar.rslc import read_rslc, rslc_contents, sniff_rslc

ROOT = "science/LSAR/RSLC"


def test_round_trip(sim_slc, sim_rslc):
    from orbit.statevectors import StateVectors

    s = read_rslc(sim_rslc)
    assert sniff_rslc(sim_rslc)
    np.testing.assert_array_equal(s.image, sim_slc.image)
    np.testing.assert_array_equal(s.azimuth_time, sim_slc.azimuth_time)  # the epoch is a whole second
    np.testing.assert_array_equal(s.slant_range, sim_slc.slant_range)
    assert s.epoch_utc == "2002-06-16T15:41:00.000000Z" and s.look_side == "right"
    assert vars(s.radar) == vars(sim_slc.radar)
    assert (s.first_full_line, s.last_full_line) == (sim_slc.first_full_line, sim_slc.last_full_line)
    assert s.parameters["azimuth_bandwidth_hz"] == 900.0 and s.parameters["nisar"]["polarization"] == "HH"
    ecef = StateVectors.from_record(sim_slc.orbit, sim_slc.epoch_utc).to_ecef()
    assert s.orbit.frame == "ECEF"
    np.testing.assert_allclose(s.orbit.position, ecef.position, atol=1e-6)
    np.testing.assert_allclose(s.attitude.pitch, sim_slc.attitude.pitch, atol=1e-11)
    np.testing.assert_allclose(s.attitude.yaw, sim_slc.attitude.yaw, atol=1e-11)
    np.testing.assert_allclose(s.doppler.fdc_hz, sim_slc.doppler.fdc_hz[0, 0], rtol=1e-12)  # constant model


def test_layout_as_isce3_reads_it(sim_rslc):
    with h5py.File(sim_rslc, "r") as f:
        ident = f["science/LSAR/identification"]
        for k in ("productType", "lookDirection", "zeroDopplerStartTime", "zeroDopplerEndTime", "listOfFrequencies",
                  "diagnosticModeFlag", "orbitPassDirection", "boundingPolygon", "missionId"):
            assert k in ident, k
        assert ident["productType"][()] == b"RSLC" and ident["lookDirection"][()] == b"Right"
        assert ident["radarBand"][()] == b"C"  # a C-band simulation, under LSAR
        assert f[f"{ROOT}/swaths/zeroDopplerTime"].attrs["units"] == b"seconds since 2002-06-16T15:41:00"
        fg = f[f"{ROOT}/swaths/frequencyA"]
        for k in ("slantRange", "slantRangeSpacing", "processedCenterFrequency", "acquiredCenterFrequency",
                  "acquiredRangeBandwidth", "processedRangeBandwidth", "processedAzimuthBandwidth",
                  "nominalAcquisitionPRF", "sceneCenterAlongTrackSpacing", "sceneCenterGroundRangeSpacing",
                  "numberOfSubSwaths", "validSamplesSubSwath1", "listOfPolarizations", "HH"):
            assert k in fg, k
        assert fg["HH"].dtype == np.complex64 and fg["listOfPolarizations"][()].tolist() == [b"HH"]
        assert f[f"{ROOT}/swaths/zeroDopplerTimeSpacing"][()] > 0
        par = f[f"{ROOT}/metadata/processingInformation/parameters"]
        lut = par["frequencyA/dopplerCentroid"]
        assert lut.shape == (par["frequencyA/zeroDopplerTime"].size, par["frequencyA/slantRange"].size)
        w = par["rangeChirpWeighting"]
        assert w.shape == (256,) and w.attrs["window_name"] == b"Kaiser" and w.attrs["window_shape"] == 2.5
        q = f[f"{ROOT}/metadata/attitude/quaternions"][()]
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
        assert f[f"{ROOT}/metadata/orbit/interpMethod"][()] == b"Hermite"
        assert f.attrs["product_type"] == "nisar_rslc"  # sarcli's provenance on the root
        assert "processingInformation/algorithms/softwareVersion" in f[f"{ROOT}/metadata"]


def test_geolocation_grid_places_the_targets(sim_slc, sim_rslc):
    """The cube's lon/lat, interpolated (trilinear) at a target's zero-Doppler time, range and height,
    is the simulator's truth position (grid spacing ~500 m: linear interpolation of the smooth
    geolocation is good to a few cm)."""
    from scipy.interpolate import RegularGridInterpolator

    with h5py.File(sim_rslc, "r") as f:
        g = f[f"{ROOT}/metadata/geolocationGrid"]
        axes = (g["heightAboveEllipsoid"][()], g["zeroDopplerTime"][()], g["slantRange"][()])
        lon = RegularGridInterpolator(axes, g["coordinateX"][()])
        lat = RegularGridInterpolator(axes, g["coordinateY"][()])
        inc = g["incidenceAngle"][()]
    assert 25 < inc.min() and inc.max() < 45  # a 33.5 deg look from 800 km
    for t in sim_slc.truth["targets"]:
        x = (t["height_m"], t["zero_doppler_time_s"], t["closest_range_m"])
        assert float(lon(x)) == pytest.approx(t["lon_deg"], abs=1e-6)
        assert float(lat(x)) == pytest.approx(t["lat_deg"], abs=1e-6)


def test_every_target_found_by_the_corner_reflector_analysis(sim_slc, sim_rslc, sim_reflectors_csv):
    """Offsets below 0.05 pixel and IRWs within 2 % of the window theory (processed bands inside the
    illuminated ones, noise-free: the residuals are the focuser's, measured 0.016 px and 0.8 %)."""
    from sarcli.calibration.analysis import analyse
    from sarcli.calibration.reflectors import parse_reflectors

    a = analyse(read_rslc(sim_rslc), parse_reflectors(sim_reflectors_csv))
    assert [r.id for r in a.results] == ["T0", "T1", "T2"] and not a.outside
    assert a.range_theory.window == "kaiser:2.5" and a.azimuth_theory.bandwidth_hz == 900.0
    for r in a.results:
        assert abs(r.range_offset_px) < 0.05 and abs(r.azimuth_offset_px) < 0.05, r
        assert r.range_irw_m == pytest.approx(r.range_irw_theory_m, rel=0.02)
        assert r.azimuth_irw_m == pytest.approx(r.azimuth_irw_theory_m, rel=0.02)
    # the SLC itself gives the same answer (the RSLC round trip is exact)
    b = analyse(sim_slc, parse_reflectors(sim_reflectors_csv))
    assert [x.record() for x in b.results] == [x.record() for x in a.results]


def test_isce3_variant_rslc(tmp_path):
    from synth import orbit_ecef, write_isce3_rslc

    t = 3600.0 + np.arange(40) / 1500.0
    r = 880e3 + 6.25 * np.arange(30)
    t_orb = np.arange(3480.0, 3730.0, 10.0)
    pos, vel = orbit_ecef(t_orb)
    rng = np.random.default_rng(1)
    img = (rng.normal(size=(40, 30)) + 1j * rng.normal(size=(40, 30))).astype(np.complex64) * 100
    p = tmp_path / "isce3.h5"
    write_isce3_rslc(p, img, t, r, t_orb, pos, vel)
    c = rslc_contents(p)
    assert c.frequencies == {"A": ["VV"]} and c.shape == (40, 30) and not c.written_by_sarcli
    s = read_rslc(p)
    np.testing.assert_allclose(s.image, img, rtol=1e-3)  # float16 pairs: 11-bit mantissa
    np.testing.assert_allclose(s.azimuth_time, t)
    assert s.look_side == "left" and s.epoch_utc == "2020-03-01T00:00:00.000000Z"
    assert s.parameters["nisar"]["processed_range_bandwidth_hz"] == 20e6
    # LUT [[10, 20], [30, 40]] on (t0, t_end) x (r0, r_end): linear in range at each time
    np.testing.assert_allclose(s.doppler.fdc_hz[0], 10.0 + 10.0 * (r - r[0]) / (r[-1] - r[0]))
    assert np.all(np.isnan(s.doppler.fr_hz_per_s)) and np.isnan(s.radar.chirp_rate_hz_per_s)
    with pytest.raises(ConfigError, match="not HH"):
        read_rslc(p, polarization="HH")


def test_refusals(sim_slc, tmp_path):
    from sarcli.model.raw import Orbit
    from sarcli.workflows.export import write_format

    local = dataclasses.replace(sim_slc, orbit=Orbit(np.array([0.0, 1.0]), np.zeros((2, 3)), np.ones((2, 3)), "LOCAL"))
    with pytest.raises(ProductError, match="Earth orbit"):
        write_format(local, tmp_path / "x.h5", "nisar-rslc")
    with pytest.raises(ConfigError, match="polarization"):
        write_format(sim_slc, tmp_path / "x.h5", "nisar-rslc", {"polarization": "XY"})
    with pytest.raises(ConfigError, match="unknown export format"):
        write_format(sim_slc, tmp_path / "x.h5", "geojpeg")
    assert not (tmp_path / "x.h5").exists()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_fuzzed_rslc_reads_or_fails_in_one_line(sim_rslc, tmp_path, data):
    raw = bytearray(sim_rslc.read_bytes())
    if data.draw(st.booleans()):
        raw = raw[:data.draw(st.integers(0, len(raw) - 1))]
    else:
        for _ in range(data.draw(st.integers(1, 8))):
            k = data.draw(st.integers(0, len(raw) - 1))
            raw[k] ^= data.draw(st.integers(1, 255))
    p = tmp_path / "fuzz.h5"
    p.write_bytes(bytes(raw))
    try:
        s = read_rslc(p)
    except SarcliError as e:
        assert str(e) and "\n" not in str(e)
    else:
        assert s.image.ndim == 2


def test_a_member_name_that_is_not_utf8_is_no_frequency_group(sim_rslc, tmp_path):
    """A damaged name (h5py lists it as bytes; the fuzz test above found it) names no member of the
    layout: the reader skips it and reads the file, or says in one line what is missing."""
    import shutil

    import h5py

    p = tmp_path / "renamed.h5"
    shutil.copy(sim_rslc, p)
    with h5py.File(p, "r+") as f:
        sw = f["science/LSAR/RSLC/swaths"]
        sw.create_group(b"frequency\xff")
    assert read_rslc(p).image.ndim == 2
    with h5py.File(p, "r+") as f:
        sw = f["science/LSAR/RSLC/swaths"]
        sw.move("frequencyA", b"frequencyA\xff")
    with pytest.raises(SarcliError) as e:
        read_rslc(p)
    assert "\n" not in str(e.value)
