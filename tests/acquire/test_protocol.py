"""Protocol conformance: the exact bytes the drivers put on the wire, checked against the documented
Prologix / 8753ES / GRBL 1.1 protocols (docs: shared gbsar-instruments.md), plus parser properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sarcli.acquire.config import load_config
from sarcli.acquire.controller import connect, run_scan, scan_template
from sarcli.acquire.emulator.faults import FaultPlan
from sarcli.acquire.emulator.vna import binary_block, fmt_number, form4_block
from sarcli.acquire.errors import GarbledData
from sarcli.acquire.grbl import parse_status
from sarcli.acquire.motion import move_time, position_at
from sarcli.acquire.prologix import escape, unescape_split
from sarcli.acquire.vna8753 import parse_binary, parse_binary_header, parse_form4
from sarcli.io.scan import ScanWriter


@pytest.fixture
def scanned(emulator, config_path, tmp_path):
    """A 3-stop, 2-polarization scan through the library, with the client's wire log."""
    emu = emulator()
    cfg = load_config(config_path, {"rail": {"count": 3}})
    inst = connect(cfg, emu.vna_port, emu.rail_port)
    for p in inst.ports:
        p.log_writes = True
    w = ScanWriter.create(tmp_path / "p.h5", scan_template(cfg, inst.identity, "2026-01-01T00:00:00Z"), 3)
    res = run_scan(cfg, inst, w, "2026-01-01T00:00:00Z")
    assert res.status == "complete", res.error
    yield emu, inst
    inst.close()


def test_prologix_init_sequence(scanned):
    emu, _ = scanned
    adapter = [m.decode() for m in emu.vna.log if m.startswith(b"++")]
    # savecfg 0 first (no EEPROM writes), controller mode, no auto-read, EOI, LF appended, timeout
    assert adapter[:8] == ["++savecfg 0", "++mode 1", "++auto 0", "++eoi 1", "++eos 2", "++read_tmo_ms 40",
                           "++addr 16", "++ver"]
    reads = [a for a in adapter if a.startswith("++read ")]
    assert reads and set(reads) == {"++read eoi"}


def test_vna_commands_and_opc(scanned):
    emu, inst = scanned
    data = [m for m in emu.vna.log if not m.startswith(b"++")]
    # every instrument message ends with ';' + the LF the adapter appends (++eos 2)
    assert all(m.endswith(b";\n") for m in data)
    assert data[0] == b"IDN?;\n" and data[1] == b"OUTPOPTS;\n"
    assert b"OPC?;PRES;\n" in data
    assert b"CHAN1;LINFREQ;S21;POLA;HOLD;AVERO0;FORM2;\n" in data
    assert b"STAR 5000000000HZ;STOP 5600000000HZ;POIN201;IFBW1000;POWE 0;SOUP1;\n" in data
    for q in (b"STAR?;\n", b"STOP?;\n", b"POIN?;\n", b"IFBW?;\n", b"POWE?;\n", b"S21?;\n", b"SWET?;\n",
              b"OUTPERRO;\n"):
        assert q in data
    # per polarization: OPC?;SING, the adapter timeout raised to the OPC value and back, a read for the
    # '1', then OUTPDATA and its read
    log = emu.vna.log
    sings = [i for i, m in enumerate(log) if m == b"OPC?;SING;\n"]
    assert len(sings) == 3 * 2
    for i in sings:
        assert log[i + 1:i + 5] == [b"++read_tmo_ms 100", b"++read eoi", b"++read_tmo_ms 40", b"OUTPDATA;\n"]
        assert log[i + 5] == b"++read eoi"
    # the wire bytes of an instrument message are the escaped payload + LF
    wire = inst.ports[0].sent
    assert b"OPC?;SING;\n" in wire and b"OUTPDATA;\n" in wire


def test_grbl_lines_and_finish_check(scanned):
    emu, inst = scanned
    log = emu.grbl.log
    assert log[0] == "\x18"  # soft reset first, then the identification and settings
    lines = [x for x in log if len(x) != 1]
    assert lines[:3] == ["$I", "$$", "G21 G90"]
    moves = [i for i, x in enumerate(log) if x.startswith("G1 ")]
    assert [log[i] for i in moves] == ["G1 X0.000 F500", "G1 X50.000 F500", "G1 X100.000 F500"]
    for i in moves:
        assert log[i + 1] == "G4 P0.01" and log[i + 2] == "?"  # finish = dwell ok, then status Idle + MPos
        assert log[i - 1] == "?"  # the start position is read before the move (timeout estimate)
    # polarization outputs: TX on M8/M9, RX on M3/M5
    assert {"M8", "M9", "M3 S1000", "M5"} <= set(lines)
    # every line is sent with LF only (no CR that GRBL would answer with a second ok)
    assert all(b"\r" not in w for w in inst.ports[1].sent)


