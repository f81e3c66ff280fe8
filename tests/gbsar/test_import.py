"""`sarcli gbsar import`: every format and layout against hand-made files whose content is known."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import scipy.io
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.errors import ConfigError, FormatError
from sarcli.io.scan import read_scan
from sarcli.io.sweeps import Names, polarization_from_names, read_sweeps, read_touchstone
from sarcli.workflows import gbsar_import

N_F, N_P = 7, 5


@pytest.fixture
def known():
    """Samples (position x frequency), frequencies, 3-D positions and reference ranges."""
    rng = np.random.default_rng(3)
    s = (rng.standard_normal((N_P, N_F)) + 1j * rng.standard_normal((N_P, N_F))).astype(np.complex64)
    f = 9e9 + 2e6 * np.arange(N_F)
    xyz = np.stack([100.0 + np.arange(N_P), 2.0 * np.arange(N_P), np.full(N_P, 50.0)], axis=1)
    return s, f, xyz, np.linalg.norm(xyz, axis=1)


def _matlab_v73(path, variables):
    """A MATLAB v7.3 file as MATLAB writes it: a 512-byte header, then HDF5 with column-major arrays
    (axes reversed) and complex numbers as (real, imag) compounds."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, a in variables.items():
            a = np.asarray(a).T
            if np.iscomplexobj(a):
                c = np.empty(a.shape, [("real", "<f8"), ("imag", "<f8")])
                c["real"], c["imag"] = a.real, a.imag
                a = c
            f[name] = a
    head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:
        fh.write(head.ljust(116) + b"\0" * 8 + b"\x00\x02" + b"IM")


@pytest.mark.parametrize("layout", ["frequency-position", "position-frequency"])
def test_matlab_struct_with_3d_track_and_reference_range(tmp_path, known, layout):
    """GOTCHA's layout (struct ``data`` with fp, freq, x, y, z, r0) read by the default names."""
    s, f, xyz, r0 = known
    fp = s.T if layout == "frequency-position" else s
    p = tmp_path / "pass_HH.mat"
    scipy.io.savemat(p, {"data": {"fp": fp, "freq": f[:, None].astype(np.float32), "x": xyz[:, 0][None],
                                  "y": xyz[:, 1][None], "z": xyz[:, 2][None], "r0": r0[None]}})
    sw = read_sweeps([p])
    assert sw.layout == layout
    assert sw.used == {"data": "data.fp", "frequency": "data.freq", "position": "data.x,data.y,data.z",
                       "reference_range": "data.r0"}
    np.testing.assert_array_equal(sw.samples, s)
    np.testing.assert_array_equal(sw.position, xyz)
    np.testing.assert_array_equal(sw.reference_range, r0)
    # float32 frequencies (rounded by up to 512 Hz at 9 GHz) -> a uniform sweep, within one float32 ulp
    # (1024 Hz) of the true one; range compression's uniformity check (1e-6 of the step) passes
    np.testing.assert_allclose(sw.frequency, f, rtol=0, atol=1024)
    steps = np.diff(sw.frequency)
    assert np.all(np.abs(steps - steps[0]) <= 1e-6 * steps[0])
    assert "float32" in sw.notes[0]


@settings(max_examples=25, deadline=None)
@given(n_f=st.integers(1, 9), n_p=st.integers(1, 9), transposed=st.booleans(), track=st.booleans(),
       seed=st.integers(0, 2**31))
def test_any_shape_either_layout_round_trips(tmp_path_factory, n_f, n_p, transposed, track, seed):
    """Whatever the sizes, a non-square matrix is oriented from the lengths and read back exactly."""
    rng = np.random.default_rng(seed)
    s = rng.standard_normal((n_p, n_f)) + 1j * rng.standard_normal((n_p, n_f))
    pos = rng.uniform(-5, 5, (n_p, 3) if track else n_p)
    p = tmp_path_factory.mktemp("any") / "a.npz"
    np.savez(p, s21=s.T if transposed else s, frequency=1e9 + 1e6 * np.arange(n_f), position=pos)
    if n_f == n_p and n_p > 1:
        with pytest.raises(ConfigError, match="ambiguous"):
            read_sweeps([p])
        return
    sw = read_sweeps([p])
    np.testing.assert_array_equal(sw.samples, s)
    np.testing.assert_array_equal(sw.position, pos)


