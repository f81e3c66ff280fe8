"""Physical plausibility of the numbers a product or an input states, beyond their type: the checks that
readers, the simulator and the focusing inputs share (one :class:`ProductError` line each, naming the
number and the bound it breaks). docs/products.md, "What sarcli refuses", lists them.

- a chirp: rate K (Hz/s, signed) and pulse length tau (s) with a time-bandwidth product |K| tau^2 of at
  least :data:`MIN_TIME_BANDWIDTH` = 0.01: the swept band |K| tau is then at least 1 % of the 1/tau
  spectrum of the pulse envelope itself. SAR chirps have 100 to 2000 (Radarsat-1: 1256), short test
  pulses about 1; a hundredth is a rate given in the wrong unit (Hz/us for Hz/s: a factor 1e6) or damaged
  (a MATLAB ``Kr = -1``: 1.7e-9). The band must also fit the complex sampling rate
  (:meth:`sarcli.model.raw.Radar.validate`);
- valid-sample windows [start, stop) of a record of n samples: 0 <= start < stop and start < n (a window
  beyond the record would leave a line without one sample);
- a Doppler model against the geometry (:func:`doppler_model`): the rate of a side-looking radar of
  speed V at slant range R and squint theta is fr = -2 V^2 cos^2(theta) / (lam R) (Cumming & Wong
  2005, eq. 4.38 [CumWong2005]); with the effective velocity Vr (V_ground <= Vr <= V for an orbit)
  and squints below 55 degrees, |fr| lies within a factor :data:`FR_FACTOR` of 2 V^2 / (lam R), and
  is negative. The centroid model must reproduce the product's own block estimates to a quarter PRF
  (a fit never misses its data by more: beyond that the polynomial is not the one fitted), and lie
  within |fdc| <= 2 V / lam (a squint of 90 degrees);
- sizes against memory: :func:`sarcli.memory.fits_in_memory`, before allocating.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sarcli.errors import ProductError

MIN_TIME_BANDWIDTH = 0.01  # |K| tau^2: a band of 1 % of the pulse's own 1/tau spectrum (module docstring)
FR_FACTOR = 3.0  # |fr| within [1/3, 3] x 2 V^2 / (lam R): effective velocity and squint < 55 deg
FDC_BLOCK_TOLERANCE_PRF = 0.25  # the centroid model at its blocks: within a quarter PRF of their estimates
MAX_SPEED_MPS = 1.2e4  # the fastest platform sarcli accepts (sarcli.model.raw.SPEED_MPS)


def chirp(where: str, rate_hz_per_s: float, pulse_s: float) -> None:
    """Refuse a chirp whose time-bandwidth product |K| tau^2 is below :data:`MIN_TIME_BANDWIDTH`."""
    tbp = abs(rate_hz_per_s) * pulse_s**2
    if not tbp >= MIN_TIME_BANDWIDTH:
        raise ProductError(f"{where}: chirp rate {rate_hz_per_s:g} Hz/s over a {pulse_s * 1e6:.6g} us pulse is "
                           f"implausible: time-bandwidth product |K| tau^2 = {tbp:.3g} < {MIN_TIME_BANDWIDTH:g} (a "
                           "rate in the wrong unit, or damaged?)")


def sample_windows(where: str, name: str, windows: np.ndarray, n_samples: int) -> np.ndarray:
    """Valid-sample windows ``(..., 2)`` [start, stop) of a record of ``n_samples``: refuse a window with
    start < 0, stop <= start or start >= n_samples (a stop beyond the record is a range cut: allowed)."""
    w = np.asarray(windows)
    start, stop = w[..., 0], w[..., 1]
    for bad, what in ((start < 0, "starts before sample 0"), (stop <= start, "ends before it starts"),
                      (start >= n_samples, f"starts beyond the {n_samples} samples of the record")):
        if np.any(bad):
            k = np.argwhere(bad)[0]
            raise ProductError(f"{where}: {name} window {w[tuple(k)].tolist()} (line {int(k[0])}) {what}: "
                               "refusing an echo with no valid sample")
    return w


def platform_speed(raw: Any) -> float | None:
    """The platform speed (m/s) a raw product states: ``radar.platform_velocity_mps``, else the median
    |v| of its state vectors; None without either."""
    if raw.radar.platform_velocity_mps:
        return float(raw.radar.platform_velocity_mps)
    if raw.orbit is not None and len(raw.orbit.velocity):
        return float(np.median(np.linalg.norm(raw.orbit.velocity, axis=1)))
    return None


def doppler_model(where: str, model: Any, raw: Any, shape: tuple[int, int]) -> None:
    """Refuse a Doppler model that contradicts the geometry of ``raw`` (module docstring): evaluated on a
    5 x 5 grid of the scene's (range, time), fr must be finite and negative with |fr| within
    :data:`FR_FACTOR` of 2 V^2 / (lam R) (V the platform speed; without one, the fastest platform
    :data:`MAX_SPEED_MPS` bounds it from above), fdc finite with |fdc| <= 2 V / lam, and a model that
    carries its block estimates must reproduce them to :data:`FDC_BLOCK_TOLERANCE_PRF` of the PRF."""
    from sarcli.model.constants import C_LIGHT

    radar = raw.radar
    lam = radar.wavelength_m
    r = radar.first_range_m + np.linspace(0.0, shape[1] - 1, 5) * C_LIGHT / (2.0 * radar.range_sampling_rate_hz)
    t = np.linspace(raw.azimuth_time[0], raw.azimuth_time[-1], 5)
    rr, tt = np.meshgrid(r, t)
    with np.errstate(all="ignore"):
        fr = np.asarray(model.fr(rr, tt), np.float64)
        fdc = np.asarray(model.fdc(rr, tt), np.float64)
    v = platform_speed(raw)
    if not (np.all(np.isfinite(fr)) and np.all(fr < 0)):
        raise ProductError(f"{where}: the Doppler rate must be finite and negative over the scene, got "
                           f"{np.nanmin(fr):.6g} .. {np.nanmax(fr):.6g} Hz/s")
    ref = 2.0 * (v if v else MAX_SPEED_MPS) ** 2 / (lam * rr)
    ratio = np.abs(fr) / ref
    lo = 1.0 / FR_FACTOR if v else 0.0
    if not np.all((ratio >= lo) & (ratio <= FR_FACTOR)):
        k = np.unravel_index(np.argmax(np.abs(np.log(ratio))), ratio.shape)
        raise ProductError(f"{where}: Doppler rate {fr[k]:.6g} Hz/s at {rr[k]:.0f} m is implausible: "
                           f"2 V^2 / (lam R) = {ref[k]:.6g} Hz/s (V = {v if v else MAX_SPEED_MPS:.0f} m/s"
                           f"{'' if v else ', the fastest platform'}); expected within a factor {FR_FACTOR:g}")
    fmax = 2.0 * (v if v else MAX_SPEED_MPS) / lam
    if not (np.all(np.isfinite(fdc)) and np.all(np.abs(fdc) <= fmax)):
        raise ProductError(f"{where}: Doppler centroid {np.nanmax(np.abs(fdc)):.6g} Hz is implausible "
                           f"(|fdc| <= 2 V / lam = {fmax:.6g} Hz)")
    _centroid_matches_blocks(where, model)


def _centroid_matches_blocks(where: str, model: Any) -> None:
    b = getattr(model, "blocks", None) or {}
    if not all(k in b for k in ("range_m", "azimuth_time_s", "fdc_hz")):
        return
    keep = np.isfinite(b["fdc_hz"]) & np.isfinite(b["range_m"]) & np.isfinite(b["azimuth_time_s"])
    for flag, want in (("valid", True), ("outlier", False)):
        if flag in b and np.size(b[flag]) == np.size(keep):
            keep &= np.asarray(b[flag], bool) == want
    if not np.any(keep):
        return
    with np.errstate(all="ignore"):
        miss = np.abs(np.asarray(model.fdc(b["range_m"][keep], b["azimuth_time_s"][keep])) - b["fdc_hz"][keep])
    bound = FDC_BLOCK_TOLERANCE_PRF * model.prf_hz
    if not np.median(miss) <= bound:
        raise ProductError(f"{where}: the Doppler centroid model misses its own block estimates by "
                           f"{np.nanmedian(miss):.6g} Hz (median), more than a quarter PRF ({bound:.6g} Hz): the "
                           "polynomial is not the one fitted (a damaged product?)")
