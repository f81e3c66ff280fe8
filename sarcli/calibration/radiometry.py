"""Radiometric model of a focused image: beta0, sigma0, gamma0 and the noise floor [Freeman1992, Small2011].

Notation: DN the SLC pixel, beta0 the radar brightness (backscatter per unit area in the slant plane),
sigma0 = beta0 sin(theta_i) and gamma0 = beta0 tan(theta_i) with theta_i the incidence angle on the
ellipsoid raised to the focusing height (terrain-flattened gamma0 over a DEM: :mod:`sarcli.calibration.products`).
One equation carries the whole chain [Freeman1992, eq. 5; ESA-S1-Cal]:

    E|DN|^2 = K F(R, t) beta0,        beta0 = |DN|^2 * L_beta0,   L_beta0 = 1 / (K F)

``L_beta0``, ``L_sigma0 = L_beta0 sin(theta_i)``, ``L_gamma0 = L_beta0 tan(theta_i)`` are look-up tables on a
coarse (zero-Doppler time, slant range) grid (:class:`sarcli.model.slc.Calibration`), multiplicative as in
NISAR's RSLC ``calibrationInformation/geometry`` [NISAR-RSLC]. K is one absolute calibration constant
per product (the transmitted power, the antenna's peak gains, the receiver gain, (4 pi)^3 and lambda^2 of
the radar equation): 1 for sarcli's simulator (a unit radar), else unknown (relative radiometry, said so)
until ``sarcli calibrate`` measures it on corner reflectors.

F, the gain a unit distributed backscatterer sees, derived for a linear focuser. A scatterer of RCS
sigma at slant range R echoes with amplitude a = sqrt(sigma) g_az g_el (R_ref / R)^2 (two-way
amplitude patterns g of a uniform aperture, sinc^2(L sin(psi) / lam), psi off the boresight;
the spreading factor is absent from the simulator's radar equation). The focused image of it is
a h(x), and a field of scatterers of mean backscatter sigma0 per ground area gives
E|DN|^2 = sigma0 int |h|^2 dA_ground = beta0 E dr dx, E = sum over pixels of |h|^2 (the integrated energy
of a unit point target), dr the slant-range spacing and dx = V_g / PRF the line spacing on the ground
(V_g the ground speed of the zero-Doppler point): dA_ground = dr dx / sin(theta_i) and beta0 = sigma0 /
sin(theta_i). The same E gives the integrated-energy RCS of a point target (:func:`point_rcs`):
sum |DN|^2 = K F sigma / (dr dx), i.e. sigma = sum(|DN|^2 L_beta0) dr dx [Gray1990]. E separates into
range and azimuth:

- range, matched filter H = conj(S_ref) W(f / (a B)) / sum|ref|^2 (:func:`sarcli.focus.rangecomp.range_filter`),
  chirp of band B = |K_r| T, N_r = T fs samples; stationary phase |S_ref(f)|^2 = fs^2 / |K_r| inside B:
  E_r = (1 / N) sum |Y|^2 = fs a <W^2> / B samples, noise gain G_r = (1 / N) sum |H|^2 = a <W^2> / N_r
  (<W^2>: the window's mean square over its support, a the processed band fraction); computed
  exactly on the filter (:func:`range_gains`), these being their stationary-phase values;
- azimuth, the Doppler history of rate f_R seen by the pattern g_az(f) = sinc^2(L_az (f - f_dc) / (2 V_s))
  (V_s the platform speed relative to the ground), processed over B_a with the window W_a:
  frequency-domain compression (rd: a phase-only filter times W_a, unnormalised FFT, 1/N inverse):
  E_a = (PRF / |f_R|) int g_az^2 W_a^2 df lines, noise gain G_a = B_a <W_a^2> / PRF;
  time-domain compression (backprojection: a sum over pulses weighted by W_a) is the same filter
  times |S_az| = PRF / sqrt(|f_R|): both E_a and G_a times PRF^2 / |f_R|;
- oversampling: the focusers renormalise their Fourier upsampling (rd's ``rcmc_oversample`` before the
  RCMC, backprojection's ``upsample``), so it changes neither E nor the noise gains (the tests measure
  this: rd with u = 1 and 2 give the same beta0).

F = E_r E_a g_el(R)^2 (R_ref / R)^4 dr dx (the spreading factor only where the data carry it), and the
noise floor in beta0 is NESZ_beta0 = P_n G_r G_a / (K F) [Freeman1992; ESA-S1-Noise] with P_n the noise power
per raw complex sample: measured on the sensor's noise lines when the product has them (Sentinel-1 noise
packets), else the receiver noise level the product states, else unknown (no noise floor written).

A term the product cannot supply (no antenna description: no elevation or azimuth pattern; no absolute
constant) is not applied and named in ``Calibration.not_applied``; the caller puts that in the GeoTIFF
tags and on stderr: a "sigma0" is then a relative one, never silently so.

Focusers: the gain model of each algorithm is its azimuth compression kind (:data:`AZIMUTH_COMPRESSION`);
a new focuser that uses the shared window and band options registers its kind there (or declares a
class attribute ``azimuth_compression``); an unknown one is refused in one line rather than guessed.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from sarcli.errors import SarcliError
from sarcli.model.slc import SLC, Calibration

#: how each focuser compresses in azimuth ("frequency": phase-only filter in the Doppler domain with an
#: unnormalised FFT pair; "time": a sum over pulses). csa / omegak / ffbp register here as they land.
AZIMUTH_COMPRESSION: dict[str, str] = {"rd": "frequency", "backprojection": "time"}
#: sources whose echoes carry no range spreading loss (sarcli's simulator: a unit radar, no 1/R^4)
NO_SPREADING_SOURCES = ("simulated",)
#: absolute constant of a simulated product (the simulator's unit radar)
SIMULATED_CONSTANT = 1.0
#: two-way elevation power pattern below which a range is "not calibrated" (NaN in the LUTs), dB
MAIN_LOBE_DB = -20.0
#: LUT grid: nodes along azimuth time and along slant range
LUT_TIMES, LUT_RANGES = 9, 65
KINDS = ("beta0", "sigma0", "gamma0")

TERM_SPREADING = "range spreading loss (R_ref/R)^4"
TERM_ELEVATION = "two-way antenna elevation pattern"
TERM_AZIMUTH = "two-way antenna azimuth pattern"
TERM_PROCESSING = "processing gain (windows, processed bands, oversampling)"
TERM_CONSTANT = "absolute calibration constant K"
TERM_GEOMETRY = ("orbit geometry (no state vectors): no incidence angle, so no sigma0 or gamma0; the effective "
                 "velocity for the ground speed in the pixel area")


def register_algorithm(name: str, kind: str) -> None:
    """Declare the azimuth compression of focuser ``name``: "frequency" or "time" (module docstring)."""
    if kind not in ("frequency", "time"):
        raise SarcliError(f"azimuth compression must be 'frequency' or 'time', got {kind!r}")
    AZIMUTH_COMPRESSION[name] = kind


def compression_kind(algorithm: str) -> str:
    """The azimuth compression kind of ``algorithm``: the table, else the focuser's own declaration."""
    if algorithm in AZIMUTH_COMPRESSION:
        return AZIMUTH_COMPRESSION[algorithm]
    try:
        from sarcli.focus import FOCUSERS

        kind = getattr(FOCUSERS.get(algorithm), "azimuth_compression", None)
    except Exception:  # an unknown name: the registry's own error is about focusing, not radiometry
        kind = None
    if kind in ("frequency", "time"):
        return kind
    raise SarcliError(f"radiometry: the processing gain of algorithm {algorithm!r} is not modelled (known: "
                      f"{', '.join(sorted(AZIMUTH_COMPRESSION))}); it must declare its azimuth compression")


