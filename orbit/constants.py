"""Physical constants (SI). WGS-84 ellipsoid; Earth rotation rate is the sidereal rate of GMST."""

C_LIGHT = 299_792_458.0  # m/s
WGS84_A = 6_378_137.0  # semi-major axis, m
WGS84_F = 1.0 / 298.257223563  # flattening
WGS84_B = WGS84_A * (1.0 - WGS84_F)  # semi-minor axis, m
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)  # first eccentricity squared
GM_EARTH = 3.986004418e14  # m^3/s^2 (WGS-84 / EGM96)
J2_EARTH = 1.08262668e-3  # EGM96 unnormalized J2
OMEGA_EARTH = 7.2921158553e-5  # rad/s, Earth rotation w.r.t. the mean equinox of date (dGMST/dt)
