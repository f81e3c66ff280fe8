"""Hyperbolic range model behind the RDA: effective velocity, squint and beam-centre offset.

Model (Cumming & Wong ch. 4, in the project's sign convention): a target with zero-Doppler time eta0
and closest-approach range R0 is seen at

    R(eta) = sqrt(R0^2 + V^2 (eta - eta0)^2),     f(eta) = -(2/lam) dR/deta = -(2/lam) V^2 (eta - eta0) / R

with ``V`` the effective (range-dependent) velocity. At the beam centre eta_c the squint angle theta
obeys sin(theta) = V (eta_c - eta0) / R_c, R_c = R0 / cos(theta), hence

    fdc = -(2 V / lam) sin(theta)                                        (centroid)
    fr  = -(2/lam) d2R/deta2 = -(2/lam) V^2 R0^2 / R_c^3 = -2 V^2 cos^3(theta) / (lam R0)   (rate)
    Delta = eta_c - eta0 = R0 tan(theta) / V                             (beam-centre offset)

Given (fdc, fr) from a Doppler model, V and theta follow from the fixed point
``V^2 = -fr lam R0 / (2 cos^3 theta)``, ``sin theta = -fdc lam / (2 V)``, iterated until V changes by
less than 1e-13 relative (the error shrinks about 1.5 sin^2(theta)-fold per step: 6 steps at 2 deg,
20 at 15 deg); where it diverges (large squint, or a rate read at R0 instead of R_c, whose apparent squint
is larger), by Newton's method on the same equation. In the range-Doppler domain a target sits at range R0 / D(f) with
the migration factor ``D(f) = sqrt(1 - (lam f / (2 V))^2)`` and its spectrum has phase
``-4 pi R0 D(f) / lam - 2 pi f eta0`` (POSP). The Doppler model's range argument is the beam-centre
slant range R_c (where a target's echo energy sits in the raw data).
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError


def velocity_and_squint(fdc_hz: np.ndarray, fr_hz_per_s: np.ndarray, r0_m: np.ndarray,
                        wavelength_m: float, max_iterations: int = 100) -> tuple[np.ndarray, np.ndarray]:
    """Effective velocity V (m/s) and sin(squint) from centroid and rate at closest range R0.

    Refuses (one line) a rate that is not negative, near zero, or not finite, and a centroid that
    would need a squint beyond 60 degrees.
    """
    fdc = np.asarray(fdc_hz, dtype=np.float64)
    fr = np.asarray(fr_hz_per_s, dtype=np.float64)
    r0 = np.asarray(r0_m, dtype=np.float64)
    if not (np.all(np.isfinite(fdc)) and np.all(np.isfinite(fr))):
        raise SarcliError("Doppler model gives NaN or inf centroid/rate over the scene")
    if np.any(fr >= 0.0):
        raise SarcliError(f"Doppler rate must be negative for a side-looking SAR (got max {fr.max():.4g} Hz/s):"
                          " check the sign of the Doppler model")
    # |fr| must give a velocity of at least 1 m/s: a smaller rate has no usable synthetic aperture
    fr_min = 2.0 / (wavelength_m * float(np.max(r0)))
    if np.any(-fr < fr_min):
        raise SarcliError(f"Doppler rate {fr.max():.3g} Hz/s is too close to zero to focus (|fr| < {fr_min:.2g})")
    cos3 = np.ones_like(fr * r0)
    v_old = np.zeros_like(cos3)
    s = np.zeros_like(cos3)
    for _ in range(max_iterations):
        v = np.sqrt(-fr * wavelength_m * r0 / (2.0 * cos3))
        if np.all(np.abs(v - v_old) <= 1e-13 * v):
            return v, s
        v_old = v
        s = -fdc * wavelength_m / (2.0 * v)
        if np.any(np.abs(s) > np.sin(np.radians(60.0))):
            break
        cos3 = (1.0 - s * s) ** 1.5
    # the fixed point diverges where 1.5 tan^2(theta) > 1 (squint beyond ~39 deg): Newton's method instead
    v, s = _velocity_and_squint_newton(fdc, fr, r0, wavelength_m)
    if np.any(np.abs(s) > np.sin(np.radians(60.0))):
        raise SarcliError(f"Doppler centroid {np.abs(fdc).max():.4g} Hz implies a squint beyond 60 deg:"
                          " check the centroid and its ambiguity")
    return v, s


def _velocity_and_squint_newton(fdc: np.ndarray, fr: np.ndarray, r0: np.ndarray,
                                wavelength_m: float) -> tuple[np.ndarray, np.ndarray]:
    """The same solution by Newton's method, for any squint: with p = (lam fdc / 2)^2, q = -fr lam R0 / 2
    and z = V^2 - p = V^2 cos^2(theta), the model reads z^(3/2) = q sqrt(z + p), i.e. in w = ln z
    h(w) = 1.5 w - 0.5 ln(e^w + p) - ln q = 0, with h' = 1.5 - 0.5 e^w / (e^w + p) in [1, 1.5] and h
    concave: Newton converges from any start (w0 = 2/3 ln q, the broadside solution), quadratically."""
    p = (wavelength_m * fdc / 2.0) ** 2
    lq = np.log(-fr * wavelength_m * r0 / 2.0)
    w = np.broadcast_to(2.0 / 3.0 * lq, np.broadcast(p, lq).shape).copy()
    for _ in range(60):
        ez = np.exp(w)
        step = (1.5 * w - 0.5 * np.log(ez + p) - lq) / (1.5 - 0.5 * ez / (ez + p))
        w -= step
        if np.all(np.abs(step) <= 1e-15):
            break
    v = np.sqrt(np.exp(w) + p)
    return v, -fdc * wavelength_m / (2.0 * v)


def migration_factor(f_hz: np.ndarray, v_mps: np.ndarray, wavelength_m: float) -> np.ndarray:
    """D(f) = sqrt(1 - (lam f / 2V)^2)."""
    x = (wavelength_m * np.asarray(f_hz) / (2.0 * np.asarray(v_mps))) ** 2
    if np.any(x >= 1.0):
        raise SarcliError("azimuth frequency exceeds 2V/lam: inconsistent Doppler model")
    return np.sqrt(1.0 - x)


def beam_centre_offset(r0_m: np.ndarray, v_mps: np.ndarray, sin_squint: np.ndarray) -> np.ndarray:
    """Delta = eta_c - eta0 = R0 tan(theta) / V (s): beam-centre time after zero-Doppler time."""
    s = np.asarray(sin_squint)
    return np.asarray(r0_m) * s / (np.sqrt(1.0 - s * s) * np.asarray(v_mps))


def aperture_time(fr_hz_per_s: np.ndarray, bandwidth_hz: float) -> np.ndarray:
    """Time (s) a target spends inside a processed Doppler band ``bandwidth_hz`` (linear-FM approx)."""
    return bandwidth_hz / np.abs(np.asarray(fr_hz_per_s))