def test_square_matrix_needs_the_layout(tmp_path, known):
    s, f, _, _ = known
    sq = s[:, :N_P]  # 5 positions x 5 frequencies
    p = tmp_path / "sq.npz"
    np.savez(p, data=sq, frequency=f[:N_P], position=np.arange(N_P) * 0.1)
    with pytest.raises(ConfigError, match="ambiguous; give --layout"):
        read_sweeps([p])
    np.testing.assert_array_equal(read_sweeps([p], Names(layout="frequency-position")).samples, sq.T)
    np.testing.assert_array_equal(read_sweeps([p], Names(layout="position-frequency")).samples, sq)


def test_matlab_v73_and_explicit_names(tmp_path, known):
    s, f, xyz, r0 = known
    p = tmp_path / "v73.mat"
    _matlab_v73(p, {"S": s.T, "fr": f, "ant": xyz, "ref": r0})
    sw = read_sweeps([p], Names(data="S", frequency="fr", position="ant", reference_range="ref"))
    np.testing.assert_array_equal(sw.samples, s)
    np.testing.assert_array_equal(sw.frequency, f)
    np.testing.assert_array_equal(sw.position, xyz)
    np.testing.assert_array_equal(sw.reference_range, r0)
    assert sw.layout == "frequency-position"


def test_npz_rail_re_im_pair_and_3xn_positions(tmp_path, known):
    s, f, xyz, _ = known
    p = tmp_path / "rail.npz"
    np.savez(p, re=s.real, im=s.imag, f=f, x=np.linspace(0, 0.4, N_P))
    sw = read_sweeps([p], Names(data="re,im"))
    np.testing.assert_array_equal(sw.samples, s)
    np.testing.assert_array_equal(sw.position, np.linspace(0, 0.4, N_P))
    assert sw.reference_range is None and sw.used["position"] == "x"
    q = tmp_path / "track.npz"
    np.savez(q, s21=s.T, freq=f, pos=xyz.T, r0=123.0)  # (3, n) positions; one reference range for all
    sw = read_sweeps([q])
    np.testing.assert_array_equal(sw.position, xyz)
    np.testing.assert_array_equal(sw.reference_range, np.full(N_P, 123.0))


def test_npy_structured_array(tmp_path, known):
    s, f, xyz, r0 = known
    rec = np.zeros((), [("fp", "c16", s.shape), ("freq", "f8", f.shape), ("pos", "f8", xyz.shape)])
    rec["fp"], rec["freq"], rec["pos"] = s, f, xyz
    p = tmp_path / "rec.npy"
    np.save(p, rec)
    sw = read_sweeps([p])
    np.testing.assert_array_equal(sw.samples, s)
    np.testing.assert_array_equal(sw.position, xyz)


def _csv_rows(s, f, pos, r0=None, complex_col=True):
    rows = []
    for i in range(s.shape[0]):
        for k in np.random.default_rng(i).permutation(f.size):  # any row order
            p = [repr(float(v)) for v in np.atleast_1d(pos[i])]
            v = [f"{complex(s[i, k])!r}".strip("()").replace("j", "i")] if complex_col else \
                [repr(float(s[i, k].real)), repr(float(s[i, k].imag))]
            rows.append([repr(float(f[k])), *p, *v] + ([repr(float(r0[i]))] if r0 is not None else []))
    return rows


def test_csv_complex_column_and_rail(tmp_path, known):
    s, f, _, _ = known
    x = np.linspace(-0.2, 0.2, N_P)
    p = tmp_path / "rail.csv"
    lines = ["# lab rail, S21", "frequency;position;s21"] + [";".join(r) for r in _csv_rows(s, f, x)]
    p.write_text("\n".join(lines) + "\n")
    sw = read_sweeps([p])
    np.testing.assert_array_equal(sw.samples, s.astype(np.complex128))
    np.testing.assert_array_equal(sw.frequency, f)
    np.testing.assert_array_equal(sw.position, x)


def test_csv_re_im_columns_3d_positions_reference(tmp_path, known):
    s, f, xyz, r0 = known
    p = tmp_path / "track.csv"
    lines = ["freq,x,y,z,re,im,r0"] + [",".join(r) for r in _csv_rows(s, f, xyz, r0, complex_col=False)]
    p.write_text("\n".join(lines) + "\n")
    sw = read_sweeps([p], Names(reference_range="r0"))
    np.testing.assert_array_equal(sw.samples, s.astype(np.complex128))
    np.testing.assert_array_equal(sw.position, xyz)
    np.testing.assert_array_equal(sw.reference_range, r0)


