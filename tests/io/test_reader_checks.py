"""What the product readers refuse (docs/products.md, "What sarcli refuses"): one ProductError line for each damaged or
implausible field, the cases found on real corrupted files, and physical plausibility from first principles."""

from __future__ import annotations

import dataclasses

import h5py
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from orbit.frames import eci_to_ecef
from sarcli.errors import ProductError
from sarcli.io.raw import read_raw, write_raw
from sarcli.io.scan import ScanWriter, read_scan, write_scan
from sarcli.model import checks as ck
from sarcli.model.gbsar import Antenna, Scan, Site
from sarcli.model.raw import EARTH_MU, Orbit

C = 299_792_458.0
BAD_UTF8 = b"F1\xff\xfe"


def _bad_text(g, key):
    g.attrs.create(key, BAD_UTF8, dtype=h5py.string_dtype("utf-8"))


def _set(group, key, value):
    return lambda f: f[group].attrs.__setitem__(key, value) if group else f.attrs.__setitem__(key, value)


def _data(name, fn):
    """Replace dataset ``name`` by fn(its values)."""
    def damage(f):
        v = fn(f[name][()])
        del f[name]
        f[name] = v
    return damage


def _time_gap(t, pulses=1.5):
    t = t.copy()
    t[5:] += (pulses - 1) * (t[1] - t[0])  # the interval 4 -> 5 is `pulses` PRIs
    return t


