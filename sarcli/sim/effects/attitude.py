"""attitude: platform pitch and yaw (degrees in [attitude]) steer the beam and move the Doppler centroid.

Angles are applied on top of the zero-Doppler reference attitude (``sarcli.sim.pointing``):
R = Rz(yaw) Ry(pitch). Roll is part of the antenna look angle ([antenna] look_angle_deg).
"""

import math

NAME = "attitude"
DOC = "pitch/yaw pointing of the beam (moves the Doppler centroid)"


def parse(table, platform):
    if table is None:
        return (0.0, 0.0)
    return (math.radians(table.num("pitch_deg", 0.0)), math.radians(table.num("yaw_deg", 0.0)))


def configure(ctx, params):
    ctx.pitch_rad, ctx.yaw_rad = params
