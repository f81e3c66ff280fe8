"""Fixtures for the NISAR tests: the real ALOS-1 L0B cut (skipped LOUDLY when ../shared is absent) and
a simulated point-target SLC written as a NISAR RSLC."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))  # synth.py (plain h5py writers)

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("SARCLI_SHARED", REPO.parent / "shared"))
L0B_NAME = "ALPSRP264757150-H1.0__A_HH_LINE4000-5000_RANGE0-2200.h5"
SCENE = Path(__file__).parent / "scenes" / "cr_points.toml"


@pytest.fixture(scope="session")
def l0b_path() -> Path:
    p = SHARED / "data" / "alos_palsar_l0b" / L0B_NAME
    if not p.is_file():
        pytest.skip(f"REAL-DATA TESTS NOT RUN: {p} is absent (the ALOS-1 PALSAR L0B cut of ../shared/data)")
    return p


@pytest.fixture(scope="session")
def l0b_raw(l0b_path):
    from sarcli.io.nisar.l0b import read_l0b

    c = read_l0b(l0b_path)
    assert list(c.products) == ["A_HH"]
    return c.products["A_HH"]


@pytest.fixture(scope="session")
def sim_slc():
    """Three point targets (Radarsat-1-like orbit, rotating Earth, uniform beam of 0.5 first-null
    half-width: a 992 Hz Doppler band inside the 1257 Hz PRF), focused by the RDA with the scene's
    geometric Doppler (truth) over 900 Hz of azimuth band (inside the illuminated band: the IRF is the
    window's). Noise-free, so the IRWs are the theory's."""
    from sarcli.focus.rda import focus_rd
    from sarcli.model.doppler import GeometricDoppler
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    raw = simulate(load_scene(SCENE))
    r = raw.slant_range()
    k = r.size // 2
    dop = GeometricDoppler.from_centroid_and_rate(float(raw.truth["doppler_centroid_hz"][k]),
                                                  float(raw.truth["doppler_rate_hz_per_s"][k]), float(r[k]),
                                                  raw.radar.wavelength_m)
    return focus_rd(raw, dop, azimuth_bandwidth_hz=900.0)


@pytest.fixture(scope="session")
def sim_rslc(sim_slc, tmp_path_factory) -> Path:
    from sarcli.workflows.export import write_format

    p = tmp_path_factory.mktemp("rslc") / "sim_rslc.h5"
    write_format(sim_slc, p, "nisar-rslc", {"polarization": "HH"})
    return p


@pytest.fixture(scope="session")
def sim_reflectors_csv(sim_slc, tmp_path_factory) -> Path:
    """A NISAR-format CSV of the simulated targets (their WGS-84 positions from the truth)."""
    from sarcli.calibration.reflectors import CornerReflector, write_reflectors

    tg = sim_slc.truth["targets"]
    crs = [CornerReflector(f"T{int(t['id'])}", float(t["lat_deg"]), float(t["lon_deg"]), float(t["height_m"]),
                           180.0, 10.0, 2.8, "2002-01-01T00:00:00.000000Z", 7, (0.0, 0.0, 0.0)) for t in tg]
    p = tmp_path_factory.mktemp("cr") / "targets.csv"
    write_reflectors(p, crs)
    return p