RAW_DAMAGE = [
    ("prf string", _set("radar", "prf_hz", "1256.98"), "prf_hz must be a number"),
    ("prf 1e-9", _set("radar", "prf_hz", 1e-9), "prf_hz = 1e-09 Hz is implausible"),
    ("prf zero", _set("radar", "prf_hz", 0.0), "prf_hz = 0 Hz is implausible"),
    ("prf NaN", _set("radar", "prf_hz", np.nan), "prf_hz must be finite"),
    ("prf array", _set("radar", "prf_hz", np.array([1256.98, 1256.98])), "prf_hz must be a number"),
    ("prf missing", lambda f: f["radar"].attrs.__delitem__("prf_hz"), "radar attribute 'prf_hz' missing"),
    ("fs implausible", _set("radar", "range_sampling_rate_hz", 10.0), "range_sampling_rate_hz = 10 Hz"),
    ("fs zero", _set("radar", "range_sampling_rate_hz", 0.0), "range_sampling_rate_hz = 0 Hz is implausible"),
    ("wavelength vs carrier", _set("radar", "wavelength_m", 0.0312), "does not match the carrier"),
    ("carrier zero", _set("radar", "carrier_frequency_hz", 0.0), "carrier_frequency_hz = 0 Hz"),
    ("pulse longer than PRI", _set("radar", "pulse_length_s", 1e-3), "exceed the pulse interval"),
    ("chirp band aliased", _set("radar", "chirp_rate_hz_per_s", -1e15), "exceeds the sampling rate"),
    ("chirp rate zero", _set("radar", "chirp_rate_hz_per_s", 0.0), "must be non-zero"),
    ("window start vs range", _set("radar", "window_start_s", 0.0), "does not match window_start_s"),
    ("quantization bits", _set("radar", "quantization_bits", 4.5), "quantization_bits must be an integer"),
    ("epoch not ISO", _set("", "epoch_utc", "16/06/2002 15:41"), "is not an ISO-8601 UTC time"),
    ("epoch number", _set("", "epoch_utc", 1024242060.0), "epoch_utc must be text"),
    ("epoch invalid UTF-8", lambda f: _bad_text(f, "epoch_utc"), "epoch_utc is not valid UTF-8"),
    ("extra attribute invalid UTF-8", lambda f: _bad_text(f, "ceos_beam_name"), "ceos_beam_name is not valid UTF-8"),
    ("look side", _set("", "look_side", "up"), "look_side must be one of right, left"),
    ("echo missing", lambda f: f.__delitem__("echo"), "missing 'echo'"),
    ("azimuth_time missing", lambda f: f.__delitem__("azimuth_time"), "missing 'azimuth_time'"),
    ("azimuth_time inf", _data("azimuth_time", lambda t: np.r_[t[:-1], np.inf]), "azimuth_time contains NaN or inf"),
    ("azimuth_time short", _data("azimuth_time", lambda t: t[:-1]),
     r"azimuth_time has shape \(39,\), expected \(40,\)"),
    ("azimuth_time text", _data("azimuth_time", lambda t: t.astype("S24")), "azimuth_time has dtype"),
    ("azimuth_time reversed", _data("azimuth_time", lambda t: t[::-1].copy()), "azimuth_time must increase"),
    ("azimuth_time off the pulse grid", _data("azimuth_time", _time_gap), "azimuth_time is not uniform: step 4"),
    ("azimuth_time PRF halved", _data("azimuth_time", lambda t: 2 * t), "azimuth_time steps are 2 times"),
    ("agc NaN", _data("radar/agc_db", lambda a: np.r_[a[:3], np.nan, a[4:]].astype(np.float32)),
     "radar/agc_db contains NaN"),
    ("agc short", _data("radar/agc_db", lambda a: a[:-2]), "radar/agc_db has shape"),
    ("replica NaN", _data("radar/replica", lambda a: np.r_[a[:1], np.nan].astype(np.complex64)),
     "radar/replica contains NaN"),
    ("orbit empty", lambda f: [_data(f"orbit/{k}", lambda a: a[:0])(f) for k in ("time", "position", "velocity")],
     "orbit: time has 0 value"),
    ("orbit times text", _data("orbit/time", lambda a: a.astype("S24")), "orbit: time has dtype"),
    ("orbit position short", _data("orbit/position", lambda a: a[:-1]), r"orbit: position has shape \(14, 3\)"),
    ("orbit radius", _data("orbit/position", lambda a: a * 0.5), "is not an Earth orbit"),
    ("orbit unbound", _data("orbit/velocity", lambda a: a * 1.5), "not an Earth orbit \\(unbound\\)"),
    ("orbit into the ground", _data("orbit/velocity", lambda a: a * 0.8), "perigee is below the ground"),
    ("orbit velocity reversed", _data("orbit/velocity", lambda a: -a), "positions and velocities disagree"),
    ("orbit frame", _set("orbit", "frame", "GALACTIC"), "frame must be one of ECI, ECEF, LOCAL"),
    ("attitude shorter than its time axis", _data("attitude/roll", lambda a: a[:-1]), "attitude: roll has shape"),
    ("attitude degrees", _data("attitude/yaw", lambda a: a + 10.0), "yaw exceeds pi rad"),
    ("n_channels", _set("", "n_channels", 2), "n_channels says 2"),
    ("radar not a group", lambda f: [f.__delitem__("radar"), f.create_dataset("radar", data=1.0)],
     "'radar' is not a group"),
    ("external link to nowhere", lambda f: [f.__delitem__("orbit"), f.__setitem__(
        "orbit", h5py.ExternalLink("no_such_file.h5", "/orbit"))], "damaged HDF5 product, cannot read it"),
]


@pytest.fixture
def raw_path(tmp_path, make_raw, rs1_orbit):
    p = make_raw()
    p.attitude = _attitude(p.azimuth_time)
    p.extra_attrs = {"ceos_beam_name": "F1"}
    path = tmp_path / "raw.h5"
    write_raw(path, p, compression="gzip")
    return path


def _attitude(t):
    from sarcli.model.raw import Attitude

    n = t.size
    return Attitude(t.copy(), np.full(n, 1e-3), np.full(n, 0.5), np.zeros(n))


def test_the_undamaged_product_reads(raw_path):
    p = read_raw(raw_path)
    assert p.shape == (40, 96) and p.extra_attrs["ceos_beam_name"] == "F1"
    q = read_raw(raw_path, load_echo=False)
    assert q.shape == (40, 0) and q.n_channels == 1