def window_mean_square(spec: str) -> float:
    """<W^2>: the mean of the window's square over its support u in [-1/2, 1/2] (Simpson, 4097 nodes)."""
    from scipy.integrate import simpson

    from sarcli.focus.windows import window

    u = np.linspace(-0.5, 0.5, 4097)
    return float(simpson(window(spec, u) ** 2, x=u))


def range_gains(radar, window_spec: str, band_fraction: float) -> tuple[float, float]:
    """(E_r, G_r): the integrated energy (samples) of the nominal chirp compressed by the focusers' range
    matched filter (:func:`sarcli.focus.rangecomp.range_filter`) and that filter's noise gain sum|h|^2,
    computed on the filter itself rather than by stationary phase (whose fs a <W^2> / B and
    a <W^2> / N_r err by the chirp's Fresnel ripple: 2.4 % at a time-bandwidth product of 72). A
    replica's own scale is a constant of the product (in K)."""
    import scipy.fft as sfft

    from sarcli.focus.rangecomp import range_filter, reference_pulse

    ref = reference_pulse(radar)
    n = sfft.next_fast_len(4 * ref.size + 64)
    h, _ = range_filter(radar, n, window_spec, None, band_fraction)
    y = sfft.ifft(sfft.fft(ref, n) * h)
    return float(np.sum(np.abs(y) ** 2)), float(np.sum(np.abs(h) ** 2) / n)


