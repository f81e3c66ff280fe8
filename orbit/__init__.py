"""orbit: pure geometry for spaceborne SAR (numpy, numba, pyproj; no file formats, no CLI, no sarcli imports).

Conventions: SI units, radians, float64; times are seconds after an ISO-8601 UTC epoch; positions m,
velocities m/s. Frames: "ECI" = the GMST inertial frame of date (true equator, mean equinox; what the
Radarsat-1 CEOS "inertial" vectors plus a Greenwich mean hour angle imply), "ECEF" = WGS-84
Earth-fixed, "LOCAL" = flat-Earth Cartesian (airborne scenes). Errors are ``orbit.errors.OrbitError``
(a ``ValueError``) with one-line messages.

Public API (stable; other modules depend on it):

``orbit.statevectors``
    ``StateVectors(time, position, velocity, frame="ECI", epoch_utc="")`` - validated (sorted, no
    duplicates, finite; non-uniform spacing is fine).
    ``.interpolate(t, n_nodes=None, max_extrapolation_s=0.0) -> (pos, vel, acc)`` - Hermite using
    positions and velocities over ``n_nodes`` (2..16, default ``DEFAULT_N_NODES`` = 10) nodes;
    numba for vectors of t; output shape ``t.shape + (3,)``; outside the span raises
    ``InterpolationRangeError`` unless within ``max_extrapolation_s``.
    ``.to_ecef()`` / ``.to_eci()``, ``.span``, ``.spacing``, ``StateVectors.from_record(obj, epoch)``.
    ``hermite_reference(...)`` - plain-numpy reference of the kernel.
``orbit.frames``
    ``gmst(epoch, t)``, ``eci_to_ecef(epoch, t, r, v=None)``, ``ecef_to_eci(...)``.
``orbit.precession``
    ``j2000_to_eci`` / ``eci_to_j2000`` / ``tod_to_eci`` (IAU 1976/1980) for vectors not in the GMST frame.
``orbit.geodetic``
    ``ecef_to_geodetic(r) -> (lat_deg, lon_deg, h)``, ``geodetic_to_ecef(lat_deg, lon_deg, h)`` (pyproj).
``orbit.pointing``
    ``flight_frame(r, v)`` (geodetic nadir), ``control_rotation(pitch, yaw, exact=True)``,
    ``beam_vector(r, v, look, pitch, yaw, side, exact)``, ``along_track_axis``, ``ellipsoid_normal``.
``orbit.geometry``
    ``target_from_look`` (ray), ``target_from_doppler`` / ``target_from_look_plane`` / ``target_in_plane``
    (range + plane + ellipsoid at height h, Newton), ``look_angle``, ``incidence_angle``,
    ``incidence_from_look``, ``look_from_incidence``, ``slant_range_from_look``, ``look_from_slant_range``,
    ``horizon_look_angle``, ``doppler_hz``, ``doppler_rate_hz_per_s``, ``relative_velocity_eci``,
    ``doppler_from_attitude`` (the fdc_orbit of [Koh2003, §3.1]), ``doppler_time(sv, p, lam, fdc, t_guess=...)``,
    ``geolocate(sv, t, rho, lam, fdc, h, side)``, ``geolocate_geodetic``.
``orbit.propagate``
    ``Keplerian``, ``kepler_to_state``, ``propagate_j2`` (truth orbits for simulation and tests).
``orbit.accuracy``
    the accuracy/cost tables of ``sarcli orbit accuracy`` and ``bench/bench_orbit.py``.
``orbit.constants``, ``orbit.timeutil``, ``orbit.errors``.

Doppler sign: with the phase convention exp(-j*4*pi*R/lam), f_D = -(2/lam) dR/dt
= +(2/lam) v_rel . (p - r)/|p - r| (positive when looking forward); see ``orbit.geometry``.
"""