def _touchstone(path, f, rows, unit="GHz", fmt="MA", ports=2, extra=""):
    scale = {"Hz": 1, "kHz": 1e3, "MHz": 1e6, "GHz": 1e9}[unit]

    def pair(z):
        z = complex(z)
        if fmt == "RI":
            return f"{z.real!r} {z.imag!r}"
        mag = abs(z) if fmt == "MA" else 20 * np.log10(abs(z))
        return f"{float(mag)!r} {float(np.degrees(np.angle(z)))!r}"

    lines = ["! hand-made", f"# {unit} S {fmt} R 50"]
    for k, fk in enumerate(f):
        lines.append(f"{float(fk / scale)!r} " + " ".join(pair(z) for z in rows[k]))
    path.write_text("\n".join(lines) + "\n" + extra)


@pytest.mark.parametrize("unit,fmt", [("Hz", "RI"), ("kHz", "MA"), ("MHz", "DB"), ("GHz", "MA")])
def test_touchstone_formats_and_units(tmp_path, known, unit, fmt):
    s, f, _, _ = known
    files = []
    for i in range(N_P):  # .s2p: S11 S21 S12 S22 per line; S21 is the sweep
        p = tmp_path / f"stop{i}.s2p"
        _touchstone(p, f, [(0.1, s[i, k], 0.2, 0.3) for k in range(N_F)], unit, fmt)
        files.append(p)
    sw = read_sweeps(files, Names(position="1.0:0.05"))
    np.testing.assert_allclose(sw.frequency, f, rtol=1e-15)
    np.testing.assert_allclose(sw.samples, s, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(sw.position, 1.0 + 0.05 * np.arange(N_P), rtol=1e-15)


def test_touchstone_s1p_v2_order_and_noise_data(tmp_path, known):
    s, f, _, _ = known
    p1 = tmp_path / "a.s1p"
    _touchstone(p1, f, [(s[0, k],) for k in range(N_F)], "MHz", "RI", ports=1)
    fr, v, name = read_touchstone(p1)
    assert name == "S11"
    np.testing.assert_allclose(v, s[0], rtol=1e-12)
    # v1 2-port with noise parameters after the network data (frequency restarts): ignored
    p2 = tmp_path / "b.s2p"
    _touchstone(p2, f, [(0, s[1, k], 0, 0) for k in range(N_F)], "GHz", "RI",
                extra="9.0 1.5 0.3 40 0.2\n9.5 1.6 0.3 41 0.2\n")
    np.testing.assert_allclose(read_touchstone(p2)[1], s[1], rtol=1e-12)
    # v2, [Two-Port Data Order] 12_21: the second pair is S12
    p3 = tmp_path / "c.s2p"
    _touchstone(p3, f, [(0, 9, s[2, k], 0) for k in range(N_F)], "GHz", "RI")
    p3.write_text("[Version] 2.0\n" + p3.read_text().replace("# GHz", "[Number of Ports] 2\n"
                                                             "[Two-Port Data Order] 12_21\n# GHz"))
    np.testing.assert_allclose(read_touchstone(p3, "S21")[1], s[2], rtol=1e-12)


def test_several_files_concatenate_along_positions(tmp_path, known):
    s, f, xyz, r0 = known
    paths = []
    for part, idx in enumerate((slice(0, 2), slice(2, N_P))):
        p = tmp_path / f"part{part}.mat"
        scipy.io.savemat(p, {"data": {"fp": s[idx].T, "freq": f, "x": xyz[idx, 0], "y": xyz[idx, 1],
                                      "z": xyz[idx, 2], "r0": r0[idx]}})
        paths.append(p)
    sw = read_sweeps(paths)
    np.testing.assert_array_equal(sw.samples, s)
    np.testing.assert_array_equal(sw.reference_range, r0)


def test_workflow_writes_a_3d_scan_and_reports(tmp_path, known):
    s, f, xyz, r0 = known
    p = tmp_path / "data_3dsar_pass1_az001_VH.mat"
    scipy.io.savemat(p, {"data": {"fp": s.T, "freq": f, "x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2], "r0": r0}})
    out = tmp_path / "scan.h5"
    rep = gbsar_import.run(gbsar_import.Config(inputs=(p,), output=out))
    assert rep.polarization == "VH" and rep.polarization_from == "from the file names"
    assert rep.layout == "frequency x position" and rep.track == "3-D"
    sc = read_scan(out)
    np.testing.assert_array_equal(sc.s21[0], s)
    np.testing.assert_array_equal(sc.antenna_position, xyz)
    np.testing.assert_array_equal(sc.reference_range, r0)
    np.testing.assert_allclose(sc.rail_position, np.r_[0, np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
    with h5py.File(out) as h:
        assert h.attrs["schema_version"] == "2"


def test_rail_import_is_a_schema_1_scan(tmp_path, known):
    """1-D positions without reference: the rail scan every focuser takes, as before (schema 1)."""
    s, f, _, _ = known
    p = tmp_path / "rail.npz"
    np.savez(p, s21=s, frequency=f, position=np.arange(N_P) * 0.05)
    out = tmp_path / "rail.h5"
    rep = gbsar_import.run(gbsar_import.Config(inputs=(p,), output=out, height_m=1.5, antenna_length_m=0.1))
    assert rep.polarization == "VV" and rep.polarization_from == "default"
    sc = read_scan(out)
    assert sc.is_rail and sc.antenna.length_azimuth_m == 0.1
    np.testing.assert_array_equal(sc.rail_height, np.full(N_P, 1.5))
    with h5py.File(out) as h:
        assert h.attrs["schema_version"] == "1" and "antenna_position" not in h and "reference_range" not in h


def test_nan_sweeps_are_flagged(tmp_path, known):
    s, f, _, _ = known
    s = s.copy()
    s[3, 2] = np.nan
    p = tmp_path / "nan.npz"
    np.savez(p, s21=s, frequency=f, position=np.arange(N_P) * 0.05)
    rep = gbsar_import.run(gbsar_import.Config(inputs=(p,), output=tmp_path / "o.h5"))
    assert rep.flagged_sweeps == [3]
    np.testing.assert_array_equal(read_scan(tmp_path / "o.h5").stop_flags, [0, 0, 0, 1, 0])


def test_decreasing_frequencies_are_reversed(tmp_path, known):
    s, f, _, _ = known
    p = tmp_path / "down.npz"
    np.savez(p, s21=s[:, ::-1], frequency=f[::-1], position=np.arange(N_P) * 0.05)
    sw = read_sweeps([p])
    np.testing.assert_array_equal(sw.frequency, f)
    np.testing.assert_array_equal(sw.samples, s)


def test_polarization_from_file_names():
    assert polarization_from_names(["a_HH.mat", "b_hh.mat"]) == "HH"
    assert polarization_from_names(["a_HH.mat", "b.mat"]) is None
    assert polarization_from_names(["a_HH_VV.mat"]) is None
    assert polarization_from_names(["chhaos.mat"]) is None


def _npz(tmp_path, name="bad.npz", **arrays):
    p = tmp_path / name
    np.savez(p, **arrays)
    return p


BAD = {
    "missing variable": (lambda t, s, f: _npz(t, s21=s, frequency=f), {}, FormatError,
                         "no position variable under the usual names"),
    "named variable absent": (lambda t, s, f: _npz(t, s21=s, frequency=f, x=np.arange(N_P)), {"data": "S"},
                              FormatError, "the data variable 'S' does not exist"),
    "real samples": (lambda t, s, f: _npz(t, s21=s.real, frequency=f, x=np.arange(N_P)), {}, FormatError,
                     "is real"),
    "wrong shape": (lambda t, s, f: _npz(t, s21=s, frequency=f[:-1], x=np.arange(N_P)), {}, FormatError,
                    "are 5 x 7 but there are 6 frequencies and 5 positions"),
    "layout given wrong": (lambda t, s, f: _npz(t, s21=s, frequency=f, x=np.arange(N_P)),
                           {"layout": "frequency-position"}, FormatError, "not frequency x position"),
    "non-finite position": (lambda t, s, f: _npz(t, s21=s, frequency=f, x=np.r_[0, 1, np.nan, 3, 4]), {},
                            FormatError, "sweep 2 is not finite"),
    "reference count": (lambda t, s, f: _npz(t, s21=s, frequency=f, x=np.arange(N_P), r0=np.ones(3)), {},
                        FormatError, "3 reference ranges for 5 sweeps"),
    "non-monotonic frequencies": (lambda t, s, f: _npz(t, s21=s, frequency=f[[0, 2, 1, 3, 4, 5, 6]],
                                                       x=np.arange(N_P)), {}, FormatError, "not strictly monotonic"),
    "plain npy": (lambda t, s, f: (np.save(t / "a.npy", s), t / "a.npy")[1], {}, FormatError, "one unnamed array"),
    "pickled npy": (lambda t, s, f: (np.save(t / "p.npy", np.array([{"a": 1}], dtype=object)), t / "p.npy")[1], {},
                    FormatError, "pickled"),
    "not a mat file": (lambda t, s, f: ((t / "x.mat").write_bytes(b"garbage" * 30), t / "x.mat")[1], {},
                       FormatError, "not a readable MATLAB file"),
    "unknown extension": (lambda t, s, f: ((t / "x.txt").write_text("1"), t / "x.txt")[1], {}, FormatError,
                          "unknown sweep format"),
    "csv gap": (lambda t, s, f: ((t / "g.csv").write_text("frequency,position,s21\n1,0,1+1j\n2,0,1\n1,1,2\n"),
                                 t / "g.csv")[1], {}, FormatError, "every position needs the same sweep"),
    "csv duplicate": (lambda t, s, f: ((t / "d.csv").write_text("frequency,position,s21\n1,0,1\n1,0,2\n"),
                                       t / "d.csv")[1], {}, FormatError, "frequency 1 Hz twice"),
    "csv text": (lambda t, s, f: ((t / "n.csv").write_text("frequency,position,s21\n1,0,abc\n"), t / "n.csv")[1],
                 {}, FormatError, "line 2: not a number"),
    "csv no column": (lambda t, s, f: ((t / "c.csv").write_text("freq,position,s21\n1,0,1\n"), t / "c.csv")[1],
                      {"data": "value"}, FormatError, "no column value"),
    "touchstone without positions": (lambda t, s, f: ((t / "a.s1p").write_text("# Hz S RI\n1 1 0\n"),
                                                      t / "a.s1p")[1], {}, ConfigError, "carry no antenna position"),
    "touchstone Z parameters": (lambda t, s, f: ((t / "a.s1p").write_text("# Hz Z RI\n1 1 0\n"), t / "a.s1p")[1],
                                {"position": "0:1"}, FormatError, "only S-parameters"),
    "touchstone broken line": (lambda t, s, f: ((t / "a.s2p").write_text("# Hz S RI\n1 1 0 2 0 3 0 4\n"),
                                                t / "a.s2p")[1], {"position": "0:1"}, FormatError,
                               "do not make whole lines of 9"),
    "touchstone S21 of one port": (lambda t, s, f: ((t / "a.s1p").write_text("# Hz S RI\n1 1 0\n2 1 0\n"),
                                                    t / "a.s1p")[1], {"position": "0:1", "data": "S21"}, ConfigError,
                                   "holds S11, not S21"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_malformed_inputs_are_one_line(tmp_path, known, case):
    make, names, error, message = BAD[case]
    s, f, _, _ = known
    path = make(tmp_path, s, f)
    with pytest.raises(error, match=message) as e:
        read_sweeps([path], Names(**names))
    assert "\n" not in str(e.value)


def test_mixed_and_mismatched_files(tmp_path, known):
    s, f, _, _ = known
    a = _npz(tmp_path, "a.npz", s21=s, frequency=f, x=np.arange(N_P))
    b = _npz(tmp_path, "b.npz", s21=s, frequency=f + 1.0, x=np.arange(N_P))
    with pytest.raises(FormatError, match="frequencies differ"):
        read_sweeps([a, b])
    c = tmp_path / "c.csv"
    c.write_text("frequency,position,s21\n1,0,1\n")
    with pytest.raises(ConfigError, match="mix formats"):
        read_sweeps([a, c])


def test_cli_import_json_and_one_line_errors(cli, tmp_path, known):
    s, f, _, _ = known
    p = _npz(tmp_path, "scan_HV.npz", s21=s.T, f=f, x=np.arange(N_P) * 0.1)
    out = tmp_path / "o.h5"
    r = cli("gbsar", "import", p, "-o", out, "--json")
    assert r.exit_code == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["layout"] == "frequency x position" and doc["polarization"] == "HV" and doc["n_sweeps"] == N_P
    r = cli("gbsar", "import", p, "-o", p)
    assert r.exit_code == 2 and "refusing to overwrite an input" in r.stderr
    r = cli("gbsar", "import", p, "--data", "nope", "-o", tmp_path / "x.h5")
    assert r.exit_code == 1 and r.stderr.count("\n") == 1 and "'nope' does not exist" in r.stderr
    assert not (tmp_path / "x.h5").exists()


def test_defaults_are_looked_up_beside_the_named_samples(tmp_path, known):
    s, f, xyz, _ = known
    p = tmp_path / "two.mat"
    scipy.io.savemat(p, {"S": s, "freq": f, "x": np.arange(N_P) * 0.1,
                         "meta": {"freq": f + 1.0, "position": xyz}})
    sw = read_sweeps([p], Names(data="S"))
    assert sw.used["frequency"] == "freq" and sw.used["position"] == "x"
    sw = read_sweeps([p], Names(data="S", frequency="meta.freq", position="meta.position"))
    np.testing.assert_array_equal(sw.frequency, f + 1.0)
    np.testing.assert_array_equal(sw.position, xyz)
