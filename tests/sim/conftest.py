"""Small scene builders for the simulator tests (fast: short pulses, short apertures)."""

from __future__ import annotations

import pytest

ORBIT_SCENE = """
[scene]
name = "t_orbit"
seed = {seed}
epoch_utc = "2002-06-16T15:41:00Z"
effects = {effects}

[radar]
carrier_frequency_hz = 5.3e9
prf_hz = 1256.9846363282768
range_sampling_rate_hz = 32317075.0
chirp_rate_hz_per_s = -0.72135e12
pulse_length_s = {pulse}
n_lines = {n_lines}
n_samples = {n_samples}
first_range_m = {first_range}

[antenna]
length_m = {length}
height_m = 1.5
look_angle_deg = 33.5

[platform]
type = "orbit"
semi_major_axis_m = 7167100.0
eccentricity = 0.00115
inclination_deg = 98.594
raan_deg = 20.0
arg_perigee_deg = 90.0
mean_anomaly_deg = -40.3

{targets}
{extra}
"""

LINEAR_SCENE = """
[scene]
name = "t_linear"
seed = {seed}
effects = {effects}

[radar]
carrier_frequency_hz = 1.0e9
prf_hz = 3000.0
range_sampling_rate_hz = 150.0e6
chirp_rate_hz_per_s = 128.0e12
pulse_length_s = 1.0e-6
n_lines = {n_lines}
n_samples = {n_samples}
first_range_m = {first_range}

[antenna]
length_m = {length}
height_m = 0.5
look_angle_deg = 27.0

[platform]
type = "linear"
velocity_mps = 2000.0
height_m = 10000.0

{targets}
{extra}
"""


def _fmt_effects(effects) -> str:
    return "[" + ", ".join(f'"{e}"' for e in effects) + "]"


def orbit_scene_text(effects=("range_migration",), seed=7, pulse=5e-6, n_lines=512, n_samples=400,
                     first_range=993400.0, length=60.0, targets=None, extra="") -> str:
    if targets is None:
        targets = "[[targets]]\nslant_range_m = 994000.0\nazimuth_time_s = 0.0\n"
    return ORBIT_SCENE.format(seed=seed, effects=_fmt_effects(effects), pulse=pulse, n_lines=n_lines,
                              n_samples=n_samples, first_range=first_range, length=length, targets=targets,
                              extra=extra)


def linear_scene_text(effects=("range_migration",), seed=7, n_lines=512, n_samples=600, first_range=11150.0,
                      length=4.0, targets=None, extra="") -> str:
    if targets is None:
        targets = "[[targets]]\nx_m = 5095.3\ny_m = 0.0\n"
    return LINEAR_SCENE.format(seed=seed, effects=_fmt_effects(effects), n_lines=n_lines, n_samples=n_samples,
                               first_range=first_range, length=length, targets=targets, extra=extra)


@pytest.fixture
def orbit_scene():
    from sarcli.sim.scene import parse_scene

    def make(**kw):
        return parse_scene(orbit_scene_text(**kw), "t_orbit.toml")
    return make


@pytest.fixture
def linear_scene():
    from sarcli.sim.scene import parse_scene

    def make(**kw):
        return parse_scene(linear_scene_text(**kw), "t_linear.toml")
    return make