@dataclass(frozen=True)
class Gains:
    """The focuser's gains on the LUT's range nodes (module docstring): ``energy`` E = E_r E_a (samples x
    lines per unit point amplitude, antenna patterns included), ``noise`` G_r G_a (per pixel per unit raw
    noise power), the two-way elevation power pattern ``elevation`` (1 without an antenna)."""

    energy: np.ndarray
    noise: np.ndarray
    elevation: np.ndarray


def _parameter(slc: SLC, name: str):
    p = slc.parameters
    if name not in p or p[name] is None:
        raise SarcliError(f"radiometry: the SLC does not record its processing parameter {name!r} (an SLC "
                          "imported from another processor cannot be calibrated by sarcli's gain model)")
    return p[name]


def processing_gains(slc: SLC, fr: np.ndarray, v_s: np.ndarray, look: np.ndarray) -> Gains:
    """The gains at the range nodes where the Doppler rate is ``fr`` (Hz/s), the platform's ground-relative
    speed ``v_s`` (m/s) and the look angle off the geodetic nadir ``look`` (rad)."""
    from sarcli.focus.windows import window

    kind = compression_kind(slc.algorithm)
    radar = slc.radar
    e_r, g_r = range_gains(radar, _parameter(slc, "range_window"), float(_parameter(slc, "range_bandwidth_fraction")))
    prf = float(slc.parameters.get("prf_hz") or slc.prf_hz)
    ba = float(_parameter(slc, "azimuth_bandwidth_hz"))
    wa_spec = _parameter(slc, "azimuth_window")
    f = np.linspace(-0.5, 0.5, 2049) * ba
    wa2 = window(wa_spec, f / ba) ** 2
    fr = np.abs(np.asarray(fr, np.float64))
    if radar.antenna_length_m is not None and np.all(np.isfinite(v_s)):
        g_az = np.sinc(radar.antenna_length_m * f[None, :] / (2.0 * np.asarray(v_s, np.float64)[:, None])) ** 2
    else:
        g_az = np.ones((fr.size, 1))
    from scipy.integrate import simpson

    e_a = prf / fr * simpson(g_az**2 * wa2[None, :], x=f, axis=-1)
    g_a = np.full(fr.shape, ba * window_mean_square(wa_spec) / prf)
    if kind == "time":
        e_a = e_a * prf**2 / fr
        g_a = g_a * prf**2 / fr
    if radar.antenna_height_m is not None and radar.antenna_look_angle_rad is not None and np.all(np.isfinite(look)):
        s_el = np.sin(np.asarray(look) - radar.antenna_look_angle_rad)
        elevation = np.sinc(radar.antenna_height_m * s_el / radar.wavelength_m) ** 4
    else:
        elevation = np.ones(fr.shape)
    return Gains(e_r * e_a, g_r * g_a, elevation)


@dataclass(frozen=True)
class Geometry:
    """Per LUT node (n_t, n_r): look angle off the geodetic nadir and ellipsoid incidence (rad), the
    platform's speed relative to the ground V_s and the zero-Doppler point's ground speed V_g (m/s).
    Without an orbit the angles and V_s are NaN (no antenna pattern can be placed) and the effective
    velocity V = sqrt(V_s V_g) of the Doppler used stands for V_g (V_g / V is about 0.94 for an 800 km
    orbit: 0.27 dB of pixel area, said so)."""

    look: np.ndarray
    incidence: np.ndarray
    v_s: np.ndarray
    v_g: np.ndarray


def _up(p: np.ndarray, local: bool) -> np.ndarray:
    """Unit normal of the ellipsoid (geodetic up) at ECEF points p (..., 3), or +z in a LOCAL frame."""
    if local:
        return np.broadcast_to(np.array([0.0, 0.0, 1.0]), p.shape)
    from orbit.geodetic import ecef_to_geodetic

    lat, lon, _ = ecef_to_geodetic(p)
    la, lo = np.radians(lat), np.radians(lon)
    return np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1)


