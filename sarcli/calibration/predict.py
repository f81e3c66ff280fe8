"""Where a corner reflector should appear in a zero-Doppler image, and what else moves it.

Prediction: the reflector's ECEF position at the acquisition (``reflectors.position_at``), its
zero-Doppler time t0 and closest slant range R0 on the product's orbit (``orbit.geometry.doppler_time``:
Newton on v(t).(p - r(t)) = 0 with the Hermite-interpolated state vectors), then the pixel
``row = (t0 - t[0]) / dt``, ``col = (R0 - r[0]) / dr``. The reflector must be on the product's look
side (the sign of (p - r).Yf, Yf = nadir x v the right-hand flight axis).

Along-track spacing at the reflector: the zero-Doppler ground points of (t0 +- k dt, R0) at the
reflector's height are ``2 k ds`` apart (ds metres per line); the ground-track speed is ds / dt.

Corrections not in the geometry (a metre-level offset is only a geometry error after them):

- troposphere: the one-way slant delay ``(ZHD + ZWD) / cos(theta_i)`` lengthens the range. ZHD by
  Saastamoinen [Saastamoinen1972] (Davis et al.'s form [Davis1985]): ``ZHD = 0.0022768 P / (1 -
  0.00266 cos 2phi - 0.28e-6 h)`` (m; P hPa, phi latitude, h m), P from the standard atmosphere
  ``P = 1013.25 (1 - 2.2557e-5 h)^5.2559`` hPa [ISO2533]; ZWD (wet) is not computable from the image:
  a nominal value is used (default 0.15 m; 0.05-0.4 m between dry and tropical air [Hanssen2001, ch. 4]).
  The 1/cos mapping is within 1 % of the Niell functions below 60 deg incidence.
- ionosphere: one-way group delay ``40.3 TEC / f^2`` (m, TEC in electrons/m^2) [Hanssen2001, eq. 4.3.9]:
  0.25 m per TEC unit (1e16 m^-2) at 1.27 GHz, vertical; slant through a thin shell at 350 km, i.e.
  divided by cos(theta_ion), sin(theta_ion) = sin(theta_i) Re / (Re + 350 km). Typical TEC 5-50 TECU:
  metres at L-band (and azimuth shifts where TEC varies along track). Needs a TEC map; not applied.
- solid-earth tide: up to ~0.3 m vertical, ~0.05 m horizontal [IERS2010, ch. 7]: up to ~0.25 m in
  slant range. Needs the IERS model; not applied.
- processor conventions: the azimuth time reference (the sensor moves v R / c, ~20 m, during the
  two-way travel time; stop-and-go processors absorb it in their timing, others do not), range
  calibration delays (internal electronic delay), the reflector's phase centre (its apex).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from orbit.errors import GeometryError, OrbitError
from orbit.statevectors import StateVectors
from sarcli.errors import ProductError
from sarcli.model.constants import C_LIGHT, WGS84_A
from sarcli.model.slc import SLC

IONO_SHELL_M = 350e3
TECU = 1e16
NOMINAL_WET_DELAY_M = 0.15


@dataclass
class Prediction:
    """A reflector's predicted place in the image (fractional pixels) and its local geometry."""

    zero_doppler_time_s: float
    slant_range_m: float
    row: float
    col: float
    inside: bool
    along_track_spacing_m: float
    incidence_deg: float
    position_ecef: np.ndarray


def image_orbit(slc: SLC) -> StateVectors:
    """ECEF state vectors of an SLC, refused in one line without an Earth orbit."""
    if slc.orbit is None or slc.orbit.frame not in ("ECI", "ECEF"):
        raise ProductError("corner-reflector prediction needs an Earth orbit (ECI or ECEF state vectors); the "
                           f"product has {'none' if slc.orbit is None else 'a LOCAL (flat-Earth) orbit'}")
    try:
        return StateVectors.from_record(slc.orbit, slc.epoch_utc).to_ecef()
    except OrbitError as e:
        raise ProductError(f"product orbit: {e}") from None


