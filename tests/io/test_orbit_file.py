"""``sarcli ingest --matlab ... --orbit FILE``: a block gets the pass's state vectors from a CSV or an ESA
orbit file (the truth: the state vectors the files were written from, a J2-propagated RADARSAT-1-like
orbit); a file in the wrong unit, for another time, or without the block's epoch is refused in one line."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.io

from orbit.timeutil import add_seconds
from sarcli.errors import FormatError, ProductError
from sarcli.io.orbit_file import read_orbit_file
from sarcli.io.raw import read_raw
from tests.focus.rs1_orbit import rs1_ecef_orbit

EPOCH = "2002-06-16T00:00:00Z"  # the epoch of rs1_ecef_orbit(): vectors at -60 .. 60 s, 10 s apart
PRF = 1256.98


def _csv(path, sv, scale=1.0, header=True):
    rows = ["# RADARSAT-1-like orbit, WGS-84 ECEF", "time_utc,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps"] if header else []
    for t, p, v in zip(sv.time, sv.position * scale, sv.velocity * scale, strict=True):
        rows.append(",".join([add_seconds(EPOCH, t), *map(repr, p.tolist()), *map(repr, v.tolist())]))
    path.write_text("\n".join(rows) + "\n")
    return path


def _eof(path, sv):
    """The layout of an ESA Earth Explorer orbit file [ESA-EOF] (Sentinel-1 POEORB), trimmed to one OSV list."""
    osv = "".join(
        f"<OSV><TAI>TAI={add_seconds(EPOCH, t + 32)[:-1]}</TAI><UTC>UTC={add_seconds(EPOCH, t)[:-1]}</UTC>"
        f"<UT1>UT1={add_seconds(EPOCH, t)[:-1]}</UT1><Absolute_Orbit>+33900</Absolute_Orbit>"
        f'<X unit="m">{p[0]!r}</X><Y unit="m">{p[1]!r}</Y><Z unit="m">{p[2]!r}</Z>'
        f'<VX unit="m/s">{v[0]!r}</VX><VY unit="m/s">{v[1]!r}</VY><VZ unit="m/s">{v[2]!r}</VZ>'
        "<Quality>NOMINAL</Quality></OSV>\n"
        for t, p, v in zip(sv.time, sv.position.tolist(), sv.velocity.tolist(), strict=True))
    path.write_text('<?xml version="1.0" ?>\n<Earth_Explorer_File><Earth_Explorer_Header/><Data_Block type="xml">'
                    f'<List_of_OSVs count="{sv.time.size}">\n{osv}</List_of_OSVs></Data_Block></Earth_Explorer_File>\n')
    return path


@pytest.fixture
def block(tmp_path):
    """A small MATLAB block (4-bit levels) and its run parameters, starting at line 1 of the pass."""
    rng = np.random.default_rng(5)
    levels = 2 * rng.integers(-8, 8, size=(2, 64, 128)) + 1
    data, params = tmp_path / "block.mat", tmp_path / "params.mat"
    scipy.io.savemat(data, {"data": levels[0] + 1j * levels[1]})
    scipy.io.savemat(params, {"f0": 5.3e9, "Fr": 32.317e6, "Kr": 0.72135e12, "Tr": 41.75e-6, "PRF": PRF,
                              "R0": 988647.462, "c": 2.9979e8})
    return data, params


@pytest.mark.parametrize("writer", [_csv, _eof], ids=["csv", "esa-eof"])
def test_state_vectors_are_read_as_written(tmp_path, writer):
    sv = rs1_ecef_orbit()
    orbit = read_orbit_file(writer(tmp_path / "orbit.txt", sv), EPOCH)
    assert orbit.frame == "ECEF"
    np.testing.assert_array_equal(orbit.position, sv.position)  # repr round-trips a float64
    np.testing.assert_array_equal(orbit.velocity, sv.velocity)
    np.testing.assert_allclose(orbit.time, sv.time, rtol=0, atol=0.5e-6)  # ISO times: microseconds
    # the same vectors, another epoch: the times move, nothing else
    later = read_orbit_file(tmp_path / "orbit.txt", add_seconds(EPOCH, 100.0))
    np.testing.assert_allclose(later.time, sv.time - 100.0, rtol=0, atol=0.5e-6)


def test_ingest_attaches_the_orbit_to_the_block(cli, block, tmp_path):
    sv = rs1_ecef_orbit()
    data, params = block
    orbit_csv = _csv(tmp_path / "orbit.csv", sv)
    out = tmp_path / "raw.h5"
    r = cli("ingest", "--matlab", data, "--params", params, "--epoch", EPOCH, "--orbit", orbit_csv, "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["n_state_vectors"] == sv.time.size
    raw = read_raw(out, load_echo=False)
    assert raw.orbit is not None and raw.orbit.frame == "ECEF"
    np.testing.assert_array_equal(raw.orbit.position, sv.position)
    assert "orbit.csv" in raw.extra_attrs["orbit_note"]
    r = cli("orbit", "info", out, "--json")
    assert r.exit_code == 0, r.stderr


def test_ingest_refuses_an_orbit_it_cannot_place(cli, block, tmp_path):
    sv = rs1_ecef_orbit()
    data, params = block
    good = _csv(tmp_path / "orbit.csv", sv)
    args = ("ingest", "--matlab", data, "--params", params, "-o", tmp_path / "x.h5")
    cases = [
        ((*args, "--orbit", good), 2, "an orbit needs the epoch (--epoch"),  # a block has no time of day
        ((*args, "--orbit", good, "--epoch", "2002-06-17T00:00:00Z"), 2, "another pass's file, or a wrong epoch"),
        ((*args, "--orbit", _csv(tmp_path / "km.csv", sv, 1e-3), "--epoch", EPOCH), 1, "km.csv: orbit"),
        ((*args, "--orbit", tmp_path / "none.csv", "--epoch", EPOCH), 2, "none.csv: no such file"),
    ]
    for argv, code, needle in cases:
        r = cli(*argv)
        lines = r.stderr.strip().splitlines()
        assert r.exit_code == code and len(lines) == 1 and needle in lines[0], (needle, r.stderr)
        assert not (tmp_path / "x.h5").exists()


@pytest.mark.parametrize("text, needle", [
    ("time_utc,x\n2002-06-16T00:00:00Z,1,2,3,4,5\n", "line 2: 6 columns"),
    ("2002-06-16T00:00:00Z,1,2,3,4,5,6\nyesterday,1,2,3,4,5,6\n", "line 2: 'yesterday' is not an ISO-8601"),
    ("2002-06-16T00:00:00Z,1,2,3,4,5,nan\n", "vz_mps is nan"),
    ("2002-06-16T00:00:00Z,1,2,3,4,5,6\n", "1 state vector(s)"),
    ("<Earth_Explorer_File><OSV><UTC>UTC=2002-06-16T00:00:00</UTC><X>1</X></OSV></Earth_Explorer_File>",
     "OSV 1: no <Y>"),
    ("<Earth_Explorer_File><OSV>", "not a readable XML orbit file"),
])
def test_a_bad_orbit_file_is_one_line(tmp_path, text, needle):
    p = tmp_path / "o.csv"
    p.write_text(text)
    with pytest.raises(FormatError) as e:
        read_orbit_file(p, EPOCH)
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_vectors_that_are_no_orbit_are_refused(tmp_path):
    """Velocities in the inertial frame's magnitude but positions in km: Orbit.validate names the radius."""
    sv = rs1_ecef_orbit()
    with pytest.raises(ProductError, match="orbit"):
        read_orbit_file(_csv(tmp_path / "o.csv", sv, 1e-3, header=False), EPOCH)
