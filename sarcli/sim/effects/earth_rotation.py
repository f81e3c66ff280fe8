"""earth_rotation: targets are fixed to the rotating Earth (ECEF); without it the scene is inertial.

Inertial scene: every target keeps its ECI position at the scene-centre time. With Earth
rotation, p_eci(t) = Rz(theta(t))^T p_ecef with theta the GMST angle (orbit.frames).
"""

from sarcli.errors import ConfigError
from sarcli.sim.effects import switch

NAME = "earth_rotation"
DOC = "targets fixed to the rotating Earth (else inertial)"


def parse(options, platform):
    from sarcli.sim.scene import LinearPlatform

    if isinstance(platform, LinearPlatform):
        raise ConfigError("effect earth_rotation needs an orbit or state_vectors platform (flat-Earth scene)")
    return None


configure = switch("earth_rotation")
