"""The emulated optical processor against the digital Range-Doppler image of the same scene.

For the brightest truth target of a simulated product, every image (digital RD, the ideal optical
processor, each device limitation alone, all of them with and without bias removal) is measured the
same way (``sarcli.focus.quality.point_target_metrics``) and converted to metres:

* position error: peak minus truth (closest-approach slant range; zero-Doppler time x platform speed);
* IRW, PSLR, ISLR in range and azimuth;
* dynamic range: peak amplitude over the rms of the image outside a guard band of 3 IRW around every
  truth target, in dB (what the image can show next to its brightest point).

Predictions stated next to the measurements (finite apertures of the device):

* range IRW = 0.886 c / (2 B) (rectangular spectrum of the chirp band B);
* azimuth IRW with ``ccd_size`` = 0.886 lam R / (2 v T), T = (rows integrated) / PRF;
* peak gain of ``light_pulse`` = sinc(dnu tau_L): the flash averages the intensity's carrier dnu;
* peak gain of ``ccd_pixels`` = sinc(2 dnu d): the pixel averages the carrier 2 dnu of the focused term
  over its delay width d.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from sarcli.design.params import doppler_bandwidth
from sarcli.errors import SarcliError
from sarcli.focus.quality import point_target_metrics
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import RawProduct
from sarcli.optical import limitations as lim
from sarcli.optical.devices import OpticalSettings, seed_mask_coefficients
from sarcli.optical.emulator import emulate, platform_speed


def brightest_target(raw: RawProduct) -> dict[str, float]:
    """Closest range, zero-Doppler time and amplitude of the brightest truth target."""
    if not raw.truth or "targets" not in raw.truth or len(raw.truth["targets"]) == 0:
        raise SarcliError("the product has no truth targets: compare needs a simulated point-target scene")
    t = raw.truth["targets"]
    amp = np.hypot(t["reflectivity_re"], t["reflectivity_im"])
    k = int(np.argmax(amp))
    return {"closest_range_m": float(t["closest_range_m"][k]),
            "zero_doppler_time_s": float(t["zero_doppler_time_s"][k]), "amplitude": float(amp[k])}


def measure(image: np.ndarray, azimuth_time: np.ndarray, slant_range: np.ndarray, raw: RawProduct,
            speed_mps: float) -> dict[str, float]:
    """Metrics (metres, dB) of the brightest truth target in an image on (azimuth_time, slant_range) axes."""
    tgt = brightest_target(raw)
    row = float(np.interp(tgt["zero_doppler_time_s"], azimuth_time, np.arange(azimuth_time.size)))
    col = float(np.interp(tgt["closest_range_m"], slant_range, np.arange(slant_range.size)))
    if not (0 <= col <= slant_range.size - 1):
        raise SarcliError(f"the brightest target ({tgt['closest_range_m']:.1f} m) is outside the image "
                          f"({slant_range[0]:.1f} .. {slant_range[-1]:.1f} m)")
    m = point_target_metrics(image, row, col, search=6, half=256)
    dr_m = float(slant_range[1] - slant_range[0])
    dt = float(np.median(np.diff(azimuth_time)))
    peak_r = float(np.interp(m["col"], np.arange(slant_range.size), slant_range))
    peak_t = float(np.interp(m["row"], np.arange(azimuth_time.size), azimuth_time))
    out = {
        "range_error_m": peak_r - tgt["closest_range_m"],
        "azimuth_error_m": (peak_t - tgt["zero_doppler_time_s"]) * speed_mps,
        "irw_range_m": m["irw_range_px"] * dr_m, "irw_azimuth_m": m["irw_azimuth_px"] * dt * speed_mps,
        "pslr_range_db": m["pslr_range_db"], "pslr_azimuth_db": m["pslr_azimuth_db"],
        "islr_range_db": m["islr_range_db"], "islr_azimuth_db": m["islr_azimuth_db"],
        "peak_amplitude": m["peak_amplitude"],
    }
    out["dynamic_range_db"] = dynamic_range_db(image, azimuth_time, slant_range, raw,
                                               3 * m["irw_azimuth_px"], 3 * m["irw_range_px"])
    return out


def dynamic_range_db(image: np.ndarray, azimuth_time: np.ndarray, slant_range: np.ndarray, raw: RawProduct,
                     guard_rows: float, guard_cols: float) -> float:
    """Peak over the rms outside +-guard rows/columns of every truth target (dB)."""
    a = np.abs(image)
    keep = np.ones(a.shape, bool)
    t = raw.truth["targets"]
    for zdt, rng in zip(t["zero_doppler_time_s"], t["closest_range_m"], strict=True):
        r = np.interp(zdt, azimuth_time, np.arange(azimuth_time.size))
        c = np.interp(rng, slant_range, np.arange(slant_range.size))
        keep[max(0, int(r - guard_rows)):int(r + guard_rows) + 1, :] = False
        keep[:, max(0, int(c - guard_cols)):int(c + guard_cols) + 1] = False
    if keep.sum() < 16:
        raise SarcliError("the image is too small to measure a background outside the targets")
    floor = math.sqrt(float(np.mean(a[keep] ** 2)))
    return 20 * math.log10(a.max() / floor) if floor > 0 else float("inf")


def predictions(raw: RawProduct, settings: OpticalSettings, rows_integrated: int, dnu: float,
                pixel_delay_s: float) -> dict[str, float]:
    """The finite-aperture predictions listed in the module docstring."""
    r = raw.radar
    B = abs(r.chirp_rate_hz_per_s) * r.pulse_length_s
    v = platform_speed(raw)
    R = brightest_target(raw)["closest_range_m"]
    T = rows_integrated / r.prf_hz
    return {
        "irw_range_m": 0.886 * C_LIGHT / (2 * B),
        "irw_azimuth_ccd_m": 0.886 * r.wavelength_m * R / (2 * v * T),
        "light_pulse_gain": float(np.sinc(dnu * settings.light_pulse_s)),
        "ccd_pixels_gain": float(np.sinc(2 * dnu * pixel_delay_s)),
    }


def cases(single_limitations: bool = True) -> list[tuple[list[str], bool]]:
    """(limitations, remove_bias) of each optical image: ideal, each limitation alone, all without and
    with bias removal."""
    out: list[tuple[list[str], bool]] = [([], False)]
    if single_limitations:
        out += [([name], False) for name in lim.ALL]
    return out + [(list(lim.ALL), False), (list(lim.ALL), True)]


def _crop(image: np.ndarray, azimuth_time: np.ndarray, slant_range: np.ndarray, raw: RawProduct,
          half_time_s: float = 0.1, half_range_m: float = 150.0) -> dict[str, np.ndarray]:
    """The same physical window (+-half_time_s, +-half_range_m) around the brightest target."""
    tgt = brightest_target(raw)
    rows = np.abs(azimuth_time - tgt["zero_doppler_time_s"]) <= half_time_s
    cols = np.abs(slant_range - tgt["closest_range_m"]) <= half_range_m
    return {"image": image[np.ix_(rows, cols)], "azimuth_time": azimuth_time[rows], "slant_range": slant_range[cols]}


def compare(raw: RawProduct, settings: OpticalSettings = OpticalSettings(),
            centre_range_m: float | None = None, single_limitations: bool = True,
            keep_images: bool = False, on_step=None) -> dict[str, Any]:
    """The comparison report (JSON-ready): design, [KimAODCCD] coefficients, predictions, one row per image.

    With ``keep_images`` the report also has ``images`` (label -> crop around the brightest target),
    which is not JSON; ``on_step(label)`` is called after each image (progress)."""
    from sarcli.focus.rda import focus_rd
    from sarcli.model.doppler import GeometricDoppler

    v = platform_speed(raw)
    if centre_range_m is None:
        centre_range_m = brightest_target(raw)["closest_range_m"]
    rows: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    # the RD processes the band the beam illuminated, not 0.8 PRF (an airborne beam a few metres long
    # spans ~100 Hz of a kHz PRF; a PRF-wide filter would make the RD aperture tens of thousands of lines)
    slc = focus_rd(raw, GeometricDoppler(v, 0.0, raw.radar.wavelength_m), azimuth_window="rect",
                   range_window="rect", azimuth_bandwidth_hz=doppler_bandwidth(raw.echo, raw.radar.prf_hz))
    rows.append({"processor": "digital RD", "limitations": [], "remove_bias": False,
                 "seconds": time.perf_counter() - t0,
                 **measure(slc.image, slc.azimuth_time, slc.slant_range, raw, v)})
    images = {"digital RD": _crop(slc.image, slc.azimuth_time, slc.slant_range, raw)} if keep_images else {}
    if on_step:
        on_step("digital RD")
    design_info: dict[str, Any] = {}
    for names, rb in cases(single_limitations):
        s = OpticalSettings(**{**settings.__dict__, "remove_bias": rb})
        t0 = time.perf_counter()
        out = emulate(raw, frozenset(names), s, centre_range_m=centre_range_m)
        secs = time.perf_counter() - t0
        label = "optical ideal" if not names else ("optical all" if len(names) > 1 else f"optical +{names[0]}")
        label += ", bias removed" if rb else ""
        if keep_images and (len(names) != 1):
            images[label] = _crop(out.image, out.azimuth_time, out.slant_range, raw)
        if on_step:
            on_step(label)
        rows.append({"processor": label, "limitations": names, "remove_bias": rb, "seconds": secs,
                     "rows_integrated": out.report["rows_integrated"], "image_columns": out.report["image_columns"],
                     **measure(out.image, out.azimuth_time, out.slant_range, raw, v)})
        if len(names) > 1:
            design_info = {**out.design.__dict__, "rows_integrated": out.report["rows_integrated"]}
    d = design_info
    u0, b2 = seed_mask_coefficients(raw.radar.carrier_frequency_hz, v, raw.radar.prf_hz,
                                    d["reference_offset_hz"], settings.aod, settings.ccd)
    report = {
        "design": d,
        "seed_notation": {"u0_cycles_per_m": u0, "b2_per_m": b2},
        "predictions": predictions(raw, settings, d["rows_integrated"], d["reference_offset_hz"],
                                   d["pixel_delay_s"]),
        "rows": rows,
    }
    if keep_images:
        report["images"] = images
    return report