def node_geometry(slc: SLC, t: np.ndarray, r: np.ndarray, height_m: float) -> Geometry:
    """:class:`Geometry` on the nodes t x r (zero-Doppler targets at ``height_m``).

    The look angle is the one at the BEAM CENTRE, where the antenna pattern is referenced: there the
    line of sight is normal to the antenna's along-track axis, so its angle off the (pitched) nadir is
    the elevation angle, and it is reached at the beam-centre range R_c = R0 / sqrt(1 - s^2), s the
    sine of the squint (:func:`sarcli.focus.rda.doppler_on_grid`'s model): at a squint of 1.5 deg
    (Radarsat-1, 5 PRFs of centroid) R_c - R0 is 360 m, 0.025 deg of look angle, a visible tilt of
    a narrow elevation pattern. It is taken at the beam-centre time t_c = t0 + R0 tan(theta) / V
    (:func:`sarcli.focus.kinematics.beam_centre_offset`), on the point at R_c and the centroid, seen from
    the platform there: seconds from the zero-Doppler time at a large squint (3.7 s for Radarsat-1),
    over which the orbit's height and the Earth's radius under it change the look angle at a fixed
    range by ~1e-4 rad (0.15 dB of a 12 m antenna's pattern half a kilometre off its boresight)."""
    from sarcli.focus.geolocation import geolocate_on_terrain, platform_state, state_vectors, zero_doppler_points
    from sarcli.focus.kinematics import beam_centre_offset, velocity_and_squint
    from sarcli.model.terrain import ConstantHeight

    if slc.orbit is None:  # no geometry: the effective velocity stands for the ground speed, angles unknown
        v = _doppler_at(slc, t, r, "velocity_mps")
        nan = np.full(v.shape, np.nan)
        return Geometry(nan, nan, nan, v)
    local = slc.orbit.frame == "LOCAL"
    terrain = ConstantHeight(height_m)
    tt, rr = np.meshgrid(t, r, indexing="ij")
    lam = slc.radar.wavelength_m
    p = zero_doppler_points(slc.orbit, slc.epoch_utc, tt, rr, lam, slc.look_side, terrain)
    pos, vel = platform_state(slc.orbit, slc.epoch_utc, tt)
    los = (p - pos) / np.linalg.norm(p - pos, axis=-1, keepdims=True)
    inc = np.arccos(np.clip(np.sum(-los * _up(p, local), axis=-1), -1.0, 1.0))
    fdc = _doppler_at(slc, t, r, "fdc_hz")
    v_eff, sq = velocity_and_squint(fdc, _doppler_at(slc, t, r, "fr_hz_per_s"), rr, lam)
    rc = rr / np.sqrt(1.0 - sq**2)
    if local:
        t_c = tt
        pc = zero_doppler_points(slc.orbit, slc.epoch_utc, tt, rc, lam, slc.look_side, terrain)
    else:
        t_c = tt + beam_centre_offset(rr, v_eff, sq)
        pc = geolocate_on_terrain(state_vectors(slc.orbit, slc.epoch_utc), t_c, rc, lam, fdc, slc.look_side, terrain)
    pos_c, _ = platform_state(slc.orbit, slc.epoch_utc, t_c)
    los_c = (pc - pos_c) / np.linalg.norm(pc - pos_c, axis=-1, keepdims=True)
    look = np.arccos(np.clip(np.sum(los_c * -_up(pos_c, local), axis=-1), -1.0, 1.0))
    dt = 0.5
    pa = zero_doppler_points(slc.orbit, slc.epoch_utc, tt - dt, rr, lam, slc.look_side, terrain)
    pb = zero_doppler_points(slc.orbit, slc.epoch_utc, tt + dt, rr, lam, slc.look_side, terrain)
    v_g = np.linalg.norm(pb - pa, axis=-1) / (2.0 * dt)
    return Geometry(look, inc, np.linalg.norm(vel, axis=-1), v_g)


def noise_power(raw) -> tuple[float | None, str]:
    """(P_n per raw complex sample, where it came from) of a raw product: the variance of its noise lines
    (an ``auxiliary`` array named ``*noise``, e.g. Sentinel-1's ``s1/noise``), else the receiver noise
    level it states (``radar.noise_power``), else (None, why)."""
    for name, lines in sorted((getattr(raw, "auxiliary", None) or {}).items()):
        if name.rsplit("/", 1)[-1] == "noise" and np.size(lines):
            x = np.atleast_2d(np.asarray(lines))
            x = x.reshape(-1, x.shape[-1])
            x = x.astype(np.complex128)
            # a reader pads lines to the widest with zeros: each line up to its last non-zero sample
            keep = np.flip(np.cumsum(np.flip(x != 0, axis=1), axis=1), axis=1) > 0
            if keep.any():
                v = x[keep]
                # the variance: a receiver's DC offset (Sentinel-1's noise packet: 0.2 of a code on I) is a
                # bias that the range filter's band rejects, not thermal noise
                return float(np.mean(np.abs(v - v.mean()) ** 2)), f"measured on {x.shape[0]} noise line(s) ({name})"
    if raw.radar.noise_power is not None:
        return float(raw.radar.noise_power), "the receiver noise level stated by the product"
    return None, "no noise lines and no stated receiver noise level"


