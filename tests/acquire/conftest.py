"""Fixtures for acquisition tests: emulated instruments on pseudo-terminals, a small test scene,
a fast acquisition config (short timeouts, no settling), and a reference scan to compare against."""

from __future__ import annotations

from pathlib import Path

import pytest

from sarcli.acquire.emulator import Emulator, scene_source

SCENE = """
[scene]
name = "acq-test"
seed = 7
epoch_utc = "2026-01-01T00:00:00Z"

[sweep]
center_frequency_hz = 5.3e9
bandwidth_hz = 600e6
points = 201
polarizations = ["HH", "VV"]

[rail]
length_m = 1.0
step_m = 0.05
height_m = 1.5

[[points]]
x_m = -0.3
y_m = 4.0
z_m = 1.5
scattering = { HH = 1.0, VV = 0.8, VH = 0.1, HV = 0.1 }

[[points]]
x_m = 0.25
y_m = 6.5
z_m = 1.5
scattering = { HH = 0.7, VV = 1.0, VH = 0.2, HV = 0.2 }
"""

# 21 stops x 201 points x 2 polarizations on a 1 m rail centred on the scene's origin;
# GRBL X0 sits at rail-frame -0.5 m. Timeouts are short so that fault tests stay fast.
CONFIG = """
[vna]
start_hz = 5.0e9
stop_hz = 5.6e9
points = 201
if_bandwidth_hz = 1000
data_format = "FORM2"
read_timeout_ms = 40
opc_read_timeout_ms = 100
read_margin_s = 0.08
data_timeout_s = 0.15
retries = 3

[rail]
start_m = -0.5
step_m = 0.05
count = 21
settle_s = 0.0
feed_mm_min = 500.0
max_travel_m = 1.5
machine_zero_m = -0.5
height_m = 1.5
retries = 2
timeout_s = 0.5

[polarization]
polarizations = ["HH", "VV"]
switch = "grbl"
settle_s = 0.0
"""

MACHINE_ZERO_M = -0.5
HEIGHT_M = 1.5


@pytest.fixture
def scene_path(tmp_path: Path) -> Path:
    p = tmp_path / "scene.toml"
    p.write_text(SCENE)
    return p


@pytest.fixture
def config_path(tmp_path: Path) -> Path:
    p = tmp_path / "scan.toml"
    p.write_text(CONFIG)
    return p


@pytest.fixture
def emulator(scene_path: Path):
    """Factory: ``emulator(faults="garble@3", switch="grbl", ...)`` -> a started Emulator (stopped after)."""
    started: list[Emulator] = []

    def make(**kw) -> Emulator:
        kw.setdefault("switch", "grbl")
        kw.setdefault("machine_zero_m", MACHINE_ZERO_M)
        kw.setdefault("grbl_settings", {130: 1500.0})
        if "source" not in kw:
            kw["source"] = scene_source(str(scene_path), HEIGHT_M)
        emu = Emulator(**kw).start()
        started.append(emu)
        return emu

    yield make
    for emu in started:
        emu.stop()


def scan_args(emu: Emulator, config: Path, *extra: str) -> list[str]:
    return ["gbsar", "scan", "--port", emu.vna_port, "--rail-port", emu.rail_port, "-c", str(config), *extra]