def predict(slc: SLC, sv: StateVectors, p: np.ndarray, height_m: float, k_lines: int = 8) -> Prediction | None:
    """The zero-Doppler pixel of the ECEF point ``p`` (module docstring); None when it is never seen
    (no zero-Doppler time within the orbit, or on the other side of the track)."""
    from orbit.geometry import doppler_time, geolocate, incidence_angle
    from orbit.pointing import flight_frame, side_sign

    t, r = slc.azimuth_time, slc.slant_range
    try:
        t0, r0 = doppler_time(sv, p[None, :], t_guess=0.5 * (t[0] + t[-1]))
    except GeometryError:
        return None
    t0, r0 = float(t0[0]), float(r0[0])
    pos, vel, _ = sv.interpolate(np.array([t0]))
    yf = flight_frame(pos, vel)[0, :, 1]
    if side_sign(slc.look_side) * float(np.dot(p - pos[0], yf)) <= 0:
        return None
    dt = float((t[-1] - t[0]) / (t.size - 1))
    dr = float((r[-1] - r[0]) / (r.size - 1))
    row, col = (t0 - t[0]) / dt, (r0 - r[0]) / dr
    inside = bool(0.0 <= row <= t.size - 1 and 0.0 <= col <= r.size - 1)
    tt = np.array([t0 - k_lines * dt, t0 + k_lines * dt])
    try:
        g = geolocate(sv, tt, np.full(2, r0), slc.radar.wavelength_m, 0.0, np.full(2, height_m), slc.look_side)
    except (GeometryError, OrbitError) as e:
        raise ProductError(f"along-track spacing at the reflector: {e}") from None
    ds = float(np.linalg.norm(g[1] - g[0]) / (2 * k_lines))
    inc = float(np.degrees(incidence_angle(pos[0], p)))
    return Prediction(t0, r0, float(row), float(col), inside, ds, inc, p)


def zenith_hydrostatic_delay_m(lat_deg: float, height_m: float) -> float:
    """Saastamoinen zenith hydrostatic delay (m) with standard-atmosphere pressure (module docstring)."""
    p_hpa = 1013.25 * (1.0 - 2.2557e-5 * height_m) ** 5.2559
    return 0.0022768 * p_hpa / (1.0 - 0.00266 * math.cos(2.0 * math.radians(lat_deg)) - 0.28e-6 * height_m)


def troposphere_slant_delay_m(lat_deg: float, height_m: float, incidence_deg: float,
                              wet_zenith_m: float = NOMINAL_WET_DELAY_M) -> float:
    """One-way slant tropospheric delay (m): (ZHD + ZWD) / cos(incidence)."""
    return (zenith_hydrostatic_delay_m(lat_deg, height_m) + wet_zenith_m) / math.cos(math.radians(incidence_deg))


def ionosphere_slant_delay_per_tecu_m(carrier_hz: float, incidence_deg: float) -> float:
    """One-way slant ionospheric group delay per TEC unit (m/TECU), thin shell at 350 km."""
    s = math.sin(math.radians(incidence_deg)) * WGS84_A / (WGS84_A + IONO_SHELL_M)
    return 40.3 * TECU / carrier_hz**2 / math.sqrt(1.0 - s * s)


def corrections(lat_deg: float, height_m: float, incidence_deg: float, carrier_hz: float,
                slant_range_m: float, velocity_mps: float, wet_zenith_m: float = NOMINAL_WET_DELAY_M) -> dict:
    """The corrections a user must consider, with the computable ones estimated (module docstring)."""
    return {
        "troposphere_slant_delay_m": troposphere_slant_delay_m(lat_deg, height_m, incidence_deg, wet_zenith_m),
        "troposphere_zenith_hydrostatic_m": zenith_hydrostatic_delay_m(lat_deg, height_m),
        "troposphere_zenith_wet_assumed_m": wet_zenith_m,
        "ionosphere_slant_delay_per_tecu_m": ionosphere_slant_delay_per_tecu_m(carrier_hz, incidence_deg),
        "solid_earth_tide_slant_bound_m": 0.3 * math.cos(math.radians(incidence_deg)) + 0.05 * math.sin(
            math.radians(incidence_deg)),
        "bistatic_along_track_m": velocity_mps * slant_range_m / C_LIGHT,
    }
