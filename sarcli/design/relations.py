"""Design relations of [KimAODCCD, §2.4 "SAR design concept"], derived in this module's notation.

Notation: c speed of light, B chirp bandwidth (Hz), K chirp rate (Hz/s), tau pulse length (s),
lam wavelength, R slant range, H platform height, v platform speed, D real antenna length (azimuth),
L synthetic-aperture length (m), theta_sq the angle between the velocity and the line of sight
(90 deg for a broadside side-looking radar), depression angle = look angle measured from the horizontal.
"""

from __future__ import annotations

import math

from sarcli.model.constants import C_LIGHT


def chirp_bandwidth(chirp_rate_hz_per_s: float, pulse_length_s: float) -> float:
    """B = |K| * tau: an LFM pulse sweeps K Hz every second for tau seconds."""
    return abs(chirp_rate_hz_per_s) * pulse_length_s


def slant_range_resolution(bandwidth_hz: float, c: float = C_LIGHT) -> float:
    """delta_R = c / (2 B): two echoes are separable when their delays differ by the compressed
    pulse width 1/B, and the two-way path halves it."""
    return c / (2.0 * bandwidth_hz)


def ground_range_resolution(bandwidth_hz: float, incidence_rad: float, c: float = C_LIGHT) -> float:
    """delta_Rg = c / (2 B sin(i)) with i the incidence angle at the ground (flat Earth: i = 90 deg -
    depression). [KimAODCCD, eq. 14] writes c/(2 B cos a) with a the side-looking angle measured from the
    horizontal: cos(a) = sin(i), the same relation."""
    return c / (2.0 * bandwidth_hz * math.sin(incidence_rad))


def flat_earth_slant_range(height_m: float, depression_rad: float) -> float:
    """R = H / sin(depression): the line of sight from height H meets flat ground at the depression angle."""
    return height_m / math.sin(depression_rad)


def spherical_earth_geometry(height_m: float, look_from_nadir_rad: float,
                             earth_radius_m: float = 6371000.0) -> tuple[float, float]:
    """(slant range, incidence) for a platform at height H over a sphere of radius Re.

    Law of cosines in the triangle (Earth centre, platform at a = Re + H, ground point at Re):
    Re^2 = a^2 + R^2 - 2 a R cos(gamma) -> R = a cos(gamma) - sqrt(Re^2 - a^2 sin^2(gamma)); the
    sine rule gives sin(i) = a sin(gamma) / Re. Raises ValueError when the look misses the Earth."""
    a = earth_radius_m + height_m
    disc = earth_radius_m**2 - (a * math.sin(look_from_nadir_rad)) ** 2
    if disc < 0:
        raise ValueError(f"a look angle of {math.degrees(look_from_nadir_rad):.2f} deg from nadir misses the Earth")
    R = a * math.cos(look_from_nadir_rad) - math.sqrt(disc)
    return R, math.asin(min(1.0, a * math.sin(look_from_nadir_rad) / earth_radius_m))


def look_angle_for_slant_range(height_m: float, slant_range_m: float, earth_radius_m: float = 6371000.0) -> float:
    """Look angle from nadir (rad) that reaches slant range R: the law of cosines of
    :func:`spherical_earth_geometry` solved for gamma, cos(gamma) = (a^2 + R^2 - Re^2) / (2 a R)."""
    a = earth_radius_m + height_m
    cosg = (a * a + slant_range_m**2 - earth_radius_m**2) / (2 * a * slant_range_m)
    if not -1.0 <= cosg <= 1.0 or slant_range_m < height_m:
        raise ValueError(f"no ground point lies at {slant_range_m:.0f} m from a platform {height_m:.0f} m high")
    return math.acos(cosg)


def azimuth_resolution(wavelength_m: float, slant_range_m: float, aperture_m: float,
                       theta_sq_rad: float = math.pi / 2) -> float:
    """delta_az = lam R / (2 L sin(theta_sq)) ([KimAODCCD, eq. 15], R_y = lam R0 / (2 L sin(theta))).

    The aperture L seen from the target spans the angle L sin(theta_sq)/R across the line of sight;
    two-way phase doubles the angular diversity: delta_az = lam / (2 * angle). Broadside: sin = 1."""
    return wavelength_m * slant_range_m / (2.0 * aperture_m * math.sin(theta_sq_rad))