@pytest.mark.parametrize("damage, msg", [d[1:] for d in RAW_DAMAGE], ids=[d[0] for d in RAW_DAMAGE])
def test_damaged_raw_refused_in_one_line(raw_path, damage, msg):
    with h5py.File(raw_path, "r+") as f:
        damage(f)
    for load_echo in (True, False):  # metadata-only readers (info, orbit) inherit every check
        with pytest.raises(ProductError, match=msg) as e:
            read_raw(raw_path, load_echo=load_echo)
        assert "\n" not in str(e.value) and str(raw_path) in str(e.value)


def test_missing_lines_kept_as_a_gap_are_a_valid_product(tmp_path, make_raw):
    """`sarcli ingest --missing keep`: a gap of whole pulse intervals is allowed (the median is one PRI)."""
    p = make_raw()
    p.azimuth_time = _time_gap(p.azimuth_time, pulses=4.0)
    write_raw(tmp_path / "gap.h5", p)
    assert np.isclose(np.diff(read_raw(tmp_path / "gap.h5").azimuth_time)[4] * p.radar.prf_hz, 4.0)


def test_nan_echo_is_refused_only_when_the_samples_are_read(raw_path):
    with h5py.File(raw_path, "r+") as f:
        f["echo"][3, 4] = np.nan
    assert read_raw(raw_path, load_echo=False).shape == (40, 0)
    with pytest.raises(ProductError, match="echo contains NaN or inf"):
        read_raw(raw_path)


def test_damaged_chunk_is_one_line(raw_path):
    with h5py.File(raw_path) as f:
        info = f["echo"].id.get_chunk_info(0)
    data = bytearray(raw_path.read_bytes())
    for k in range(info.byte_offset + 8, info.byte_offset + info.size, 7):
        data[k] ^= 0x5A
    raw_path.write_bytes(bytes(data))
    with pytest.raises(ProductError, match="damaged HDF5 product") as e:
        read_raw(raw_path)
    assert "\n" not in str(e.value)