def _doppler_at(slc: SLC, t: np.ndarray, r: np.ndarray, name: str) -> np.ndarray:
    """A quantity of the Doppler used (``fdc_hz``, ``fr_hz_per_s``, ``velocity_mps``) at the nodes t x r
    (the block nearest in time, linear in range)."""
    d = slc.doppler
    out = np.empty((t.size, r.size))
    for i, ti in enumerate(t):
        k = int(np.argmin(np.abs(np.asarray(d.block_time) - ti)))
        out[i] = np.interp(r, d.range_m, getattr(d, name)[k])
    return out


def compressed_span(slc: SLC, n_raw_samples: int) -> tuple[float, float]:
    """(first, last) slant range (m) of the targets whose whole pulse lies inside the raw receive window of
    ``n_raw_samples`` samples (from ``radar.first_range_m``): a pulse of length T centred on its delay
    2R/c spans R +- c T / 4 in range, so within c T / 4 of either end of the swath a target lacks part
    of its chirp (part of its band, hence of its energy, up to half at the very edge): not calibrated."""
    from sarcli.model.constants import C_LIGHT

    half = C_LIGHT * slc.radar.pulse_length_s / 4.0
    dr = C_LIGHT / (2.0 * slc.radar.range_sampling_rate_hz)
    lo = slc.radar.first_range_m + half
    hi = slc.radar.first_range_m + (n_raw_samples - 1) * dr - half
    return lo, hi


def calibrate(slc: SLC, noise: tuple[float | None, str] = (None, "not given"), constant: float | None = None,
              warn: bool = True, n_raw_samples: int | None = None) -> Calibration:
    """The :class:`Calibration` of ``slc`` (module docstring); ``noise`` from :func:`noise_power`;
    ``constant`` a measured K (default: 1 for a simulated product, else unknown, taken as 1 and named
    among the terms not applied). ``warn``: one warning line naming the terms not applied.
    ``n_raw_samples``: the raw swath's samples (default: the SLC's columns are the raw grid), for the
    fully range-compressed span (:func:`compressed_span`; NaN in the LUTs beyond it)."""
    from sarcli.io.slc import recorded_height

    t = np.linspace(slc.azimuth_time[0], slc.azimuth_time[-1], min(LUT_TIMES, slc.azimuth_time.size))
    r = np.linspace(slc.slant_range[0], slc.slant_range[-1], min(LUT_RANGES, slc.slant_range.size))
    span0 = compressed_span(slc, slc.slant_range.size if n_raw_samples is None else n_raw_samples)
    inner = (r > span0[0]) & (r < span0[1])
    r = np.unique(np.r_[r[inner], [x for x in span0 if slc.slant_range[0] <= x <= slc.slant_range[-1]],
                        r[~inner]])
    geo = node_geometry(slc, t, r, recorded_height(slc.parameters))
    fr = _doppler_at(slc, t, r, "fr_hz_per_s")
    energy = np.empty(fr.shape)
    noise_gain = np.empty(fr.shape)
    elevation = np.empty(fr.shape)
    for i in range(t.size):
        g = processing_gains(slc, fr[i], geo.v_s[i], geo.look[i])
        energy[i], noise_gain[i], elevation[i] = g.energy, g.noise, g.elevation
    applied, missing = [TERM_PROCESSING], []
    r_ref = float(0.5 * (r[0] + r[-1]))
    if slc.source in NO_SPREADING_SOURCES:
        spreading = np.ones(r.size)
        applied.append(TERM_SPREADING + " (none in the simulator's radar equation)")
    else:
        spreading = (r_ref / r) ** 4
        applied.append(TERM_SPREADING)
    has_orbit = slc.orbit is not None
    (applied if slc.radar.antenna_height_m is not None and has_orbit else missing).append(TERM_ELEVATION)
    (applied if slc.radar.antenna_length_m is not None and has_orbit else missing).append(TERM_AZIMUTH)
    if not has_orbit:
        missing.append(TERM_GEOMETRY)
    if constant is None:
        if slc.source in NO_SPREADING_SOURCES and not slc.radar.quantization_bits:
            constant = SIMULATED_CONSTANT
            applied.append(TERM_CONSTANT + " (1: the simulator's unit radar)")
        elif slc.source in NO_SPREADING_SOURCES:
            constant = 1.0
            missing.append(TERM_CONSTANT + " (the simulated receiver gain before the quantizer is not in the "
                           "product: relative radiometry)")
        else:
            constant = 1.0
            missing.append(TERM_CONSTANT + " (relative radiometry: run sarcli calibrate)")
    else:
        if not (math.isfinite(constant) and constant > 0):
            raise SarcliError(f"calibration constant K must be a positive number, got {constant}")
        applied.append(TERM_CONSTANT + " (measured)")
    prf = float(slc.parameters.get("prf_hz") or slc.prf_hz)
    f = constant * energy * elevation * spreading[None, :] * slc.range_spacing_m * geo.v_g / prf
    span = compressed_span(slc, slc.slant_range.size if n_raw_samples is None else n_raw_samples)
    lit = (elevation >= 10.0 ** (MAIN_LOBE_DB / 10.0)) & (r >= span[0] - 1e-6)[None, :] & (r <= span[1] + 1e-6)
    beta0 = np.where(lit, 1.0 / f, np.nan)
    p_n, how = noise
    if p_n is not None:
        nes0 = p_n * noise_gain * beta0 * np.sin(geo.incidence)
    else:
        nes0 = np.full(beta0.shape, np.nan)
    if warn and missing:
        warnings.warn(f"radiometry: not applied: {'; '.join(missing)} (backscatter is relative)", stacklevel=2)
    details = {"reference_range_m": r_ref, "noise_power": float("nan") if p_n is None else p_n,
               "noise_source": how, "azimuth_compression": compression_kind(slc.algorithm),
               "main_lobe_db": MAIN_LOBE_DB, "height_m": recorded_height(slc.parameters),
               "compressed_range_m": [float(span[0]), float(span[1])]}
    return Calibration(azimuth_time=t, slant_range=r, beta0=beta0, sigma0=beta0 * np.sin(geo.incidence),
                       gamma0=beta0 * np.tan(geo.incidence), nes0=nes0, constant=float(constant),
                       applied=tuple(applied), not_applied=tuple(missing), details=details)


