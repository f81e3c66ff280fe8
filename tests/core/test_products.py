"""The product core: atomic writes, provenance, SOURCE_DATE_EPOCH reproducibility, raw/scan schemas."""

from __future__ import annotations

import json
import time

import h5py
import numpy as np
import pytest

from orbit.propagate import Keplerian, kepler_to_state, propagate_j2
from sarcli.errors import ProductError
from sarcli.io.h5common import atomic_h5, dataset, provenance
from sarcli.io.raw import read_raw, write_raw
from sarcli.io.scan import ScanWriter, read_scan, write_scan
from sarcli.model.gbsar import Scan
from sarcli.model.raw import Attitude, Orbit, Radar, RawProduct


def _orbit() -> Orbit:
    """A Radarsat-1-like J2 orbit: 15 ECI state vectors 480 s apart."""
    r0, v0 = kepler_to_state(Keplerian(7_167_000.0, 0.0011, np.radians(98.59), 0.7, 1.3, 2.1))
    t = np.arange(15) * 480.0 - 3360.0
    pos, vel = propagate_j2(r0, v0, t)
    return Orbit(t, pos, vel, "ECI")


def _raw(n_lines=16, n_samples=32, seed=0) -> RawProduct:
    rng = np.random.default_rng(seed)
    shape = (n_lines, n_samples)
    echo = (rng.integers(-8, 8, shape) * 2 + 1) + 1j * (rng.integers(-8, 8, shape) * 2 + 1)
    return RawProduct(
        echo=echo.astype(np.complex64), azimuth_time=np.arange(n_lines) / 1256.98,
        epoch_utc="2002-06-16T15:41:00.000000Z",
        radar=Radar(5.3e9, 0.0565646, 1256.98, 32.317e6, -0.72135e12, 41.75e-6, 6.5956e-3, 988647.46, 4),
        agc_db=np.full(n_lines, 5.0, np.float32), replica=np.ones(8, np.complex64),
        orbit=_orbit(),
        attitude=Attitude(np.array([0.0, 1.0]), np.array([1e-4, 2e-4]), np.array([0.5, 0.5]), np.zeros(2)),
        truth={"scene_toml": "[scene]\n", "doppler_centroid_hz": np.zeros(n_samples)},
    )


def test_raw_round_trip(tmp_path):
    p = _raw()
    write_raw(tmp_path / "r.h5", p, parameters={"k": 1}, compression="gzip")
    q = read_raw(tmp_path / "r.h5")
    np.testing.assert_array_equal(q.echo, p.echo)
    np.testing.assert_array_equal(q.azimuth_time, p.azimuth_time)
    assert q.radar == p.radar
    np.testing.assert_array_equal(q.orbit.position, p.orbit.position)
    assert q.orbit.frame == "ECI"
    np.testing.assert_array_equal(q.attitude.pitch, p.attitude.pitch)
    np.testing.assert_array_equal(q.agc_db, p.agc_db)
    assert q.truth["scene_toml"] == "[scene]\n"
    with h5py.File(tmp_path / "r.h5") as f:
        assert f["echo"].chunks is not None
        assert f["azimuth_time"].attrs["units"] == "seconds since 2002-06-16T15:41:00.000000"  # CF, UTC
        prov = provenance(f)
    assert prov["product_type"] == "raw" and prov["parameters"] == {"k": 1}