def test_binary_upload_is_escaped_through_the_prologix(emulator, config_path):
    emu = emulator()
    cfg = load_config(config_path, {"rail": {"count": 1}})
    inst = connect(cfg, emu.vna_port, emu.rail_port)
    try:
        vals = np.zeros(201, np.complex128)
        # float32 big-endian bit patterns made of the special bytes CR, LF, ESC and '+'
        specials = np.frombuffer(bytes([0x0D, 0x0A, 0x1B, 0x2B] * 2), ">f4")
        vals[:2] = specials[0] + 1j * specials[1]
        vals[5] = np.frombuffer(b"\x2b\x2b\x0a\x0d", ">f4")[0]
        inst.ports[0].log_writes = True
        inst.vna.upload_data(vals)
        wire = inst.ports[0].sent[-1]
        payload = np.empty((201, 2), ">f4")
        payload[:, 0], payload[:, 1] = vals.real, vals.imag
        raw = b"INPUDATA#A" + (201 * 8).to_bytes(2, "big") + payload.tobytes() + b";"
        assert wire == escape(raw) + b"\n"
        assert all(wire[i - 1] == 0x1B for i, b in enumerate(wire[:-1]) if b in (0x0A, 0x0D) and i > 0)
        back = inst.vna.read_data()
        np.testing.assert_array_equal(back, vals.astype(np.complex64))
        assert inst.vna.errors() == []
    finally:
        inst.close()


@settings(max_examples=200, deadline=None)
@given(st.lists(st.binary(min_size=1, max_size=40), min_size=1, max_size=5))
def test_escape_roundtrip(chunks):
    stream = b"".join(escape(c) + b"\n" for c in chunks)
    lines, rest = unescape_split(stream)
    assert rest == b"" and lines == [(c, False) for c in chunks]


def test_adapter_lines_are_recognised():
    lines, rest = unescape_split(b"++addr 16\nS21?;\n\x1b+\x1b+x\n++rea")
    assert lines == [(b"++addr 16", True), (b"S21?;", False), (b"++x", False)] and rest == b"++rea"


@settings(max_examples=100, deadline=None)
@given(st.lists(st.complex_numbers(max_magnitude=1e30, allow_nan=False, allow_infinity=False), min_size=1,
                max_size=30))
def test_form4_and_binary_roundtrip(vals):
    z = np.array(vals, np.complex128)
    np.testing.assert_allclose(parse_form4(form4_block(z), z.size), z, rtol=1e-15, atol=0)
    blk = binary_block(z, "FORM3")
    n = parse_binary_header(blk[:4], z.size * 16)
    np.testing.assert_array_equal(parse_binary(blk[4:4 + n], z.size, ">f8"), z)


def test_number_field_layout():
    assert fmt_number(-1.5) == "-1.500000000000000E+00".rjust(24) and len(fmt_number(2e-7)) == 24
    z = np.array([1.5 - 2e-7j, -0.0 + 3.25e12j, 1e-300 - 1e300j])
    assert form4_block(z) == "".join(f"{fmt_number(v.real)},{fmt_number(v.imag)}\n" for v in z).encode()


@pytest.mark.parametrize("bad", [b"1,2\n3,x\n", b"1,2\n3\n", b"1,2\n", b"1,2\nnan,1\n"])
def test_form4_garbage_is_detected(bad):
    with pytest.raises(GarbledData):
        parse_form4(bad, 2)


def test_binary_header_checks():
    with pytest.raises(GarbledData):
        parse_binary_header(b"#B\x00\x10", 16)
    with pytest.raises(GarbledData):
        parse_binary_header(b"#A\x00\x08", 16)
    assert parse_binary_header(b"#A\x32\x08", 12808) == 12808  # 1601 points in FORM2


@pytest.mark.parametrize("line, state, x", [
    ("<Idle|MPos:50.000,0.000,0.000|FS:0,0>", "Idle", 50.0),
    ("<Run|MPos:12.345,0.000,0.000|FS:500,0|WCO:0.000,0.000,0.000>", "Run", 12.345),
    ("<Hold:0|MPos:-3.000,0.000,0.000|Bf:15,128|FS:0,0|Ov:100,100,100>", "Hold:0", -3.0),
    ("<Alarm|WPos:1.000,2.000,3.000|F:0>", "Alarm", 1.0),
])
def test_status_parsing(line, state, x):
    s = parse_status(line)
    assert s.state == state and s.x_mm == x


