"""What the listed effects switched on: the single object effects configure and the simulator reads.

Defaults are the "effect absent" physics: range envelope frozen at closest approach, inertial
scene, zero attitude (beam perpendicular to the platform velocity, see ``sarcli.sim.pointing``),
uniform illumination inside the processed beam, one receive channel, static targets.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from sarcli.sim.scene import Scene


@dataclass
class SimContext:
    scene: Scene
    range_migration: bool = False
    earth_rotation: bool = False
    antenna_pattern: bool = False
    target_motion: bool = False
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    receiver_offsets_m: tuple[float, ...] = (0.0,)

    def rng(self, stream: str) -> np.random.Generator:
        """An independent generator per named stream, all derived from the scene seed."""
        return np.random.default_rng([self.scene.seed, zlib.crc32(stream.encode())])