def annotate(slc: SLC, raw, n_raw_samples: int | None = None) -> Calibration | None:
    """The calibration the focus workflow stores with a new SLC (noise from ``raw``, :func:`noise_power`;
    ``n_raw_samples`` the raw swath's samples);
    None, with one warning line saying why, when the product cannot be calibrated (no orbit, an
    algorithm whose gain is not modelled)."""
    try:
        return calibrate(slc, noise_power(raw), n_raw_samples=n_raw_samples)
    except ValueError as e:  # sarcli's and orbit's one-line errors (a geometry the solver cannot place)
        warnings.warn(f"no radiometric calibration: {e}", stacklevel=2)
        return None


def rescaled(cal: Calibration, constant: float, note: str) -> Calibration:
    """``cal`` with a new absolute constant K (the LUTs divide by K / K_old); the constant's term
    moves to ``applied`` with ``note``."""
    if not (math.isfinite(constant) and constant > 0):
        raise SarcliError(f"calibration constant K must be a positive number, got {constant}")
    q = cal.constant / constant
    applied = tuple(a for a in cal.applied if not a.startswith(TERM_CONSTANT)) + (f"{TERM_CONSTANT} ({note})",)
    missing = tuple(m for m in cal.not_applied if not m.startswith(TERM_CONSTANT))
    return Calibration(cal.azimuth_time, cal.slant_range, cal.beta0 * q, cal.sigma0 * q, cal.gamma0 * q,
                       cal.nes0 * q, float(constant), applied, missing, dict(cal.details))


def lut_on(cal: Calibration, name: str, t: np.ndarray, r: np.ndarray) -> np.ndarray:
    """LUT ``name`` (beta0, sigma0, gamma0, nes0) bilinear on the axes t x r (clamped at the grid's ends;
    NaN nodes stay NaN around them)."""
    lut = getattr(cal, name)
    r = np.asarray(r, np.float64)
    by_r = np.stack([np.interp(r, cal.slant_range, row) for row in lut])
    span = cal.details.get("compressed_range_m")
    if span is not None:
        by_r[:, (r < span[0] - 1e-6) | (r > span[1] + 1e-6)] = np.nan
    if cal.azimuth_time.size == 1:
        return np.broadcast_to(by_r, (np.size(t), np.size(r))).copy()
    return np.stack([np.interp(t, cal.azimuth_time, by_r[:, j]) for j in range(r.size)], axis=1)


