"""orbit: pure geometry for spaceborne SAR (no file formats, no CLI, no sarcli imports).

Modules: ``constants`` (WGS-84, Earth rotation), ``timeutil`` (epochs, Julian dates),
``frames`` (ECI <-> ECEF by Greenwich sidereal angle), ``geodetic`` (ECEF <-> lat/lon/h via pyproj),
``propagate`` (Keplerian elements and J2 numerical propagation).
"""
