"""Ground-based SAR ([LeeGBSAR-II-2007], [LeeGBSAR-I-2007]): scene simulation, focusing (DF, RD, BP), interferometry.

Local frame of a GB-SAR scene (SI units, right-handed): ``x`` along the rail (increasing rail
position), ``y`` horizontal away from the rail towards the look side, ``z`` up; the rail centre
is at ``x = 0`` and the antenna phase centre of a stop at (x_rail, 0, rail_height).
Focused images live in the slant plane of the rail: azimuth ``x`` and range ``R0``, the distance
of a point from the rail line (``R0 = sqrt(y**2 + (z - h)**2)``). Phase of a scatterer at one-way
range R at frequency f: ``exp(-j*4*pi*f*R/c)``.
"""