def calibrated_intensity(slc: SLC, inten: np.ndarray, looks_az: int, looks_rg: int, kind: str,
                         noise_subtraction: bool = False) -> np.ndarray:
    """The multilooked intensity ``inten`` (mean |DN|^2 of looks_az x looks_rg cells) as ``kind``
    (beta0, sigma0; gamma0 on the ellipsoid), float32, NaN where not calibrated; with
    ``noise_subtraction`` the noise floor (sigma0's NESZ, scaled to ``kind``) subtracted."""
    if kind not in KINDS:
        raise SarcliError(f"radiometry must be one of {', '.join(KINDS)}, got {kind!r}")
    cal = slc.calibration
    if cal is None:
        raise SarcliError("the SLC carries no radiometric calibration (focus it again with this sarcli)")
    n, m = inten.shape
    t = slc.azimuth_time[: n * looks_az].reshape(n, looks_az).mean(axis=1)
    r = slc.slant_range[: m * looks_rg].reshape(m, looks_rg).mean(axis=1)
    lut = lut_on(cal, kind, t, r)
    out = inten.astype(np.float64) * lut
    if noise_subtraction:
        if not np.any(np.isfinite(cal.nes0)):
            raise SarcliError("noise subtraction needs a noise floor: the product has no noise measurement")
        out -= lut_on(cal, "nes0", t, r) * lut / lut_on(cal, "sigma0", t, r)
        out = np.where(out < 0.0, 0.0, out)  # below the noise floor: zero backscatter (-inf dB), as ESA's
    return out.astype(np.float32)


def point_rcs(slc: SLC, row: float, col: float, half: int = 16, guard: int = 24) -> float:
    """Integrated-energy RCS (m^2) of the point target near (row, col) [Gray1990]: the energy in a
    (2 half + 1)^2 window minus the clutter mean power of the ring between half and ``guard`` pixels
    times the window's pixels, times the beta0 LUT there times dr dx, i.e. sigma = sum(|DN|^2 - c)
    L_beta0 dr dx (the beta0 of the window integrated over its slant-plane area)."""
    cal = slc.calibration
    if cal is None:
        raise SarcliError("the SLC carries no radiometric calibration (focus it again with this sarcli)")
    i, j = int(round(row)), int(round(col))
    n, m = slc.image.shape
    a, b, c, d = i - guard, i + guard + 1, j - guard, j + guard + 1
    if a < 0 or c < 0 or b > n or d > m:
        raise SarcliError(f"point target at ({row:.1f}, {col:.1f}) is within {guard} pixels of the image edge")
    p = np.abs(slc.image[a:b, c:d].astype(np.complex128)) ** 2
    inner = np.zeros(p.shape, bool)
    inner[guard - half:guard + half + 1, guard - half:guard + half + 1] = True
    clutter = float(np.mean(p[~inner]))
    energy = float(np.sum(p[inner]) - clutter * inner.sum())
    lut = float(lut_on(cal, "beta0", np.array([slc.azimuth_time[i]]), np.array([slc.slant_range[j]]))[0, 0])
    geo = node_geometry(slc, np.array([slc.azimuth_time[i]]), np.array([slc.slant_range[j]]),
                        float(cal.details.get("height_m", 0.0)))
    prf = float(slc.parameters.get("prf_hz") or slc.prf_hz)
    return energy * lut * slc.range_spacing_m * float(geo.v_g[0, 0]) / prf


def trihedral_rcs(side_m: float, wavelength_m: float, u: np.ndarray | None = None) -> float:
    """RCS (m^2) of a triangular trihedral corner reflector of inner edge ``side_m`` seen along ``u`` (unit
    vector from the reflector toward the radar in its plate frame: the three plate normals; default the
    boresight (1, 1, 1)/sqrt(3)), by physical optics: sigma = 4 pi A(u)^2 / lam^2 with A the effective
    (triply reflected) aperture area [Ruck1970, sec. 8.3], A = a^2 / sqrt(3) on the boresight, hence
    4 pi a^4 / (3 lam^2) there.

    A(u) by geometry: a ray entering the aperture at a point q of the aperture triangle (the plate edges'
    ends a e1, a e2, a e3 projected on the plane normal to u, the corner at the origin) leaves after
    three bounces at -q (a corner reflector retro-reflects through its vertex), so it is returned iff
    -q is also in the aperture: A is the area of the triangle's intersection with its point reflection
    (a regular hexagon of 2/3 of the triangle on the boresight), computed by polygon clipping."""
    if u is None:
        u = np.full(3, 1.0 / math.sqrt(3.0))
    return 4.0 * math.pi * _trihedral_area(side_m, np.asarray(u, np.float64)) ** 2 / wavelength_m**2


