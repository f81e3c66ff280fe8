"""End to end: the real CLI scans the emulated instruments through pseudo-terminals; the file is a
valid scan whose data equal the GB-SAR simulator's at the measured stops and whose focused image
shows the scene's targets where they are."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.gbsar.scene import load_scene
from sarcli.gbsar.simulate import simulate_stop
from sarcli.io.scan import read_scan
from sarcli.model.constants import C_LIGHT
from tests.acquire.conftest import HEIGHT_M, scan_args


def simulated(scene_path, scan):
    sc = load_scene(scene_path)
    return np.stack([simulate_stop(sc, x, HEIGHT_M, scan.frequency, scan.polarizations)
                     for x in scan.rail_position], axis=1)


def test_full_scan_matches_simulator_and_focuses(cli, emulator, config_path, scene_path, tmp_path):
    emu = emulator()
    out = tmp_path / "scan.h5"
    r = cli(*scan_args(emu, config_path, "-o", out, "--json"))
    assert r.exit_code == 0, r.stderr
    s = read_scan(out)
    assert s.status == "complete" and s.source == "measured" and s.n_stops == 21
    assert s.s21.shape == (2, 21, 201) and s.polarizations == ("HH", "VV")
    np.testing.assert_allclose(s.rail_position, -0.5 + 0.05 * np.arange(21), atol=1e-12)
    np.testing.assert_allclose(s.frequency, np.linspace(5.0e9, 5.6e9, 201))
    assert np.all(s.rail_height == HEIGHT_M) and np.all(np.diff(s.stop_time) >= 0)
    assert s.instrument["vna_model"] == "8753ES" and "Grbl 1.1h" in s.instrument["rail_banner"]
    # FORM2 carries float32: the file equals the simulator to float32 rounding
    ref = simulated(scene_path, s)
    np.testing.assert_allclose(s.s21, ref, rtol=0, atol=2e-6 * np.abs(ref).max())

    # focus with a plain-numpy backprojection (independent of the acquisition code): the two
    # targets appear at their true (x, slant range) within a resolution cell
    for ip, pol in enumerate(s.polarizations):
        for tx, ty in ((-0.3, 4.0), (0.25, 6.5)):
            X, R, a = backprojection(s.s21[ip], s.frequency, s.rail_position, tx, ty)
            i = np.unravel_index(np.argmax(a), a.shape)
            assert abs(X[i] - tx) <= 0.03 and abs(R[i] - ty) <= 0.03, (pol, X[i], R[i])

    # and with the project's GB-SAR focusing (backprojection onto a slant-plane grid)
    from sarcli.gbsar.focus import FocusOptions, Grid, focus_scan

    grid = Grid(ranges=np.arange(3.0, 7.5, 0.025), azimuths=np.arange(-1.0, 1.0, 0.025))
    foc = focus_scan(s, FocusOptions(algorithm="bp", max_range_m=8.0), grid)
    for ip, pol in enumerate(s.polarizations):
        a = np.abs(foc.image[ip])
        for tx, ty in ((-0.3, 4.0), (0.25, 6.5)):
            near = (np.abs(grid.ranges[:, None] - ty) < 0.4) & (np.abs(grid.azimuths[None, :] - tx) < 0.3)
            i, j = np.unravel_index(np.argmax(np.where(near, a, 0)), a.shape)
            assert abs(grid.azimuths[j] - tx) <= 0.05 and abs(grid.ranges[i] - ty) <= 0.05, (pol, i, j)


def backprojection(s21, f, x, xc, rc, half=0.3, n=61, n_fft=8192):
    """|image| on an n x n grid around (xc, rc): IFFT range profiles, linear interpolation in range,
    phase compensation exp(+j 4 pi f0 d / c) (targets at antenna height: slant range = y)."""
    df = f[1] - f[0]
    prof = np.fft.ifft(s21 * np.hanning(f.size), n=n_fft, axis=1)  # bin m <-> range m*c/(2*n_fft*df)
    r_axis = np.arange(n_fft) * C_LIGHT / (2 * n_fft * df)
    X, R = np.meshgrid(np.linspace(xc - half, xc + half, n), np.linspace(rc - half, rc + half, n), indexing="ij")
    img = np.zeros(X.shape, np.complex128)
    for k in range(x.size):
        d = np.sqrt((X - x[k]) ** 2 + R**2)
        # the profile of a target at d carries exp(-j 4 pi f0 d / c) with f0 = f[0]
        p = np.interp(d, r_axis, prof[k].real) + 1j * np.interp(d, r_axis, prof[k].imag)
        img += p * np.exp(4j * np.pi * f[0] * d / C_LIGHT)
    return X, R, np.abs(img)


@pytest.mark.parametrize("fmt", ["FORM4", "FORM3"])
def test_data_formats(cli, emulator, config_path, scene_path, tmp_path, fmt):
    emu = emulator()
    out = tmp_path / "s.h5"
    r = cli(*scan_args(emu, config_path, "-o", out, "--count", "3", "--data-format", fmt))
    assert r.exit_code == 0, r.stderr
    s = read_scan(out)
    ref = simulated(scene_path, s)
    # FORM4 has 16 significant digits and FORM3 is float64: only the file's complex64 rounds
    np.testing.assert_allclose(s.s21, ref.astype(np.complex64), rtol=0, atol=1e-7 * np.abs(ref).max())


def test_full_polarimetric_with_11713a(cli, emulator, config_path, scene_path, tmp_path):
    emu = emulator(switch="11713a")
    out = tmp_path / "quad.h5"
    r = cli(*scan_args(emu, config_path, "-o", out, "--count", "2", "--pol", "VV,VH,HV,HH", "--switch", "11713a"))
    assert r.exit_code == 0, r.stderr
    s = read_scan(out)
    assert s.polarizations == ("VV", "VH", "HV", "HH")
    ref = simulated(scene_path, s)
    np.testing.assert_allclose(s.s21, ref, rtol=0, atol=2e-6 * np.abs(ref).max())
    # the 11713A got listen-only switch strings on GPIB 28: S9 = TX, S0 = RX
    sent = [m for m in emu.vna.log if not m.startswith(b"++")]
    assert b"B90\n" in sent and b"A9B0\n" in sent and b"A0B9\n" in sent and b"A90\n" in sent
