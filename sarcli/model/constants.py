"""Physical constants (SI) for all of sarcli: one definition each, in ``orbit.constants``.

Code in ``sarcli`` imports them from here (``from sarcli.model.constants import C_LIGHT``).
"""

from orbit.constants import C_LIGHT, GM_EARTH, J2_EARTH, OMEGA_EARTH, WGS84_A, WGS84_B, WGS84_E2, WGS84_F

__all__ = ["C_LIGHT", "GM_EARTH", "J2_EARTH", "OMEGA_EARTH", "WGS84_A", "WGS84_B", "WGS84_E2", "WGS84_F"]
