"""``sarcli ingest`` on CEOS scenes: end to end, and every bad input -> one line, non-zero exit,
input files unchanged (hashed before and after)."""

from __future__ import annotations

import json
import shutil

import h5py
import numpy as np
import pytest

from sarcli.io.ceos.radarsat1 import write_ceos
from sarcli.io.h5common import sha256_file
from sarcli.io.raw import read_raw


@pytest.fixture
def scene(make_raw, tmp_path):
    raw = make_raw(n_lines=24)
    lea, dat = write_ceos(tmp_path / "scene", raw)
    return raw, lea, dat


def one_line_error(r, *needles):
    assert r.exit_code != 0
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("sarcli: error: "), r.stderr
    for n in needles:
        assert n in lines[0], lines[0]
    return lines[0]


def run_unchanged(cli, paths, *args):
    before = [sha256_file(p) for p in paths]
    r = cli(*args)
    assert [sha256_file(p) for p in paths] == before  # the input is never modified
    return r


def test_ingest_folder_and_pair_then_info(cli, scene, tmp_path):
    raw, lea, dat = scene
    r = run_unchanged(cli, [lea, dat], "ingest", lea.parent, "-o", tmp_path / "a.h5", "--json")
    assert r.exit_code == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["shape"] == [24, 96] and s["beam"] == "FN1" and s["replica_lines"] == 3
    r = cli("ingest", lea, dat, "-o", tmp_path / "b.h5")
    assert r.exit_code == 0 and "wrote" in r.stderr
    a, b = read_raw(tmp_path / "a.h5"), read_raw(tmp_path / "b.h5")
    assert np.array_equal(a.echo, raw.echo) and np.array_equal(b.echo, raw.echo)
    with h5py.File(tmp_path / "a.h5") as f:
        assert f["orbit"].attrs["frame"] == "ECI" and f.attrs["ceos_beam_name"] == "FN1"
        assert [i["path"] for i in json.loads(f.attrs["inputs"])] == ["LEA_01.001", "DAT_01.001"]
    info = json.loads(cli("info", tmp_path / "a.h5", "--json").stdout)
    assert info["prf_hz"] == pytest.approx(raw.radar.prf_hz, rel=1e-15)
    assert info["first_range_m"] == pytest.approx(raw.radar.first_range_m, rel=1e-12)
    assert info["azimuth_start_utc"] == raw.epoch_utc and info["n_state_vectors"] == 15