def beam_limited_aperture(wavelength_m: float, slant_range_m: float, antenna_length_m: float) -> float:
    """L = lam R / D: the length of track over which a point stays in the real beam (width lam/D)."""
    return wavelength_m * slant_range_m / antenna_length_m


def prf_min_azimuth(velocity_mps: float, antenna_length_m: float) -> float:
    """PRF > 2 v / D: the Doppler bandwidth of the real beam, 2 v (lam/D) / lam, must be sampled
    without aliasing ([KimAODCCD, §2.4]: "2v/l < PRF", l the antenna length)."""
    return 2.0 * velocity_mps / antenna_length_m


def processed_doppler_bandwidth(velocity_mps: float, azimuth_resolution_m: float) -> float:
    """B_D = v / delta_az: the Doppler bandwidth the processor actually integrates (the minimum PRF
    when no real antenna length is given)."""
    return velocity_mps / azimuth_resolution_m


def prf_max_range(max_slant_range_m: float, c: float = C_LIGHT) -> float:
    """PRF < c / (2 R_max): the echo of the farthest point must return before the next pulse leaves
    ([KimAODCCD, §2.4]'s relation; one pulse in flight)."""
    return c / (2.0 * max_slant_range_m)


def echo_window_prf_max(swath_slant_m: float, pulse_length_s: float, c: float = C_LIGHT) -> float:
    """PRF < 1 / (2 W / c + tau): the echo window of a swath W (slant) plus one pulse must fit in a
    PRI; the weaker, multi-pulse-in-flight form of the range-ambiguity constraint."""
    return 1.0 / (2.0 * swath_slant_m / c + pulse_length_s)


def ccd_doppler_samples(ccd_rows: int, ccd_line_rate_hz: float, prf_hz: float) -> int:
    """Pulses integrated by a CCD azimuth correlator.

    The CCD shifts its charge by one row per line clock (``ccd_line_rate_hz``; 15734 Hz is the NTSC
    line rate the PRFs of [KimAODCCD, §2.4] are sub-multiples of) and integrates over ``ccd_rows - 1`` shifts, i.e.
    a fixed aperture time T = (rows - 1)/line_rate; a pulse arrives every line_rate/PRF shifts, so
    N = floor((rows - 1) * PRF / line_rate): 490, 122, 61 at 15734, 3934, 1967 Hz with 491 rows.
    """
    return int(math.floor((ccd_rows - 1) * prf_hz / ccd_line_rate_hz + 1e-9))


def aod_swath(aod_aperture_m: float, acoustic_velocity_mps: float, pulse_length_s: float,
              c: float = C_LIGHT) -> float:
    """Slant swath processed per light flash by a space-integrating AOD correlator.

    The AOD holds T_a = aperture / v_acoustic seconds of signal; a full chirp (tau) must lie inside it
    to be correlated, so echoes spanning T_a - tau of delay are compressed at once: W = c (T_a - tau)/2.
    """
    ta = aod_aperture_m / acoustic_velocity_mps
    return max(0.0, c * (ta - pulse_length_s) / 2.0)


def stepped_frequency_max_range(frequency_step_hz: float, c: float = C_LIGHT) -> float:
    """GB-SAR: R_max = c / (4 df) — the inverse FFT of N frequency steps df spans a two-way delay
    1/df, i.e. c/(2 df) of range; [LeeGBSAR-II-2007, §2.1] keeps half of it to avoid the negative-time half."""
    return c / (4.0 * frequency_step_hz)


def gbsar_max_step(wavelength_m: float, beamwidth_rad: float) -> float:
    """GB-SAR spatial sampling: the two-way phase gradient 4 pi sin(theta)/lam over the beam half-width
    must not alias between rail positions: dx <= lam / (4 sin(beam/2))."""
    return wavelength_m / (4.0 * math.sin(beamwidth_rad / 2.0))
