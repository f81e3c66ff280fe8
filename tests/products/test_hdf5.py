"""HDF5 products as netCDF/xarray, ISCE3-style orbit readers and h5py see them: every group opens with
``xarray.open_dataset(engine="h5netcdf")`` without phony dimensions, times decode to datetime64, every
dataset has units and a description; the ECEF orbit against astropy's Greenwich sidereal time; the SLC
geolocation grid and bounding polygon against the simulator's truth; echo compression where it pays."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import xarray as xr

from sarcli.io.h5common import unlabelled
from sarcli.io.raw import read_raw, write_raw
from tests.core.test_products import _raw


def _groups(path) -> list[str]:
    out = ["/"]
    with h5py.File(path) as f:
        f.visititems(lambda n, o: out.append("/" + n) if isinstance(o, h5py.Group) else None)
    return out


def assert_self_describing(path, skip=("/auxiliary",)) -> dict[str, xr.Dataset]:
    """Conventions, units, descriptions and dimension scales on every dataset; every group opens in xarray."""
    with h5py.File(path) as f:
        assert f.attrs["Conventions"] == "CF-1.8"
        assert unlabelled(f, skip) == []
    out = {}
    for g in _groups(path):
        if any(g.startswith(s) for s in skip):
            continue
        ds = xr.open_dataset(path, engine="h5netcdf", group=g)  # raises on a phony dimension
        assert not any(d.startswith("phony_dim") for d in ds.sizes), (path, g)
        out[g] = ds.load()
        ds.close()
    return out


def _epoch64(epoch: str) -> np.datetime64:
    return np.datetime64(epoch.rstrip("Z"), "ns")


def test_raw_is_self_describing_and_time_aware(tmp_path):
    p = _raw(n_lines=20, n_samples=24)
    write_raw(tmp_path / "r.h5", p)
    groups = assert_self_describing(tmp_path / "r.h5")
    root = groups["/"]
    assert root.echo.dims == ("azimuth_time", "slant_range")
    # CF time: epoch + seconds, to the nanosecond of datetime64[ns]
    want = _epoch64(p.epoch_utc) + (p.azimuth_time * 1e9).round().astype("timedelta64[ns]")
    assert np.abs(root.azimuth_time.values - want).max() <= np.timedelta64(1, "ns")
    c, r = 299792458.0, p.radar
    tau = r.window_start_s + np.arange(24) / r.range_sampling_rate_hz  # two-way delay of each sample
    np.testing.assert_allclose(root.slant_range.values, c / 2 * tau)
    assert groups["/orbit"].position.dims == ("time", "xyz") and groups["/attitude"].pitch.dims == ("time",)
    assert groups["/radar"].agc_db.dims == ("azimuth_time",)
    assert groups["/truth"].doppler_centroid_hz.attrs["units"] == "Hz"


def test_orbit_ecef_matches_astropy_sidereal_time(tmp_path):
    """ECI of date -> ECEF is a rotation about z by GMST: same z, same radius, longitude shifted by GMST."""
    from astropy.time import Time

    p = _raw()
    write_raw(tmp_path / "r.h5", p)
    with h5py.File(tmp_path / "r.h5") as f:
        g = f["orbit_ecef"]
        t, pos = g["time"][()], g["position"][()]
        assert g["time"].attrs["units"] == "seconds since 2002-06-16T15:41:00.000000"
        assert g["orbitType"][()] == b"Custom" and g["interpMethod"][()] == b"Hermite"
    eci = p.orbit.position
    np.testing.assert_allclose(pos[:, 2], eci[:, 2], rtol=0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(pos, axis=1), np.linalg.norm(eci, axis=1), rtol=1e-14)
    shift = np.arctan2(eci[:, 1], eci[:, 0]) - np.arctan2(pos[:, 1], pos[:, 0])
    when = Time("2002-06-16T15:41:00", scale="utc") + t / 86400.0
    gmst = when.sidereal_time("mean", "greenwich", model="IAU1982").rad
    # IAU-1982 in UT1 vs UTC here: |UT1 - UTC| < 0.9 s turns the Earth by < 6.6e-5 rad
    assert np.max(np.abs(np.angle(np.exp(1j * (shift - gmst))))) < 7e-5


def test_echo_compression_where_it_pays(tmp_path):
    q = _raw(n_lines=64, n_samples=256)  # odd integer levels of a 4-bit quantizer
    rng = np.random.default_rng(0)
    f = _raw(n_lines=64, n_samples=256)
    f.echo = (rng.normal(size=f.echo.shape) + 1j * rng.normal(size=f.echo.shape)).astype(np.complex64)
    for name, p, mode, want in (("q", q, "auto", "gzip"), ("f", f, "auto", None), ("l", q, "lzf", "lzf"),
                                ("n", q, "none", None)):
        write_raw(tmp_path / f"{name}.h5", p, compression=mode)
        with h5py.File(tmp_path / f"{name}.h5") as h:
            e = h["echo"]
            assert e.compression == want, name
            assert e.shuffle == (want is not None)
            assert e.chunks[1] == 256  # whole lines: the readers read line blocks across the swath
        np.testing.assert_array_equal(read_raw(tmp_path / f"{name}.h5").echo, p.echo)


def test_ati_and_gbsar_products_are_self_describing(cli, tmp_path):
    from sarcli.io.ati_product import write_ati
    from tests.gbsar.test_cli import _scan

    rng = np.random.default_rng(2)
    img = (rng.normal(size=(8, 6)) + 1j).astype(np.complex64)
    write_ati(tmp_path / "ati.h5", epoch_utc="2020-01-01T00:00:00Z", t_ref_s=0.5, look_side="right",
              azimuth_time=np.arange(8) * 0.1, slant_range=1e4 + np.arange(6.0), image_before=img,
              ati_phase=np.angle(img).astype(np.float32), movers=[{"id": 0, "vx_mps": 1.0}], detection={},
              image_after=img)
    g = assert_self_describing(tmp_path / "ati.h5")
    assert g["/"].azimuth_time.values[1] == np.datetime64("2020-01-01T00:00:00.1", "ns")
    with h5py.File(tmp_path / "ati.h5") as f:
        assert json.loads(f["movers"].attrs["field_units"])["vx_mps_sigma"] == "m/s"
    a = _scan(cli, tmp_path, "a")
    b = _scan(cli, tmp_path, "b", minute=30, extra="[effects.displacement]\nscale = 1.0\n")
    scan = assert_self_describing(a)["/"]
    assert scan.s21.dims == ("polarization", "rail_position", "frequency")
    assert list(scan.polarization.values) == [b"VV", b"HH"]
    assert scan.stop_time.dtype.kind == "M"  # CF time since the scan's epoch
    assert cli("gbsar", "focus", a, "-o", tmp_path / "ia.h5").exit_code == 0
    assert cli("gbsar", "focus", b, "-o", tmp_path / "ib.h5").exit_code == 0
    im = assert_self_describing(tmp_path / "ia.h5")["/"]
    assert im.image.dims == ("polarization", "range", "azimuth")
    assert cli("gbsar", "interfere", tmp_path / "ia.h5", tmp_path / "ib.h5", "-o", tmp_path / "ifg.h5").exit_code == 0
    ifg = assert_self_describing(tmp_path / "ifg.h5")["/"]
    assert ifg.unwrapped_phase.dims == ("range", "azimuth") and ifg.value.attrs["units"] == "mm"
    assert cli("gbsar", "coherence", tmp_path / "ia.h5", tmp_path / "ib.h5", "-o", tmp_path / "ps.h5").exit_code == 0
    ps = assert_self_describing(tmp_path / "ps.h5")
    assert ps["/ps"].phase.dims == ("scatterer", "time_s")


def test_scan_written_stop_by_stop_is_self_describing(tmp_path):
    from sarcli.io.scan import ScanWriter, read_scan
    from sarcli.model.gbsar import Scan

    tmpl = Scan(s21=np.zeros((1, 0, 5), np.complex64), frequency=np.linspace(5e9, 5.1e9, 5),
                rail_position=np.zeros(0), rail_height=np.zeros(0), polarizations=("VV",),
                epoch_utc="2024-05-01T10:00:00Z")
    w = ScanWriter.create(tmp_path / "s.h5", tmpl, n_planned=3)
    for k in range(2):
        w.append(np.full((1, 5), k + 1j, np.complex64), 0.1 * k, 2.0, 10.0 * k)
    w.finish("interrupted")
    g = assert_self_describing(tmp_path / "s.h5")["/"]
    assert g.s21.shape == (1, 2, 5) and list(g.rail_position.values) == [0.0, 0.1]
    assert read_scan(tmp_path / "s.h5").n_stops == 2


@pytest.mark.slow
def test_slc_raw_doppler_self_describing_geolocation_grid(cli, small, tmp_path):
    from matplotlib.path import Path as Polygon
    from scipy.interpolate import RegularGridInterpolator

    raw = assert_self_describing(small.raw)
    slc = assert_self_describing(small.slc)
    assert slc["/"].image.dims == ("azimuth_time", "slant_range")
    assert slc["/doppler"].fdc_hz.dims == ("block_time", "range_m")
    assert raw["/"].echo.dims == ("azimuth_time", "slant_range")
    with h5py.File(small.raw) as f:
        assert f["echo"].compression == "gzip"  # a 4-bit quantized simulation compresses
    doppler = tmp_path / "d.h5"
    assert cli("doppler", small.raw, "-o", doppler).exit_code == 0
    d = assert_self_describing(doppler)
    assert d["/blocks"].fdc_hz.dims == ("block",) and d["/blocks"].fdc_hz.attrs["units"] == "Hz"
    # the geolocation grid and the polygon against the simulator's truth (targets on the ellipsoid)
    grid = slc["/geolocation_grid"]
    assert list(grid.height.values) == [-500.0, 0.0, 500.0, 1000.0, 2000.0, 4000.0, 9000.0]
    with h5py.File(small.slc) as f:
        tg = f["truth/targets"][()]
        t_grid, r_grid = f["geolocation_grid/azimuth_time"][()], f["geolocation_grid/slant_range"][()]
        polygon = f.attrs["bounding_polygon"]
    pts = np.column_stack([tg["height_m"], tg["zero_doppler_time_s"], tg["closest_range_m"]])
    grid_lat = RegularGridInterpolator((grid.height.values, t_grid, r_grid), grid.latitude.values)(pts)
    grid_lon = RegularGridInterpolator((grid.height.values, t_grid, r_grid), grid.longitude.values)(pts)
    # trilinear interpolation between nodes ~150 lines x 60 samples apart on a smooth map: well under 5 m
    dn = (grid_lat - tg["lat_deg"]) * 111.2e3
    de = (grid_lon - tg["lon_deg"]) * 111.2e3 * np.cos(np.radians(tg["lat_deg"]))
    assert np.max(np.hypot(dn, de)) < 5.0
    assert polygon.startswith("POLYGON ((")
    ring = np.array([[float(v) for v in p.split()[:2]] for p in polygon[len("POLYGON (("):-2].split(",")])
    assert np.allclose(ring[0], ring[-1])
    inside = Polygon(ring).contains_points(np.column_stack([tg["lon_deg"], tg["lat_deg"]]))
    assert inside.all()
