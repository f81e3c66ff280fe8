"""The AOD/CCD processor emulated on a raw product (see ``devices`` for the signal chain).

Per pulse n (all in two-way delay tau; the CCD column j covers [tau_j - d/2, tau_j + d/2], d the pixel
delay of the design):

1. ``aod_bandwidth``: band-limit the baseband echo to the AOD passband.
2. Interpolate to a fine delay grid (band-limited, FFT) fine enough for the mask carrier 2 dnu.
3. ``aod_aperture``: zero what is outside the AOD at the flash, [t_f - T_a, t_f].
4. Range correlation with the chirp (space-integrating correlator): g_n(tau), unit peak for a unit chirp.
5. Detection: ``detector_intensity`` -> I = |g + A e^{j theta}|^2 (A = reference_ratio * max|g|),
   theta = 2 pi dnu tau; else the ideal linear term I = A g e^{-j theta}.
6. ``light_pulse``: I smeared by a box of tau_L (the acoustic wave moves during the flash).
7. Pixel read-out weights: P0_j = <I>, P_j = <I e^{-j theta}>, over the pixel (``ccd_pixels``) or at
   its centre. The mask chirp psi varies by < 1e-3 of itself across a pixel and is taken at the centre.
8. CCD transfer + mask: packet k collects pulse n through mask row r = k - n (r_c = centre row):
   ``mask`` -> Q = 1/2 sum_r P0 + 1/2 Re{sum_r P e^{-j psi}} (eq. 12 transmittance; with
   ``remove_bias`` the complementary exposure 1/2(1 - cos) is subtracted before read-out, leaving
   Re{sum P e^{-j psi}}); else the ideal complex reference Q = sum_r P e^{-j psi}.
9. ``adc``: n-bit quantization over the charge range. 10. Demodulate: Q e^{+j 2 theta_j}, low-pass
   |f| < B/2 along the columns (Kaiser FIR) -> the focused complex image, scaled back to unit target
   amplitude; the columns the filter cannot fully support at the CCD edges are dropped.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
import scipy.fft as sfft
from scipy.signal import fftconvolve

from sarcli.errors import SarcliError
from sarcli.focus.rangecomp import reference_pulse
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import RawProduct
from sarcli.optical import limitations as lim
from sarcli.optical.devices import OpticalDesign, OpticalSettings, design, mask_phase


@dataclass
class OpticalImage:
    """Emulated processor output: complex image (azimuth rows = raw lines, range columns)."""

    image: np.ndarray  # complex64 (n_lines, n_columns), unit target amplitude
    azimuth_time: np.ndarray  # s after the product epoch, zero-Doppler time of each row
    slant_range: np.ndarray  # m, centre of each column
    charge: np.ndarray  # the CCD read-out before demodulation (real or complex)
    design: OpticalDesign
    limitations: frozenset[str]
    report: dict = field(default_factory=dict)


def platform_speed(raw: RawProduct) -> float:
    """|v| of an airborne (LOCAL-frame) product, or ``radar.platform_velocity_mps``."""
    if raw.radar.platform_velocity_mps:
        return float(raw.radar.platform_velocity_mps)
    if raw.orbit is not None and raw.orbit.frame == "LOCAL":
        return float(np.median(np.linalg.norm(raw.orbit.velocity, axis=1)))
    raise SarcliError("optical emulation needs an airborne product (LOCAL orbit frame) or "
                      "radar.platform_velocity_mps: the AOD/CCD processor assumes a straight, uniform track")


def _box(x: np.ndarray, width: int, axis: int = -1) -> np.ndarray:
    """Centred moving average of ``width`` samples along ``axis`` (same length)."""
    if width <= 1:
        return x
    k = np.ones(width) / width
    shape = [1] * x.ndim
    shape[axis] = width
    return fftconvolve(x, k.reshape(shape), mode="same", axes=axis)


def emulate(raw: RawProduct, limitations: frozenset[str] | str = frozenset(),
            settings: OpticalSettings = OpticalSettings(), channel: int = 0,
            centre_range_m: float | None = None) -> OpticalImage:
    """Run the emulated AOD/CCD processor on ``raw`` with the listed device limitations."""
    lims = lim.parse(limitations) if isinstance(limitations, str) else frozenset(limitations)
    r = raw.radar
    echo = np.asarray(raw.channel(channel))
    n_lines, n_samples = echo.shape
    if not np.any(echo):
        raise SarcliError("the raw echo is all zero: nothing to process")
    v = platform_speed(raw)
    lam, fs, prf = r.wavelength_m, r.range_sampling_rate_hz, r.prf_hz
    B = abs(r.chirp_rate_hz_per_s) * r.pulse_length_s
    tau0 = r.window_start_s
    valid_lo, valid_hi = tau0 + r.pulse_length_s / 2, tau0 + (n_samples - 1) / fs - r.pulse_length_s / 2
    if valid_hi <= valid_lo:
        raise SarcliError("the range window is shorter than one pulse: nothing can be range-compressed")
    ccd = settings.ccd
    finite_ccd = "ccd_size" in lims  # else: columns over the whole valid window, every line integrated
    centre = (valid_lo + valid_hi) / 2
    if finite_ccd and centre_range_m is not None:
        centre = 2 * centre_range_m / C_LIGHT
    des = design(B, r.pulse_length_s, centre, settings, max_pulses=None if finite_ccd else n_lines)
    n_cols = ccd.columns if finite_ccd else int(math.floor((valid_hi - valid_lo) / des.pixel_delay_s))
    col_delay = des.centre_delay_s + (np.arange(n_cols) - (n_cols - 1) / 2) * des.pixel_delay_s
    rows = min(des.aperture_pulses, n_lines) if finite_ccd else n_lines
    rows -= 1 - rows % 2  # odd: the mask's centre row is a row
    dnu = des.reference_offset_hz

    # fine delay grid: an integer number of samples per pixel, fine enough for 2 dnu + B/2
    per_pixel = max(4, int(math.ceil(4 * (2 * dnu + B / 2) * des.pixel_delay_s)))
    fine_dt = des.pixel_delay_s / per_pixel
    up = fs * fine_dt  # raw samples per fine sample (<1)
    n_fft_raw = sfft.next_fast_len(n_samples)
    n_fine = int(math.ceil(n_fft_raw / up))
    n_fine = sfft.next_fast_len(n_fine)
    fine_dt = n_fft_raw / (fs * n_fine)  # exact band-limited interpolation grid
    fine_delay = tau0 + np.arange(n_fine) * fine_dt
    chirp = reference_pulse(dataclasses.replace(r, range_sampling_rate_hz=1.0 / fine_dt))
    chirp_f = np.conj(sfft.fft(chirp, n_fine)) / np.sum(np.abs(chirp) ** 2)
    # the chirp reference is centred: shift so that the output sample sits at the pulse centre
    chirp_f *= np.exp(-2j * np.pi * sfft.fftfreq(n_fine) * (chirp.size - 1) / 2)
    f_raw = sfft.fftfreq(n_fft_raw, 1 / fs)
    passband = np.ones(n_fft_raw)
    if "aod_bandwidth" in lims:
        passband = (np.abs(f_raw) <= settings.aod.bandwidth_hz / 2).astype(float)
    aod_window = np.ones(n_fine)
    if "aod_aperture" in lims:
        aod_window = ((fine_delay >= des.flash_delay_s - settings.aod.time_aperture_s)
                      & (fine_delay <= des.flash_delay_s)).astype(float)
    # fine samples of each pixel (pixel integration) or its centre (point sampling)
    theta_fine = 2 * np.pi * dnu * fine_delay
    idx_centre = np.round((col_delay - tau0) / fine_dt).astype(int)
    if idx_centre[0] - per_pixel // 2 < 0 or idx_centre[-1] + per_pixel // 2 >= n_fine:
        raise SarcliError("the CCD swath reaches outside the raw range window; choose a centre range inside it")
    offs = np.arange(per_pixel) - per_pixel // 2 if "ccd_pixels" in lims else np.zeros(1, int)
    pix_idx = idx_centre[:, None] + offs[None, :]
    smear = max(1, int(round(settings.light_pulse_s / fine_dt))) if "light_pulse" in lims else 1

    P0 = np.zeros((n_lines, n_cols), np.complex128)
    P = np.zeros((n_lines, n_cols), np.complex128)
    Pp = np.zeros((n_lines, n_cols), np.complex128)
    block = 128
    a_ref = None
    for start in range(0, n_lines, block):
        e = echo[start:start + block].astype(np.complex128)
        E = sfft.fft(e, n_fft_raw, axis=1) * passband
        # band-limited interpolation: zero-pad the spectrum to n_fine
        Ef = np.zeros((e.shape[0], n_fine), np.complex128)
        half = n_fft_raw // 2
        Ef[:, :half] = E[:, :half]
        Ef[:, -(n_fft_raw - half):] = E[:, half:]
        fine = sfft.ifft(Ef, axis=1) * (n_fine / n_fft_raw)
        fine *= aod_window
        g = sfft.ifft(sfft.fft(fine, axis=1) * chirp_f, axis=1)
        if a_ref is None:
            peak = float(np.max(np.abs(g[:, idx_centre]))) if np.any(g) else 1.0
            a_ref = settings.reference_ratio * (peak if peak > 0 else 1.0)
        if "detector_intensity" in lims:
            intensity = np.abs(g + a_ref * np.exp(1j * theta_fine)) ** 2
        else:
            intensity = a_ref * g * np.exp(-1j * theta_fine)
        intensity = _box(intensity, smear, axis=1)
        sel = intensity[:, pix_idx]  # (lines, cols, samples per pixel)
        P0[start:start + block] = sel.mean(axis=2)
        P[start:start + block] = (sel * np.exp(-1j * theta_fine[pix_idx])).mean(axis=2)
        Pp[start:start + block] = (sel * np.exp(1j * theta_fine[pix_idx])).mean(axis=2)

    r_c = (rows - 1) / 2
    row_off = np.arange(rows) - r_c
    psi = mask_phase(col_delay[None, :], row_off[:, None], v, lam, prf)  # (rows, cols)
    lo = int(r_c)

    def ccd_sum(p: np.ndarray, kernel: np.ndarray) -> np.ndarray:
        """Charge packets: sum over mask rows r of p[k - r] * kernel[r] (aligned to the raw lines)."""
        return fftconvolve(p, kernel, axes=0, mode="full")[lo:lo + n_lines]

    if "mask" in lims:
        # T = 1/2 + 1/4 e^{j(theta + psi)} + 1/4 e^{-j(theta + psi)}; P = <I e^{-j theta}>, P+ = <I e^{+j theta}>
        modulated = 0.25 * (ccd_sum(P, np.exp(-1j * psi)) + ccd_sum(Pp, np.exp(1j * psi)))
        if settings.remove_bias:  # complementary exposure 1/2 (1 - cos) subtracted before read-out
            Q, scale = 2.0 * modulated, 2.0
        else:
            Q, scale = 0.5 * ccd_sum(P0, np.ones((rows, 1))) + modulated, 4.0
        if "detector_intensity" in lims:
            Q = np.real(Q)  # real intensity through a real mask: the charge is real
    else:  # ideal complex reference e^{-j(theta + psi)}: no mask bias
        Q, scale = ccd_sum(P, np.exp(-1j * psi)), 1.0
    if "adc" in lims:
        Q = _quantize(Q, ccd.adc_bits, np.random.default_rng(settings.seed))
    demod = Q * np.exp(2j * np.pi * 2 * dnu * col_delay)[None, :]
    fir = demod_filter(B, des.pixel_delay_s)
    edge = fir.size // 2  # columns where the filter reaches past the CCD edge are not image
    if n_cols <= 2 * edge:
        raise SarcliError(f"{n_cols} CCD columns are too few to demodulate (need more than {2 * edge})")
    img = fftconvolve(demod, fir[None, :], mode="valid", axes=1) * (scale / a_ref)
    return OpticalImage(
        image=img.astype(np.complex64),
        azimuth_time=np.asarray(raw.azimuth_time, np.float64),
        slant_range=C_LIGHT * col_delay[edge:n_cols - edge] / 2,
        charge=np.asarray(Q),
        design=des,
        limitations=lims,
        report={"rows_integrated": rows, "columns": n_cols, "image_columns": n_cols - 2 * edge,
                "fine_samples_per_pixel": per_pixel,
                "reference_amplitude": a_ref, "platform_speed_mps": v,
                "bias_fraction": _bias_fraction(Q) if np.isrealobj(Q) else 0.0},
    )


def demod_filter(bandwidth_hz: float, pixel_delay_s: float) -> np.ndarray:
    """Low-pass FIR (Kaiser, ~80 dB stop band) along the columns keeping the compressed band |f| < B/2.

    Unit gain at DC; about 8 resolution cells long. A brick-wall FFT mask would spread the strong bias
    tones through its rectangular-window sidelobes into the image: a filter artifact, not the device.
    """
    from scipy.signal import firwin

    half = int(math.ceil(4.0 / (bandwidth_hz * pixel_delay_s)))
    return firwin(2 * half + 1, 0.55 * bandwidth_hz, window=("kaiser", 8.0), fs=1.0 / pixel_delay_s)


def _quantize(Q: np.ndarray, bits: int, rng: np.random.Generator) -> np.ndarray:
    """n-bit uniform read-out spanning the charge range (real: [min, max]; complex: per component).

    The CCD's read noise (0.5 LSB rms, Gaussian) dithers the converter, as on a real device; without it
    a smooth, wide main lobe would read out as a staircase.
    """
    if np.iscomplexobj(Q):
        return _quantize(Q.real, bits, rng) + 1j * _quantize(Q.imag, bits, rng)
    lo, hi = float(Q.min()), float(Q.max())
    if hi <= lo:
        return Q
    step = (hi - lo) / (2**bits - 1)
    noisy = (Q - lo) / step + rng.normal(0.0, 0.5, Q.shape)
    return lo + np.clip(np.round(noisy), 0, 2**bits - 1) * step


def _bias_fraction(Q: np.ndarray) -> float:
    """Share of the read-out range taken by the mean level (the bias) rather than its variation."""
    span = float(Q.max() - Q.min())
    return float(abs(np.mean(Q)) / (abs(np.mean(Q)) + span)) if span > 0 else 1.0