def test_source_date_epoch_gives_byte_identical_files(tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1024243200")
    p = _raw()
    write_raw(tmp_path / "a.h5", p)
    time.sleep(1.1)  # object timestamps would differ across a second boundary
    write_raw(tmp_path / "b.h5", p)
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()
    with h5py.File(tmp_path / "a.h5") as f:
        assert f.attrs["created_utc"] == "2002-06-16T16:00:00.000000Z"


def test_atomic_write_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "x.h5"
    with pytest.raises(RuntimeError):
        with atomic_h5(target, "raw", "1") as f:
            dataset(f, "a", np.zeros(3))
            raise RuntimeError("crash mid-write")
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_keeps_old_product_on_failure(tmp_path):
    write_raw(tmp_path / "r.h5", _raw(seed=1))
    before = (tmp_path / "r.h5").read_bytes()
    bad = _raw()
    bad.azimuth_time = bad.azimuth_time[::-1].copy()
    with pytest.raises(ProductError, match="azimuth_time must increase"):
        write_raw(tmp_path / "r.h5", bad)
    assert (tmp_path / "r.h5").read_bytes() == before


@pytest.mark.parametrize("damage, msg", [
    (lambda f: f.__delitem__("echo"), "missing 'echo'"),
    (lambda f: f["radar"].attrs.__delitem__("prf_hz"), "radar attribute 'prf_hz' missing"),
    (lambda f: f.attrs.__setitem__("product_type", "slc"), "is a 'slc' product, expected raw"),
    (lambda f: f.attrs.__setitem__("schema_version", "9"), "schema version 9 is not supported"),
    (lambda f: f["orbit"].attrs.__setitem__("frame", "GALACTIC"), "orbit: frame must be one of ECI"),
])
def test_malformed_raw_refused_in_one_line(tmp_path, damage, msg):
    path = tmp_path / "r.h5"
    write_raw(path, _raw())
    with h5py.File(path, "r+") as f:
        damage(f)
    with pytest.raises(ProductError, match=msg) as e:
        read_raw(path)
    assert "\n" not in str(e.value)


def test_nan_echo_refused(tmp_path):
    p = _raw()
    path = tmp_path / "r.h5"
    write_raw(path, p)
    with h5py.File(path, "r+") as f:
        f["echo"][0, 0] = np.nan
    with pytest.raises(ProductError, match="NaN"):
        read_raw(path)


def test_not_hdf5_refused(tmp_path):
    path = tmp_path / "r.h5"
    path.write_bytes(b"CEOS" * 100)
    with pytest.raises(ProductError, match="not a readable HDF5"):
        read_raw(path)


def _scan(n_stops=5, n_freq=11) -> Scan:
    rng = np.random.default_rng(3)
    s21 = (rng.normal(size=(2, n_stops, n_freq)) + 1j * rng.normal(size=(2, n_stops, n_freq))).astype(np.complex64)
    return Scan(s21=s21, frequency=np.linspace(5.2e9, 5.4e9, n_freq), rail_position=np.arange(n_stops) * 0.05,
                rail_height=np.zeros(n_stops), polarizations=("VV", "HH"), epoch_utc="2026-11-22T00:00:00Z",
                instrument={"if_bandwidth_hz": 1000.0, "vna_idn": "HEWLETT PACKARD,8753ES,X,7.74"})


def test_scan_round_trip(tmp_path):
    s = _scan()
    write_scan(tmp_path / "s.h5", s)
    q = read_scan(tmp_path / "s.h5")
    np.testing.assert_array_equal(q.s21, s.s21)
    assert q.polarizations == ("VV", "HH")
    assert q.instrument["vna_idn"].startswith("HEWLETT")
    np.testing.assert_array_equal(q.pol("HH"), s.s21[1])


def test_scan_writer_keeps_every_completed_stop(tmp_path):
    s = _scan()
    path = tmp_path / "acq.h5"
    w = ScanWriter.create(path, s, n_planned=5)
    for k in range(3):
        w.append(s.s21[:, k], s.rail_position[k], 0.0, float(k))
    # simulate a crash: the file is not finished, the handle dies
    w.f.close()
    q = read_scan(path)
    assert q.n_stops == 3 and q.status == "interrupted" and q.n_planned == 5
    np.testing.assert_array_equal(q.s21, s.s21[:, :3])
    w = ScanWriter.resume(path)
    for k in range(3, 5):
        w.append(s.s21[:, k], s.rail_position[k], 0.0, float(k))
    w.finish()
    q = read_scan(path)
    assert q.status == "complete"
    np.testing.assert_array_equal(q.s21, s.s21)
    np.testing.assert_array_equal(q.rail_position, s.rail_position)


def test_provenance_inputs_hash(tmp_path):
    src = tmp_path / "in.bin"
    src.write_bytes(b"abc")
    with atomic_h5(tmp_path / "o.h5", "test", "1", inputs=[src]) as f:
        dataset(f, "x", np.zeros(1))
    with h5py.File(tmp_path / "o.h5") as f:
        inputs = json.loads(f.attrs["inputs"])
    assert inputs == [{"path": "in.bin",
                       "sha256": "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"}]


def test_products_get_the_usual_file_mode(tmp_path):
    import os
    import stat

    write_raw(tmp_path / "r.h5", _raw())
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE((tmp_path / "r.h5").stat().st_mode) == 0o666 & ~mask


def test_extra_root_attributes_round_trip(tmp_path):
    p = _raw()
    p.extra_attrs = {"ceos_beam": "F1", "published_fdc_hz": -6900.0}
    write_raw(tmp_path / "r.h5", p)
    assert read_raw(tmp_path / "r.h5").extra_attrs == {"ceos_beam": "F1", "published_fdc_hz": -6900.0}


def test_calibrated_undoes_agc_per_line():
    p = _raw(n_lines=4)
    p.agc_db = np.array([0.0, 6.0, 20.0, 3.0], np.float32)
    q = p.calibrated()
    np.testing.assert_allclose(q.echo[2], p.echo[2] * 10.0, rtol=1e-6)
    np.testing.assert_allclose(q.echo[1], p.echo[1] * 10 ** (6 / 20), rtol=1e-6)
    assert q.agc_db is None and p.agc_db is not None  # the original is untouched


def test_images_get_the_usual_file_mode_too(tmp_path):
    import os
    import stat

    from sarcli.io.images import write_quicklook

    write_quicklook(tmp_path / "q.png", np.ones((8, 8), np.complex64))
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE((tmp_path / "q.png").stat().st_mode) == 0o666 & ~mask
    assert [p.name for p in tmp_path.iterdir()] == ["q.png"]  # no temporary left behind
