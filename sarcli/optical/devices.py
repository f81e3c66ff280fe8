"""Device parameters of the AOD/CCD processor and the processor design derived from the radar geometry.

Signal chain ([KimAODCCD, §2.1-2.3], in this module's notation):

* The echo of pulse n, heterodyned to the AOD centre frequency nu1 and summed with a reference tone at
  nu2 = nu1 + dnu (eq. 6), travels through the AOD at the acoustic speed v_a. A light flash at time t_f
  freezes it: AOD position x holds the signal of two-way delay tau = t_f - x / v_a, over the time
  aperture T_a = X / v_a (eq. 7). The Bragg tilt (second factor of eq. 8) removes the nu1 carrier, so the
  optical field is the baseband echo plus a tilted plane wave exp(-j 2 pi u0 x), u0 = dnu / v_a.
* Lenses L3/L5 correlate the field with the spatial chirp (eq. 8-9): range compression, g(tau).
* The CCD records the intensity |g + A exp(j theta)|^2, theta = 2 pi dnu tau (eq. 10), behind the mask
  T = (1/2)(1 + cos(theta + psi)) (eq. 12), and shifts its charge one row per PRI (eq. 11, 13): row r of
  the mask multiplies pulse n into the charge packet k = n + r, an azimuth correlation.
* The mask chirp is psi(tau, r) = -2 pi v^2 ((r - r_c) / PRF)^2 / (lam R(tau)), R = c tau / 2, with the
  sign that makes the carrier term at 2 theta focus (eq. 13's cos(4 pi u0 x + phi)): the focused image
  sits on a carrier at 2 dnu and is demodulated after read-out.

The coefficients of [KimAODCCD, §2.5(3)-(4)] reproduced by :func:`seed_mask_coefficients` (AOD plane, magnification 1):
u0 = dnu / v_a (cycles/m; [KimAODCCD] prints "rad/m" but writes 2 pi u0 x) = 16207 for dnu = 10 MHz
(printed 16210), and b2 = 4 v^2 T^2 v_a f0 / (c^2 dy^2) = 385.56 m^-1 (printed "m^-2"), which equals our
psi only with a factor pi: psi = pi * b2 * y^2 / x with y = r dy and x = v_a 2R/c. The printed eq. 12
drops that pi (typo). The AOD coefficient b1 = 7.88e-2 could not be reconciled with any unit choice of
the spatial chirp pi K / v_a^2 (4.13e6 rad/m^2); we derive the spatial chirp from K and v_a instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sarcli.model.constants import C_LIGHT


@dataclass(frozen=True)
class AOD:
    """Acousto-optic device: 45 MHz centre, 30 MHz bandwidth, 31 mm aperture, 0.617 mm/us ([KimAODCCD, §2.5(1)])."""

    center_frequency_hz: float = 45.0e6
    bandwidth_hz: float = 30.0e6
    aperture_m: float = 0.031
    acoustic_velocity_mps: float = 617.0

    @property
    def time_aperture_s(self) -> float:
        """T_a = X / v_a: the span of echo delay held in the AOD at one flash (50.2 us)."""
        return self.aperture_m / self.acoustic_velocity_mps


@dataclass(frozen=True)
class CCD:
    """Interline-transfer CCD: 384 (H, range) x 491 (V, azimuth) pixels of 23.0 x 13.4 um ([KimAODCCD, §2.5(2)])."""

    columns: int = 384
    rows: int = 491
    pitch_x_m: float = 23.0e-6
    pitch_y_m: float = 13.4e-6
    adc_bits: int = 8


@dataclass(frozen=True)
class OpticalSettings:
    """Knobs of the emulated processor. ``reference_offset_hz`` None -> the rule dnu = B of [KimAODCCD].

    ``magnification``: "carrier" (default) images the AOD onto the CCD so that the focused carrier at
    2 dnu is sampled by the pixels (two pixels per period at the band edge); "fit_aod" images the whole
    31 mm AOD onto the 8.8 mm CCD (what the device sizes suggest), which aliases the carrier.
    """

    aod: AOD = field(default_factory=AOD)
    ccd: CCD = field(default_factory=CCD)
    light_pulse_s: float = 20e-9
    reference_offset_hz: float | None = None
    reference_ratio: float = 1.0
    magnification: str = "carrier"
    remove_bias: bool = False
    seed: int = 0  # read noise of the ``adc`` limitation

    def __post_init__(self) -> None:
        from sarcli.errors import ConfigError

        if self.reference_offset_hz is not None and not self.reference_offset_hz > 0:
            raise ConfigError(f"reference offset must be a positive frequency (Hz), got {self.reference_offset_hz}")
        if self.magnification not in ("carrier", "fit_aod"):
            raise ConfigError(f"magnification must be 'carrier' or 'fit_aod', not {self.magnification!r}")
        if not self.light_pulse_s > 0 or not self.reference_ratio > 0:
            raise ConfigError("light_pulse_s and reference_ratio must be positive")
        if not 1 <= self.ccd.adc_bits <= 24 or self.ccd.rows < 3 or self.ccd.columns < 8:
            raise ConfigError("CCD: adc_bits must be 1..24, rows >= 3, columns >= 8")


@dataclass(frozen=True)
class OpticalDesign:
    """The processor design for one radar geometry (all derived, nothing typed in)."""

    bandwidth_hz: float  # chirp bandwidth B = |K| tau_p
    reference_offset_hz: float  # dnu = nu2 - nu1
    pixel_delay_s: float  # two-way delay spanned by one CCD column
    magnification: float  # CCD plane / AOD plane
    centre_delay_s: float  # two-way delay at the CCD's centre column
    flash_delay_s: float  # t_f: the flash fires when the AOD holds [t_f - T_a, t_f]
    aperture_pulses: int  # pulses the CCD integrates (mask rows used)
    u0_cycles_per_m: float  # mask carrier in the CCD plane
    swath_slant_m: float  # slant range covered by the CCD columns

    def column_delay(self, columns: int) -> list[float]:
        c0 = (columns - 1) / 2.0
        return [self.centre_delay_s + (j - c0) * self.pixel_delay_s for j in range(columns)]


def design(bandwidth_hz: float, pulse_length_s: float, centre_delay_s: float, settings: OpticalSettings,
           max_pulses: int | None = None) -> OpticalDesign:
    """Derive the processor design from the radar (B, pulse length) and the scene's centre delay."""
    aod, ccd = settings.aod, settings.ccd
    dnu = bandwidth_hz if settings.reference_offset_hz is None else settings.reference_offset_hz
    if settings.magnification == "fit_aod":
        mag = ccd.columns * ccd.pitch_x_m / aod.aperture_m
        pixel_delay = ccd.pitch_x_m / (mag * aod.acoustic_velocity_mps)
    elif settings.magnification == "carrier":
        # focused term: carrier 2 dnu with the compressed band +-B/2 around it; Nyquist on its top edge
        pixel_delay = 1.0 / (2.0 * (2.0 * dnu + bandwidth_hz / 2.0))
        mag = ccd.pitch_x_m / (pixel_delay * aod.acoustic_velocity_mps)
    else:
        raise ValueError(f"magnification must be 'carrier' or 'fit_aod', not {settings.magnification!r}")
    span = ccd.columns * pixel_delay
    # the last column's chirp must still be inside the AOD when the flash fires
    flash = centre_delay_s + span / 2.0 + pulse_length_s / 2.0
    rows = ccd.rows - 1 if max_pulses is None else min(ccd.rows - 1, max_pulses)
    return OpticalDesign(bandwidth_hz=bandwidth_hz, reference_offset_hz=dnu, pixel_delay_s=pixel_delay,
                         magnification=mag, centre_delay_s=centre_delay_s, flash_delay_s=flash,
                         aperture_pulses=rows, u0_cycles_per_m=dnu / (aod.acoustic_velocity_mps * mag),
                         swath_slant_m=span * C_LIGHT / 2.0)