def test_truncated_file_is_one_line(raw_path):
    raw_path.write_bytes(raw_path.read_bytes()[: raw_path.stat().st_size // 3])
    with pytest.raises(ProductError, match="not a readable HDF5 product|damaged HDF5 product"):
        read_raw(raw_path)


def test_writer_refuses_what_the_reader_would(tmp_path, make_raw):
    p = make_raw()
    p.radar = dataclasses.replace(p.radar, prf_hz=1e-9)
    with pytest.raises(ProductError, match="prf_hz = 1e-09 Hz is implausible"):
        write_raw(tmp_path / "x.h5", p)
    assert list(tmp_path.iterdir()) == []


# --- orbits: plausibility from the two-body problem ---------------------------------------------------

def _kepler_orbit(r_a: float, r_p: float, n: int = 5, dt: float = 10.0) -> Orbit:
    """State vectors near apoapsis of an ellipse with apoapsis r_a and periapsis r_p (vis-viva:
    v_a = sqrt(2 mu r_p / (r_a (r_a + r_p)))), in the orbit plane z = 0, propagated as a circle
    segment of angular rate v_a / r_a over a few seconds (short enough for the chord check)."""
    v_a = np.sqrt(2 * EARTH_MU * r_p / (r_a * (r_a + r_p)))
    w = v_a / r_a
    t = np.arange(n) * dt
    pos = r_a * np.c_[np.cos(w * t), np.sin(w * t), np.zeros(n)]
    vel = v_a * np.c_[-np.sin(w * t), np.cos(w * t), np.zeros(n)]
    return Orbit(t, pos, vel, "ECI")


@pytest.mark.parametrize("r_a, r_p", [
    (7.167e6, 7.167e6),  # Radarsat-1-like circular LEO
    (4.2164e7, 4.2164e7),  # geostationary
    (4.6e7, 7.0e6),  # Molniya-like apogee: 1.5 km/s, half the circular speed there
    (6.6e6, 6.4e6),  # perigee 22 km above the pole radius: still an orbit
])
def test_earth_orbits_pass(r_a, r_p):
    _kepler_orbit(r_a, r_p).validate()


def test_orbit_whose_perigee_is_inside_the_earth_is_refused():
    with pytest.raises(ProductError, match="perigee is below the ground"):
        _kepler_orbit(7.0e6, 6.2e6).validate()


def test_escape_speed_is_refused():
    o = _kepler_orbit(7.0e6, 7.0e6)
    v_esc = np.sqrt(2 * EARTH_MU / 7.0e6)
    o.velocity = o.velocity / np.linalg.norm(o.velocity, axis=1)[:, None] * v_esc * 1.001
    with pytest.raises(ProductError, match="unbound"):
        o.validate()


def test_geostationary_in_ecef_is_an_orbit():
    """ECEF velocity of a geostationary satellite is ~0; the inertial velocity w x r makes it an orbit."""
    o = _kepler_orbit(4.2164e7, 4.2164e7)
    r, v = eci_to_ecef("2002-06-16T15:41:00Z", o.time, o.position, o.velocity)
    Orbit(o.time, r, v, "ECEF").validate()


def test_real_j2_orbit_in_both_frames(rs1_orbit):
    t, pos, vel = rs1_orbit
    Orbit(t, pos, vel, "ECI").validate()
    r, v = eci_to_ecef("2002-06-16T15:41:00Z", t, pos, vel)
    Orbit(t, r, v, "ECEF").validate()


def test_local_platform_speed():
    t = np.arange(3.0)
    Orbit(t, np.c_[np.zeros(3), 200.0 * t, np.full(3, 3000.0)], np.tile([0.0, 200.0, 0.0], (3, 1)), "LOCAL").validate()
    with pytest.raises(ProductError, match="platform speed 0 m/s is implausible"):
        Orbit(t, np.zeros((3, 3)), np.zeros((3, 3)), "LOCAL").validate()


# --- GB-SAR scans -------------------------------------------------------------------------------------

def _scan(n_stops=6, n_freq=11) -> Scan:
    rng = np.random.default_rng(3)
    s21 = (rng.normal(size=(2, n_stops, n_freq)) + 1j * rng.normal(size=(2, n_stops, n_freq))).astype(np.complex64)
    return Scan(s21=s21, frequency=np.linspace(5.2e9, 5.4e9, n_freq), rail_position=np.arange(n_stops) * 0.05,
                rail_height=np.full(n_stops, 1.5), polarizations=("VV", "HH"), epoch_utc="2026-11-22T00:00:00Z",
                stop_time=np.arange(n_stops) * 2.0, stop_flags=np.zeros(n_stops, np.uint8),
                site=Site(37.87, 127.74, 90.0, 90.0, "left"), antenna=Antenna(),
                instrument={"if_bandwidth_hz": 1000.0, "vna_idn": "HEWLETT PACKARD,8753ES,X,7.74"})


def _stop(name, k, value):
    def damage(f):
        a = f[name][()]
        a[k] = value
        f[name][...] = a
    return damage


SCAN_DAMAGE = [
    ("rail NaN", _stop("rail_position", 2, np.nan), "rail_position contains NaN"),
    ("rail constant", _data("rail_position", lambda x: np.zeros_like(x)), "rail_position must increase"),
    ("rail not monotonic", _stop("rail_position", 3, 0.01), "rail_position must increase"),
    ("rail back and forth", _data("rail_position", lambda x: np.r_[x[::-1][:-2], x[:2]]), "must move one way"),
    ("rail height NaN", _stop("rail_height", 1, np.nan), "rail_height contains NaN"),
    ("rail height implausible", _stop("rail_height", 1, 1e6), "rail_height has implausible values"),
    ("n_complete -1", _set("", "n_complete", -1), "n_complete = -1 is implausible"),
    ("n_complete too large", _set("", "n_complete", 7), "n_complete = 7 is implausible"),
    ("n_complete text", _set("", "n_complete", "6"), "n_complete must be a number"),
    ("n_complete missing", lambda f: f.attrs.__delitem__("n_complete"), "attribute 'n_complete' missing"),
    ("rail short", _data("rail_position", lambda x: x[:4]), "rail_position has 4 value"),
    ("frequency uneven", _stop("frequency", 4, 5.285e9), "frequency is not uniform"),
    ("frequency implausible", _data("frequency", lambda x: x * 1e-9), "frequency\\[0\\] = 5.2 Hz"),
    ("stop flag", _stop("stop_flags", 0, 7), "stop_flags must be 0"),
    ("stop time NaN", _stop("stop_time", 0, np.nan), "stop_time contains NaN"),
    ("polarization", _set("", "polarizations", "VV,XX"), "polarization must be one of"),
    ("polarization count", _set("", "polarizations", "VV"), "do not match s21's 2 plane"),
    ("site latitude", _set("site", "latitude_deg", 120.0), "latitude_deg = 120 deg is implausible"),
    ("site unknown attribute", _set("site", "altitude", 3.0), "site has an unknown attribute 'altitude'"),
    ("antenna beamwidth text", _set("antenna", "beamwidth_rad", "wide"), "beamwidth_rad must be a number"),
    ("instrument invalid UTF-8", lambda f: _bad_text(f["instrument"], "vna_idn"), "vna_idn is not valid UTF-8"),
    ("epoch not ISO", _set("", "epoch_utc", "yesterday"), "not an ISO-8601 UTC time"),
]


@pytest.fixture
def scan_path(tmp_path):
    path = tmp_path / "scan.h5"
    write_scan(path, _scan())
    return path


@pytest.mark.parametrize("damage, msg", [d[1:] for d in SCAN_DAMAGE], ids=[d[0] for d in SCAN_DAMAGE])
def test_damaged_scan_refused_in_one_line(scan_path, damage, msg):
    assert read_scan(scan_path).n_stops == 6
    with h5py.File(scan_path, "r+") as f:
        damage(f)
    with pytest.raises(ProductError, match=msg) as e:
        read_scan(scan_path)
    assert "\n" not in str(e.value)


def test_nan_sweep_is_a_skipped_stop_and_focusing_needs_two_usable(scan_path):
    with h5py.File(scan_path, "r+") as f:
        s = f["s21"][()]
        s[:, 1:, 3] = np.nan  # only stop 0 is usable
        f["s21"][...] = s
    assert read_scan(scan_path).usable_stops().tolist() == [True] + [False] * 5
    with pytest.raises(ProductError, match="1 usable rail stop"):
        read_scan(scan_path, min_usable_stops=2)


def test_resume_refuses_a_damaged_scan(tmp_path):
    path = tmp_path / "acq.h5"
    w = ScanWriter.create(path, _scan(), n_planned=6)
    w.append(_scan().s21[:, 0], 0.0, 1.5, 0.0)
    w.close()
    with h5py.File(path, "r+") as f:
        f.attrs["n_complete"] = 5  # more than the one stop written
    with pytest.raises(ProductError, match="n_complete = 5 is implausible"):
        ScanWriter.resume(path)


# --- the shared checks ----------------------------------------------------------------------------------

@pytest.mark.parametrize("value", [True, "3", b"3", np.array([1.0, 2.0]), None, np.nan, np.inf])
def test_number_refuses_non_numbers(value):
    with pytest.raises(ProductError):
        ck.number("f", "x", value)


def test_number_converts_numpy_scalars():
    assert ck.number("f", "n", np.int64(3), integer=True) == 3 and isinstance(ck.number("f", "x", np.float32(2)), float)
    assert ck.number("f", "x", np.array(2.5)) == 2.5


def test_text_refuses_surrogates_and_invalid_bytes():
    with pytest.raises(ProductError, match="not valid UTF-8"):
        ck.text("f", "s", BAD_UTF8.decode("utf-8", "surrogateescape"))
    with pytest.raises(ProductError, match="not valid UTF-8"):
        ck.text("f", "s", BAD_UTF8)
    assert ck.text("f", "s", "Wellington ✓".encode()) == "Wellington ✓"


def test_uniform_tolerance_is_relative_to_the_step():
    t = np.arange(10) / 1000.0
    ck.uniform("f", "t", t + np.r_[0, 0, 0, 0.09e-3, 0, 0, 0, 0, 0, 0], 1e-3, 0.1)
    with pytest.raises(ProductError, match="step 2 is 0.00111"):
        ck.uniform("f", "t", t + np.r_[0, 0, 0, 0.11e-3, 0, 0, 0, 0, 0, 0], 1e-3, 0.1)


# --- HDF5 files that hang the library -----------------------------------------------------------------

def _hanging_product(path):
    """Two text attributes live in a global heap; XOR 7 into the second object's size (byte 1 of the
    8-byte size at collection + 16 (header) + 16 (first object's header) + 16 (its 10 bytes, padded)
    + 8 (second object's index, reference count, reserved)) sends HDF5 1.14 into an endless loop."""
    with h5py.File(path, "w", libver=("earliest", "v110")) as f:
        f.attrs["product_type"] = "gbsar_scan"
        f.attrs["schema_version"] = "1"
    data = bytearray(path.read_bytes())
    heap = data.find(b"GCOL")
    assert heap > 0 and data[heap + 32:heap + 42] == b"gbsar_scan"
    data[heap + 57] ^= 7
    path.write_bytes(bytes(data))


def test_a_file_that_hangs_the_hdf5_library_is_refused(tmp_path, monkeypatch):
    from sarcli.io import h5common

    monkeypatch.setattr(h5common, "PROBE_TIMEOUT_S", 2.0)
    path = tmp_path / "scan.h5"
    _hanging_product(path)
    with pytest.raises(ProductError, match="reading its metadata does not finish"):
        read_scan(path)


def test_probe_runs_once_per_file_version(tmp_path, monkeypatch):
    from sarcli.io import h5common

    asked = []
    real = h5common._PROBER.ask
    monkeypatch.setattr(h5common._PROBER, "ask", lambda p, t: asked.append(p) or real(p, t))
    path = tmp_path / "scan.h5"
    with h5py.File(path, "w") as f:  # written by another tool: probed on first read
        f.attrs["product_type"] = "gbsar_scan"
    for _ in range(3):
        with h5common.open_product(path):
            pass
    assert len(asked) == 1
    with h5py.File(path, "r+") as f:  # a new version of the file is probed again
        f.attrs["x"] = 1.0
    with h5common.open_product(path):
        pass
    assert len(asked) == 2
    write_scan(tmp_path / "own.h5", _scan())  # what this process wrote needs no probe
    read_scan(tmp_path / "own.h5")
    assert len(asked) == 2


@settings(max_examples=30, deadline=None)
@given(st.sampled_from([np.float32, np.float64, np.complex64, np.complex128]), st.integers(1, 3),
       st.integers(0, 2**31), st.booleans(), st.booleans())
def test_finite_check_in_slices_finds_every_bad_value(dtype, ndim, seed, strided, poison):
    # slices of 7 elements: the bad value may sit in any slice, also the last (short) one
    rng = np.random.default_rng(seed)
    a = rng.standard_normal(tuple(rng.integers(1, 9, ndim))).astype(dtype)
    if strided and a.shape[-1] > 1:
        a = a[..., ::2]
    if poison:
        a[np.unravel_index(rng.integers(a.size), a.shape)] = np.nan if rng.integers(2) else np.inf
    assert ck._all_finite(a, 7) == bool(np.isfinite(a).all()) == (not poison)
