"""Truth arrays against closed forms; the explicit state-vector platform against the orbit platform."""

from __future__ import annotations

import numpy as np

from orbit.frames import eci_to_ecef
from orbit.propagate import kepler_to_state, propagate_j2
from sarcli.sim.scene import parse_scene
from sarcli.sim.stripmap import simulate
from tests.sim.conftest import orbit_scene_text


def test_flat_earth_doppler_truth_closed_form_and_undefined_ranges(linear_scene):
    raw = simulate(linear_scene(effects=(), first_range=9900.0, n_lines=8))
    rho = raw.slant_range()
    fdc, fr = raw.truth["doppler_centroid_hz"], raw.truth["doppler_rate_hz_per_s"]
    below = rho < 10000.0  # shorter than the altitude: never reaches the ground
    assert np.all(np.isnan(fdc[below])) and np.all(np.isfinite(fdc[~below]))
    lam, V = 0.299792458, 2000.0
    assert np.max(np.abs(fdc[~below])) < 1e-9
    assert np.allclose(fr[~below], -2 * V**2 / (lam * rho[~below]), rtol=1e-12)


def test_orbit_doppler_truth_nan_below_the_altitude(orbit_scene):
    raw = simulate(orbit_scene(effects=("earth_rotation",), first_range=790000.0, n_samples=2000,
                               targets="[[targets]]\nslant_range_m = 798000.0\n", n_lines=8, pulse=1e-6))
    fdc = raw.truth["doppler_centroid_hz"]
    bad = np.isnan(fdc)
    assert bad[0] and not bad[-1] and np.all(np.diff(bad.astype(int)) <= 0)  # one NaN block at near range


def test_state_vector_platform_reproduces_the_orbit(tmp_path):
    base = orbit_scene_text(effects=("range_migration", "earth_rotation"), n_lines=200)
    orbit_raw = simulate(parse_scene(base, "a.toml"), dtype=np.complex128)
    sc = parse_scene(base, "a.toml")
    t = np.arange(-120.0, 121.0, 10.0)
    r0, v0 = kepler_to_state(sc.platform.elements)
    r, v = propagate_j2(r0, v0, t)
    re, ve = eci_to_ecef(sc.epoch_utc, t, r, v)
    table = "\n".join([
        "[platform]", 'type = "state_vectors"', 'frame = "ECEF"',
        f"time_s = {t.tolist()}", f"position_m = {re.tolist()}", f"velocity_mps = {ve.tolist()}"])
    start = base.index("[platform]")
    end = base.index("[[targets]]")
    text = base[:start] + table + "\n\n" + base[end:]
    sv_raw = simulate(parse_scene(text, "b.toml"), dtype=np.complex128)
    lit = (np.abs(orbit_raw.echo) > 0) & (np.abs(sv_raw.echo) > 0)
    assert lit.sum() > 1000
    dphi = np.angle(sv_raw.echo[lit] * np.conj(orbit_raw.echo[lit]))
    assert np.max(np.abs(dphi)) < 1e-3  # Hermite interpolation of 10 s vectors: sub-micrometre
    assert sv_raw.orbit.frame == "ECEF" and sv_raw.orbit.time.size == t.size