def seed_mask_coefficients(carrier_frequency_hz: float, velocity_mps: float, prf_hz: float,
                           reference_offset_hz: float, aod: AOD = AOD(), ccd: CCD = CCD()) -> tuple[float, float]:
    """(u0 cycles/m, b2 1/m) of eq. 12 in the AOD-plane notation of [KimAODCCD] (magnification 1).

    u0 = dnu / v_a; b2 = 4 v^2 T^2 v_a f0 / (c^2 dy^2), T = 1/PRF, dy the CCD row pitch, such that
    pi * b2 * y^2 / x equals the azimuth phase 2 pi v^2 t^2 / (lam R) at y = dy t / T, x = v_a 2 R / c.
    """
    va = aod.acoustic_velocity_mps
    T = 1.0 / prf_hz
    u0 = reference_offset_hz / va
    b2 = 4.0 * velocity_mps**2 * T**2 * va * carrier_frequency_hz / (C_LIGHT**2 * ccd.pitch_y_m**2)
    return u0, b2


def mask_phase(delay_s, row_offset, velocity_mps: float, wavelength_m: float, prf_hz: float):
    """psi = -2 pi v^2 (row_offset / PRF)^2 / (lam R), R = c delay / 2 (rad); numpy-broadcasting."""
    R = C_LIGHT * delay_s / 2.0
    t = row_offset / prf_hz
    return -2.0 * math.pi * velocity_mps**2 * t * t / (wavelength_m * R)