@pytest.mark.parametrize("line", ["<Idle|MPos:50.0", "Idle|MPos:1,0,0>", "<Idle|FS:0,0>", "<Idle|MPos:a,0,0>"])
def test_status_garbage(line):
    with pytest.raises(GarbledData):
        parse_status(line)


@settings(max_examples=100, deadline=None)
@given(d=st.floats(0.001, 2000), v=st.floats(1, 500), a=st.floats(1, 2000))
def test_trapezoid_time_and_profile(d, v, a):
    """Time from the closed form equals the time the profile needs; the profile is monotonic and its
    numerical speed never exceeds v."""
    t = move_time(d, v, a)
    ts = np.linspace(0, t, 401)
    x = np.array([position_at(ti, 0.0, d, v, a) for ti in ts])
    assert math.isclose(x[-1], d, rel_tol=1e-9) and np.all(np.diff(x) >= -1e-9)
    assert np.max(np.diff(x) / np.diff(ts)) <= v * (1 + 1e-6)
    assert position_at(0.99 * t, 0.0, d, v, a) < d  # not there before the closed-form time


def test_fault_plan_parsing_and_counting():
    plan = FaultPlan.parse("garble@2, alarm@1:9 ,slow-sweep@3")
    assert plan.event("data") == {} and plan.event("data") == {"garble": 0.0}
    assert plan.event("move") == {"alarm": 9.0}
    assert [plan.event("sweep") for _ in range(3)][-1] == {"slow-sweep": 4.0}
    assert plan.fired == ["garble@2", "alarm@1", "slow-sweep@3"]


def test_locked_rail_is_unlocked_and_homed(cli, emulator, config_path, tmp_path):
    """GRBL with homing enabled starts in Alarm ('$H'|'$X' to unlock): the driver unlocks, homes when
    configured, then scans."""
    config_path.write_text(config_path.read_text().replace("[rail]\n", "[rail]\nhome = true\n"))
    emu = emulator(start_locked=True, grbl_settings={130: 1500.0, 22: 1.0})
    r = cli("gbsar", "scan", "--port", emu.vna_port, "--rail-port", emu.rail_port, "-c", config_path,
            "-o", tmp_path / "h.h5", "--count", "2")
    assert r.exit_code == 0, r.stderr
    lines = [x for x in emu.grbl.log if len(x) != 1]
    assert lines.index("$X") < lines.index("$H") < lines.index("G1 X0.000 F500")


def test_homing_disabled_is_refused(cli, emulator, config_path, tmp_path):
    config_path.write_text(config_path.read_text().replace("[rail]\n", "[rail]\nhome = true\n"))
    emu = emulator()  # $22 = 0
    r = cli("gbsar", "scan", "--port", emu.vna_port, "--rail-port", emu.rail_port, "-c", config_path,
            "-o", tmp_path / "h.h5")
    assert r.exit_code == 3 and "error:5 (homing not enabled)" in r.stderr
    assert not any(x.startswith("G1") for x in emu.grbl.log) and not (tmp_path / "h.h5").exists()


@pytest.mark.parametrize("change, words", [
    ({"points": 300}, "VNA refused the settings: 2,\"INVALID NUMBER OF POINTS\""),
    ({"if_bandwidth_hz": 500.0}, "INVALID IF BANDWIDTH"),
    ({"power_dbm": 20.0}, "POWE? reads back 10, expected 20"),   # the analyzer clamps
    ({"stop_hz": 7e9}, "STOP? reads back 6e+09, expected 7e+09"),
])
def test_vna_error_queue_and_readback(emulator, config_path, change, words):
    """Settings the analyzer rejects (error queue) or changes (clamping) are caught by the driver
    even when they bypass the configuration checks."""
    from dataclasses import replace

    from sarcli.acquire.errors import InstrumentError

    emu = emulator()
    cfg = load_config(config_path)
    inst = connect(cfg, emu.vna_port, emu.rail_port)
    try:
        with pytest.raises(InstrumentError, match=words.replace("?", r"\?").replace("+", r"\+")):
            inst.vna.configure(replace(cfg.vna_settings(), **change))
        assert inst.vna.errors() == []  # drained
    finally:
        inst.close()
