"""attitude: platform pitch and yaw (degrees in [attitude]) steer the beam and move the Doppler centroid.

Angles are applied on top of the zero-Doppler reference attitude (``sarcli.sim.pointing``):
R = Rz(yaw) Ry(pitch). Roll is part of the antenna look angle ([antenna] look_angle_deg).
"""

import math
from dataclasses import dataclass

NAME = "attitude"
DOC = "pitch/yaw pointing of the beam (moves the Doppler centroid)"


@dataclass(frozen=True)
class Options:
    """pitch_deg, yaw_deg: platform pitch and yaw (degrees)."""

    pitch_deg: float = 0.0
    yaw_deg: float = 0.0


def parse(options, platform):
    o = options or Options()
    return (math.radians(o.pitch_deg), math.radians(o.yaw_deg))


def configure(ctx, params):
    ctx.pitch_rad, ctx.yaw_rad = params