def test_reproducible_ingest(cli, scene, tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1000000000")
    _, lea, _ = scene
    for name in ("x.h5", "y.h5"):
        assert cli("ingest", lea.parent, "-o", tmp_path / name).exit_code == 0
    assert sha256_file(tmp_path / "x.h5") == sha256_file(tmp_path / "y.h5")


def test_not_a_ceos_file(cli, scene, tmp_path):
    _, lea, dat = scene
    junk = tmp_path / "junk.bin"
    junk.write_bytes(np.random.default_rng(0).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    one_line_error(run_unchanged(cli, [junk, dat], "ingest", junk, dat, "-o", tmp_path / "o.h5"),
                   "not a CEOS leader file")
    one_line_error(run_unchanged(cli, [lea, junk], "ingest", lea, junk, "-o", tmp_path / "o.h5"),
                   "not a CEOS data file")
    one_line_error(cli("ingest", dat, lea, "-o", tmp_path / "o.h5"), "leader and data swapped?")
    # a folder no reader recognises (sniffed: the readers are asked in turn); named, the CEOS reader says why
    one_line_error(cli("ingest", tmp_path, "-o", tmp_path / "o.h5"), "no reader recognises this input",
                   "ceos-rs1", "--format")
    one_line_error(cli("ingest", tmp_path, "--format", "ceos-rs1", "-o", tmp_path / "o.h5"), "no LEA_01.001")
    empty = tmp_path / "empty.001"
    empty.write_bytes(b"")
    one_line_error(cli("ingest", lea, empty, "-o", tmp_path / "o.h5"), "empty file")
    one_line_error(cli("ingest", lea, tmp_path / "nope.001", "-o", tmp_path / "o.h5"), "no such file")
    short = tmp_path / "short.001"
    short.write_bytes(dat.read_bytes()[:5000])  # inside the 16252-byte descriptor
    one_line_error(cli("ingest", lea, short, "-o", tmp_path / "o.h5"), "file descriptor claims 16252 bytes")
    assert not (tmp_path / "o.h5").exists()


def test_truncated_data_file_and_keep_partial(cli, scene, tmp_path):
    raw, lea, dat = scene
    cut = tmp_path / "cut"
    cut.mkdir()
    shutil.copy(lea, cut / "LEA_01.001")
    data = dat.read_bytes()
    (cut / "DAT_01.001").write_bytes(data[: 16252 + 7 * (242 + 192) + (242 + 2880 + 192) + 100])
    paths = [cut / "LEA_01.001", cut / "DAT_01.001"]
    one_line_error(run_unchanged(cli, paths, "ingest", cut, "-o", tmp_path / "o.h5"),
                   "truncated: 8 of 24 lines complete", "--keep-partial")
    r = run_unchanged(cli, paths, "ingest", cut, "-o", tmp_path / "o.h5", "--keep-partial")
    assert r.exit_code == 0 and "kept the 8 complete lines of 24" in r.stderr
    assert np.array_equal(read_raw(tmp_path / "o.h5").echo, raw.echo[:8])


def corrupt(tmp_path, src_lea, src_dat, edit_lea=None, edit_dat=None):
    d = tmp_path / "bad"
    d.mkdir(exist_ok=True)
    for src, edit in ((src_lea, edit_lea), (src_dat, edit_dat)):
        b = bytearray(src.read_bytes())
        if edit:
            edit(b)
        (d / src.name).write_bytes(bytes(b))
    return d, [d / src_lea.name, d / src_dat.name]


def test_inconsistent_record_length(cli, scene, tmp_path):
    _, lea, dat = scene

    def flip_replica_bit(b):  # line 1: claims a replica its length does not hold
        b[16252 + 192 + 49] |= 0x40

    d, paths = corrupt(tmp_path, lea, dat, edit_dat=flip_replica_bit)
    one_line_error(run_unchanged(cli, paths, "ingest", d, "-o", tmp_path / "o.h5"),
                   "inconsistent record length at line 1")

    def bad_header(b):  # line 2's header length off by 2: the walk lands inside a record
        off = 16252 + 242 + 192
        b[off + 8:off + 12] = (242 + 192 + 2).to_bytes(4, "big")

    d, paths = corrupt(tmp_path, lea, dat, edit_dat=bad_header)
    line = one_line_error(cli("ingest", d, "-o", tmp_path / "o.h5"))
    assert any(k in line for k in ("inconsistent record length at line 2", "not a signal data record", "corrupt"))


def test_garbage_numbers_in_ascii_fields(cli, scene, tmp_path):
    _, lea, dat = scene

    def garbage_wavelength(b):
        b[720 + 500:720 + 516] = b"    0.05x5646147"

    d, paths = corrupt(tmp_path, lea, dat, edit_lea=garbage_wavelength)
    one_line_error(run_unchanged(cli, paths, "ingest", d, "-o", tmp_path / "o.h5"),
                   "wavelength", "501-516", "not a number")

    def garbage_count(b):
        b[180:186] = b"  12a4"

    d, paths = corrupt(tmp_path, lea, dat, edit_dat=garbage_count)
    one_line_error(cli("ingest", d, "-o", tmp_path / "o.h5"), "number of SAR data records", "not an integer")


def test_missing_state_vectors(cli, scene, tmp_path):
    _, lea, dat = scene

    def drop_platform(b):
        del b[720 + 4096:]

    d, paths = corrupt(tmp_path, lea, dat, edit_lea=drop_platform)
    one_line_error(run_unchanged(cli, paths, "ingest", d, "-o", tmp_path / "o.h5"), "missing state vectors")

    def blank_vector(b):
        start = 720 + 4096 + 386 + 132 * 3
        b[start:start + 22] = b" " * 22

    d, paths = corrupt(tmp_path, lea, dat, edit_lea=blank_vector)
    one_line_error(cli("ingest", d, "-o", tmp_path / "o.h5"), "state vector 4 component 1", "blank")

    def cut_platform(b):  # the platform position record ends early
        del b[720 + 4096 + 3000:]

    d, paths = corrupt(tmp_path, lea, dat, edit_lea=cut_platform)
    one_line_error(cli("ingest", d, "-o", tmp_path / "o.h5"), "claims 8960 bytes", "truncated or corrupt")

    def one_vector(b):
        b[720 + 4096 + 140:720 + 4096 + 144] = b"   1"

    d, paths = corrupt(tmp_path, lea, dat, edit_lea=one_vector)
    one_line_error(cli("ingest", d, "-o", tmp_path / "o.h5"), "1 state vectors")


def test_bad_options(cli, scene, tmp_path):
    _, lea, _ = scene
    one_line_error(cli("ingest", lea.parent, "-o", tmp_path / "o.h5", "--missing", "guess"), "policy")
    one_line_error(cli("ingest", "-o", tmp_path / "o.h5"), "give LEADER DATA")
    one_line_error(cli("ingest", "--matlab", lea, "-o", tmp_path / "o.h5"), "--params")
