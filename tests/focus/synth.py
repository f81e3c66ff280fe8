"""Plain-numpy point-target raw data for the focusing tests (independent of sarcli.focus).

Flat hyperbolic geometry: platform along y at constant speed V, target at closest range R0 and
zero-Doppler time eta0, R(eta) = sqrt(R0^2 + V^2 (eta - eta0)^2). Echo sample (line n, range sample m):

    sum_targets a * exposure(eta_n) * rect(|tau_m - 2R/c| <= T/2) * exp(j pi K (tau_m - 2R/c)^2) * exp(-j 4 pi R / lam)

with tau_m = 2 (r_first + m dr) / c and the exposure a rect in instantaneous Doppler
f(eta) = -(2/lam) V^2 (eta - eta0) / R around the centroid fdc = -2 V sin(theta) / lam (the beam),
``exposure_bw_hz`` wide, so that the processed band (narrower) sees a flat spectrum. ``fdc`` may be a
function of time (a steered beam: the exposure follows fdc(eta_n) line by line).
"""

from __future__ import annotations

import numpy as np

from sarcli.model.raw import Radar, RawProduct

C = 299792458.0


def scene(targets, *, n_lines=1024, n_samples=768, prf=1500.0, fs=24e6, chirp_rate=-1e12, pulse=20e-6,
          wavelength=0.0566, velocity=7000.0, fdc=0.0, r_first=850e3, t0=0.0, exposure_bw_hz=1300.0,
          replica=False, dtype=np.complex64):
    """RawProduct with point targets ``[(R0, eta0, amplitude), ...]`` (see the module docstring)."""
    eta = t0 + np.arange(n_lines) / prf
    dr = C / (2 * fs)
    rng = r_first + np.arange(n_samples) * dr
    echo = np.zeros((n_lines, n_samples), np.complex128)
    for r0, eta0, amp in targets:
        rr = np.sqrt(r0**2 + velocity**2 * (eta - eta0) ** 2)
        f = -(2 / wavelength) * velocity**2 * (eta - eta0) / rr
        centre = fdc(eta) if callable(fdc) else fdc
        lines = np.nonzero(np.abs(f - centre) <= 0.5 * exposure_bw_hz)[0]
        for n in lines:
            d = 2 * (rng - rr[n]) / C
            inside = np.abs(d) <= 0.5 * pulse
            echo[n, inside] += amp * np.exp(1j * np.pi * chirp_rate * d[inside] ** 2
                                            - 4j * np.pi * rr[n] / wavelength)
    radar = Radar(carrier_frequency_hz=C / wavelength, wavelength_m=wavelength, prf_hz=prf,
                  range_sampling_rate_hz=fs, chirp_rate_hz_per_s=chirp_rate, pulse_length_s=pulse,
                  window_start_s=2 * r_first / C, first_range_m=r_first, platform_velocity_mps=velocity)
    rep = None
    if replica:
        n = int(round(pulse * fs))
        t = (np.arange(n) - 0.5 * (n - 1)) / fs
        rep = np.exp(1j * np.pi * chirp_rate * t * t).astype(np.complex64)
    return RawProduct(echo=echo.astype(dtype), azimuth_time=eta, epoch_utc="2002-06-16T00:00:00Z", radar=radar,
                      replica=rep, source="simulated")


def sin_squint(fdc, velocity=7000.0, wavelength=0.0566):
    return -fdc * wavelength / (2 * velocity)


def beam_offset(r0, fdc, velocity=7000.0, wavelength=0.0566):
    """Beam-centre time minus zero-Doppler time (s)."""
    s = sin_squint(fdc, velocity, wavelength)
    return r0 * s / np.sqrt(1 - s * s) / velocity


#: the spaceborne C band point scene of the focuser tests (test_point_targets.py's geometry)
SPACE_PRF, SPACE_FS, SPACE_LAM, SPACE_V, SPACE_BA = 1500.0, 24e6, 0.0566, 7000.0, 1200.0
SPACE_DR = C / (2 * SPACE_FS)
SPACE_R0 = 850e3 + 384.3 * SPACE_DR


def focus_spaceborne(focus, fdc, window, **kw):
    """One target at SPACE_R0 (zero-Doppler time 0.34 s + 0.37 line) seen at centroid ``fdc``, focused by
    ``focus`` (focus_rd, focus_csa, focus_omegak) with ``window`` in range and azimuth, 90 % of the chirp
    band and SPACE_BA of Doppler band -> (raw, slc, the target's row, its column)."""
    from sarcli.model.doppler import GeometricDoppler

    eta0 = 0.34 + 0.37 / SPACE_PRF - beam_offset(SPACE_R0, fdc)
    raw = scene([(SPACE_R0, eta0, 1.0)], fdc=fdc)
    dop = GeometricDoppler(SPACE_V, sin_squint(fdc), SPACE_LAM)
    slc = focus(raw, dop, range_window=window, azimuth_window=window, range_bandwidth_fraction=0.9,
                azimuth_bandwidth_hz=SPACE_BA, **kw)
    row = float(np.interp(eta0, slc.azimuth_time, np.arange(slc.azimuth_time.size)))
    return raw, slc, row, (SPACE_R0 - slc.slant_range[0]) / SPACE_DR
