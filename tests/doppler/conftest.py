"""Simulated Radarsat-1-like scenes for the Doppler tests (small; cached per session by scene text)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

SCENES = Path(__file__).parent / "scenes"
_CACHE: dict[str, object] = {}


def scene_text(pitch_deg: float = 0.0, yaw_deg: float = 0.0, n_lines: int | None = None,
               density: float | None = None, azimuth_extent_m: float | None = None, seed: int | None = None,
               extra_effects: tuple[str, ...] = (),
               extra: str = "") -> str:
    """The base clutter scene with attitude / size / density / seed / effects replaced."""
    t = (SCENES / "rs1_clutter.toml").read_text()
    t = re.sub(r"(?m)^pitch_deg = .*$", f"pitch_deg = {pitch_deg!r}", t)
    t = re.sub(r"(?m)^yaw_deg = .*$", f"yaw_deg = {yaw_deg!r}", t)
    if n_lines is not None:
        t = re.sub(r"(?m)^n_lines = .*$", f"n_lines = {n_lines}", t)
    if density is not None:
        t = re.sub(r"(?m)^density_per_m2 = .*$", f"density_per_m2 = {density!r}", t)
    if azimuth_extent_m is not None:
        t = re.sub(r"(?m)^azimuth_extent_m = .*$", f"azimuth_extent_m = {azimuth_extent_m!r}", t)
    if seed is not None:
        t = re.sub(r"(?m)^seed = .*$", f"seed = {seed}", t)
    if extra_effects:
        t = t.replace('"noise"]', '"noise", ' + ", ".join(f'"{e}"' for e in extra_effects) + "]")
    return t + extra


def simulate_text(text: str):
    """RawProduct of a scene text (cached)."""
    if text not in _CACHE:
        from sarcli.sim.scene import parse_scene
        from sarcli.sim.stripmap import simulate

        _CACHE[text] = simulate(parse_scene(text, "doppler-test-scene"))
    return _CACHE[text]


@pytest.fixture(scope="session")
def clutter_raw():
    """The base scene (512 x 384, zero attitude)."""
    return simulate_text(scene_text())
