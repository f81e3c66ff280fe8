"""Scene files: parsing, and bad scene files give one clear line (library and CLI)."""

from __future__ import annotations

import pytest

from sarcli.errors import FormatError, SarcliError
from sarcli.sim.effects import known_effects
from sarcli.sim.scene import LinearPlatform, OrbitPlatform, load_scene, parse_scene
from tests.sim.conftest import linear_scene_text, orbit_scene_text

ALL_EFFECTS = ["antenna_pattern", "attitude", "chirp_replica", "earth_rotation", "noise", "quantization",
               "range_migration", "second_channel", "target_motion"]


def test_registry_knows_every_effect():
    assert known_effects() == ALL_EFFECTS


def test_parse_orbit_and_linear():
    s = parse_scene(orbit_scene_text(), "a.toml")
    assert isinstance(s.platform, OrbitPlatform) and s.effects == ("range_migration",)
    assert s.targets[0].where == ("slant", 994000.0, 0.0, 0.0)
    s = parse_scene(linear_scene_text(), "b.toml")
    assert isinstance(s.platform, LinearPlatform) and s.targets[0].where == ("local", 5095.3, 0.0, 0.0)


def test_samples_parse():
    from tests.conftest import SAMPLES

    for name in ("rs1_point.toml", "rs1_clutter.toml", "ati_paper.toml"):
        load_scene(SAMPLES / name)


@pytest.mark.parametrize("text, message", [
    (orbit_scene_text(effects=("range_migration", "sparkle")), "unknown effect 'sparkle'; known effects: antenna"),
    (orbit_scene_text(effects=("noise",)), "noise needs a table [noise]"),
    (orbit_scene_text(effects=("second_channel",)), "second_channel needs a table"),
    (orbit_scene_text(extra="[range_migration]\nstrength = 2\n"),
     "range_migration: effect range_migration takes no options, got strength"),
    (orbit_scene_text(extra="[bogus]\nx = 1\n"), "unknown table(s) bogus"),
    (linear_scene_text(effects=("earth_rotation",)), "earth_rotation needs an orbit"),
    (orbit_scene_text().replace("n_lines = 512", "n_lines = -3"), "radar.n_lines: must be an integer >= 1, got -3"),
    (orbit_scene_text().replace("prf_hz", "prf_hzz"), "radar: unknown option(s) prf_hzz; known: carrier_frequency_hz"),
    (orbit_scene_text().replace("look_angle_deg = 33.5", "look_angle_deg = 33.5\ncolour = 1"),
     "antenna: unknown option(s) colour"),
    (orbit_scene_text().replace("[antenna]", "[antena]"), "missing table [antenna]"),
    (orbit_scene_text().replace('type = "orbit"', 'type = "balloon"'), "'balloon' is not one of orbit"),
    (orbit_scene_text(targets="[[targets]]\nx_m = 1.0\ny_m = 2.0\n"), "orbit scenes place targets by lat_deg"),
    (orbit_scene_text(targets=""), "no [[targets]] and no [[clutter]]"),
    (orbit_scene_text().replace("[scene]", "[scene"), "not valid TOML"),
    (orbit_scene_text().replace("eccentricity = 0.00115", "eccentricity = 1.5"), "platform.eccentricity: must be < 1"),
    (orbit_scene_text().replace("first_range_m = 993400.0", "first_range_m = inf"),
     "radar.first_range_m: expected a finite number, got inf"),
    (orbit_scene_text(effects=("quantization",), extra="[quantization]\nbits = 9\n"),
     "quantization.bits: must be 2..8"),
    (orbit_scene_text(effects=("noise",), extra="[noise]\nsnr_db = 'loud'\n"), "noise.snr_db: expected a number"),
    (orbit_scene_text().replace('first_range_m = 993400.0', 'first_range_m = "far"'),
     "radar.first_range_m: expected a number, got 'far'"),
    (orbit_scene_text().replace("n_samples = 400", ""), "radar: missing required option(s) n_samples"),
    (orbit_scene_text(targets="[[targets]]\nlat_deg = 49.0\n"), "targets[0]: a geodetic position needs both"),
])
def test_bad_scenes_one_line(text, message):
    with pytest.raises(SarcliError) as ei:
        parse_scene(text, "bad.toml")
    msg = str(ei.value)
    assert message in msg and "\n" not in msg and msg.startswith("bad.toml")


def test_unreachable_slant_range_is_one_line(orbit_scene):
    from sarcli.sim.stripmap import simulate

    sc = orbit_scene(targets="[[targets]]\nslant_range_m = 500000.0\n")
    with pytest.raises(FormatError, match="does not reach the ground"):
        simulate(sc)


@pytest.mark.parametrize("content, message", [
    (None, "no such file"),
    ("[scene]\nseed = 1\neffects = ['nope']\n", "missing table [radar]"),
    (orbit_scene_text(effects=("warp_drive",)), "unknown effect 'warp_drive'"),
])
def test_cli_bad_scene_one_line(cli, tmp_path, content, message):
    path = tmp_path / "scene.toml"
    if content is not None:
        path.write_text(content)
    r = cli("simulate", path, "-o", tmp_path / "raw.h5")
    assert r.exit_code != 0
    assert r.stderr.startswith("sarcli: error:") and message in r.stderr
    assert r.stderr.strip().count("\n") == 0 and "Traceback" not in r.stderr
    assert not (tmp_path / "raw.h5").exists()