def reflector_rcs(cr, p_ecef: np.ndarray, radar_ecef: np.ndarray, wavelength_m: float) -> float:
    """Theoretical RCS (m^2) of the corner reflector ``cr`` (:class:`sarcli.calibration.reflectors.CornerReflector`)
    at ``p_ecef`` seen from the radar at ``radar_ecef``. The CSV's angles follow ISCE3's reading of the NISAR
    corner-reflector specification [NISAR-CR-SIS]: ``azimuth_deg`` is the boresight's heading measured
    clockwise from geographic EAST (so the boresight points to azimuth_deg + 90 clockwise from north),
    ``tilt_deg`` tilts the reflector's vertical axis from the ellipsoid normal, raising the boresight
    from its 35.26 deg above the base plate to 35.26 + tilt above the horizon."""
    from sarcli.calibration.reflectors import enu_basis

    u = np.asarray(radar_ecef, np.float64) - np.asarray(p_ecef, np.float64)
    u_enu = enu_basis(cr.latitude_deg, cr.longitude_deg).T @ (u / np.linalg.norm(u))
    el0 = math.degrees(math.asin(1.0 / math.sqrt(3.0)))
    frame = plate_frame(cr.azimuth_deg + 90.0, el0 + cr.tilt_deg)
    return trihedral_rcs(cr.side_length_m, wavelength_m, frame.T @ u_enu)


def plate_frame(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """(3, 3) rotation whose columns are the plate normals of a trihedral, in local east-north-up, whose
    boresight points to azimuth ``azimuth_deg`` (clockwise from north) and ``elevation_deg`` above the
    horizon (the reflector CSV's azimuth and tilt), the base plate's in-plane rotation being the one
    that keeps the boresight's vertical plane a symmetry plane (the reflector tilted about its
    horizontal axis). Canonical frame: base plate horizontal, boresight (1, 1, 1)/sqrt(3) at azimuth
    45 deg and elevation asin(1/sqrt(3)) = 35.26 deg; tilted by the elevation difference about the
    horizontal axis normal to the boresight's azimuth, then turned to the azimuth."""
    el0 = math.asin(1.0 / math.sqrt(3.0))
    a45 = math.radians(45.0)
    axis = np.array([math.cos(a45), -math.sin(a45), 0.0])  # horizontal, normal to the azimuth-45 plane
    tilt = _rotation(axis, math.radians(elevation_deg) - el0)
    turn = _rotation(np.array([0.0, 0.0, 1.0]), -(math.radians(azimuth_deg) - a45))
    return turn @ tilt


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: rotation by ``angle`` (rad, right-handed) about the unit ``axis``."""
    k = axis / np.linalg.norm(axis)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * (kx @ kx)


def _trihedral_area(a: float, u: np.ndarray) -> float:
    """Effective area A(u) of :func:`trihedral_rcs` (0 where u leaves the reflector's octant)."""
    if np.any(u <= 0.0):
        return 0.0
    u = u / np.linalg.norm(u)
    b1 = np.cross(u, [0.0, 0.0, 1.0])
    if np.linalg.norm(b1) < 1e-9:
        b1 = np.cross(u, [1.0, 0.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(u, b1)
    tri = a * np.stack([np.eye(3) @ b1, np.eye(3) @ b2], axis=1)
    return _polygon_area(_clip(tri, -tri))


def _polygon_area(p: np.ndarray) -> float:
    return abs(_polygon_signed(p)) if len(p) >= 3 else 0.0


def _polygon_signed(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _clip(subject: np.ndarray, clip: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: the polygon ``subject`` clipped by the convex polygon ``clip`` (both (n, 2))."""
    if _polygon_signed(clip) < 0:
        clip = clip[::-1]
    out = [tuple(v) for v in subject]
    for k in range(len(clip)):
        if not out:
            break
        a, b = clip[k], clip[(k + 1) % len(clip)]

        def side(p, a=a, b=b):
            return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])

        inp, out = out, []
        for i in range(len(inp)):
            p, q = inp[i], inp[(i + 1) % len(inp)]
            sp, sq = side(p), side(q)
            if sq >= 0.0:
                if sp < 0.0:
                    w = sp / (sp - sq)
                    out.append((p[0] + w * (q[0] - p[0]), p[1] + w * (q[1] - p[1])))
                out.append(q)
            elif sp >= 0.0:
                w = sp / (sp - sq)
                out.append((p[0] + w * (q[0] - p[0]), p[1] + w * (q[1] - p[1])))
    return np.array(out, np.float64).reshape(-1, 2)
