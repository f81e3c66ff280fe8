"""GB-SAR interferometry of [LeeGBSAR-I-2007, eq. 5-14]: DInSAR, cross-track, delta-f and combined modes.

Both images carry the phase ``-4 pi f_c R0/c`` of a scatterer at distance R0 from their own rail
line. The interferogram is ``z = B * conj(A)`` (secondary times conjugate reference, ``phi = phi_B - phi_A``).
For a surface point P at height h, horizontal distance y from the rail:

* DInSAR (same geometry, P moved by r along the line of sight): ``phi = -(4 pi/lam) r``
  -> -12729 deg per metre (1 mm -> -12.7 deg). [LeeGBSAR-I-2007, §3.2] prints ``phi = (4 pi/lam) r`` with the
  negative rate; the sign here follows the phase convention.
* Cross-track (B's rail higher by Bv): ``R_B^2 = y^2 + (H_B - h)^2`` so
  ``phi = -(4 pi/lam)(R_B - R_A) ~ -(4 pi/lam) Bv (H - h)/R``; at fixed pixel range R,
  ``dphi/dh = (4 pi/lam_B) Bv/R_B`` (-38.2 deg/m at 100 m for Bv = -0.3 m) and on a flat surface
  ``dphi/dR = (4 pi/lam) Bv (H - h)/R^2`` (-8.0 deg/m at 100 m, H = 21 m).
* Delta-f (f_B = f_A + df): ``phi = -(4 pi/c) df R`` -> +24.0 deg/m for df = -10 MHz (15 m a fringe).
* Combined: ``phi = -(4 pi/c)(f_B R_B - f_A R_A)``: 16.0 deg/m at 100 m (24.0 - 8.0).

The model phase of a flat surface at ``z_ref`` is removed, the wrapped residual is unwrapped spatially
(:mod:`sarcli.gbsar.unwrap`, SNAPHU weighted by the coherence; one 2 pi multiple per connected
component fixed by its median) and the unwrapped residual converted: DInSAR ->
LOS displacement ``-residual lam/(4 pi)`` (mm, + = away from the radar); cross-track and combined
-> height ``z_ref + residual/(dphi/dh)``; delta-f -> range offset ``-residual c/(4 pi df)`` from the pixel
range (delta-f measures range, not height; ambiguity c/(2 df)).

Masking: a pixel is defined only where both images have support (:func:`support`: covered by the
focusing algorithm, non-zero, inside the beam footprint of some rail stop); elsewhere phase, coherence,
residual and value are NaN (an unsupported pixel is 0 in the image, and ``angle(+-0 +- 0j)`` is 0 or
+-pi by the signs of the zeros: bands of half-ambiguity "heights"). The converted value is also NaN where
the coherence is below ``min_coherence`` (default 0.5). The default sits above the bias of the boxcar
estimator on pixels with no correlation at all (``E|gamma| ~ sqrt(pi/(4 L))`` for L independent looks:
0.18 for 25 looks, ~0.3 for the ~9 independent looks of an oversampled 5 x 5 window) and keeps pixels whose
phase standard deviation ``sqrt((1 - g^2)/(2 L g^2))`` (Cramer-Rao) is <= 14 deg at L = 25 (0.37 m of height
at 100 m for Bv = 0.3 m, 1.1 mm of LOS displacement).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter

from sarcli.errors import ProductError, SarcliError
from sarcli.model.constants import C_LIGHT
from sarcli.model.gbsar import GbsarImage

MODES = ("dinsar", "crosstrack", "deltaf", "combined")


def pol_index(img: GbsarImage, pol: str) -> int:
    """Index of ``pol`` in the image's first axis (the pixels are not read: ``image`` may be on disk)."""
    if pol not in img.polarizations:
        raise ProductError(f"image has polarizations {','.join(img.polarizations)}, not {pol}")
    return img.polarizations.index(pol)


def check_same_grid(a: GbsarImage, b: GbsarImage, pol: str) -> None:
    """One-line errors for images whose frequency grid, pixel grid or polarizations differ."""
    if a.n_freq != b.n_freq or not np.isclose(a.frequency_step_hz, b.frequency_step_hz, rtol=1e-9):
        raise SarcliError(f"the scans have different frequency grids ({a.n_freq} x {a.frequency_step_hz:g} Hz vs "
                          f"{b.n_freq} x {b.frequency_step_hz:g} Hz): their range pixels differ")
    if a.range_m.shape != b.range_m.shape or a.azimuth_m.shape != b.azimuth_m.shape or \
            not np.allclose(a.range_m, b.range_m, atol=1e-6) or not np.allclose(a.azimuth_m, b.azimuth_m, atol=1e-6):
        raise SarcliError("the images are on different grids; focus both with the same --max-range/--pixel-x/--width")
    for img in (a, b):
        pol_index(img, pol)


def check_compatible(a: GbsarImage, b: GbsarImage, mode: str, pol: str) -> None:
    """One-line errors for images that cannot be combined in ``mode``."""
    if mode not in MODES:
        raise SarcliError(f"unknown interferometric mode '{mode}' (use {', '.join(MODES)})")
    check_same_grid(a, b, pol)
    df = b.center_frequency_hz - a.center_frequency_hz
    bv = b.rail_height_m - a.rail_height_m
    if mode in ("dinsar", "crosstrack") and abs(df) > 1e-3:
        raise SarcliError(f"the centre frequencies differ by {df:g} Hz: use --mode deltaf or combined")
    if mode in ("dinsar", "deltaf") and abs(bv) > 1e-6:
        raise SarcliError(f"the rail heights differ by {bv:g} m: use --mode crosstrack or combined")
    if mode in ("crosstrack", "combined") and abs(bv) <= 1e-6:
        raise SarcliError("no vertical baseline between the scans: cross-track height needs one")
    if mode == "deltaf" and abs(df) <= 1e-3:
        raise SarcliError("the centre frequencies are equal: delta-f needs a frequency shift")


def coherence(a: np.ndarray, b: np.ndarray, window: int) -> np.ndarray:
    """Sample coherence ``|<b a*>| / sqrt(<|a|^2><|b|^2>)`` over a ``window`` x ``window`` boxcar."""
    if window < 1:
        raise SarcliError("the coherence window must be >= 1 pixel")
    z = b * np.conj(a)
    num = np.hypot(uniform_filter(z.real.astype(np.float64), window), uniform_filter(z.imag.astype(np.float64), window))
    pa = uniform_filter(np.abs(a).astype(np.float64) ** 2, window)
    pb = uniform_filter(np.abs(b).astype(np.float64) ** 2, window)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(pa * pb > 0, num / np.sqrt(pa * pb), 0.0).astype(np.float32)


def support(img: GbsarImage, pol: str, rows: slice = slice(None), values: np.ndarray | None = None) -> np.ndarray:
    """(n_r, n_x) bool (or the ``rows`` block of it): pixels the image has data for.

    Covered by its algorithm (``algorithm_map != 0``), non-zero, and -- when the product records the
    footprint's L_x (``report["footprint_antenna_length_m"]``) -- seen by some rail stop: the pixel's
    synthetic aperture, the rail ``[x_c - X/2, x_c + X/2]`` intersected with the beam footprint
    ``|x - x_i| <= lam R0/(2 L_x)`` ([LeeGBSAR-II-2007, Fig. 2], as in BP and DF), is not empty. RD leaks energy
    outside the footprint (non-zero there), so the geometric test is needed beside the zero test.
    ``values``: the block ``image[pol, rows]`` when the caller has read it already (it is read otherwise).
    """
    if values is None:
        values = img.image[pol_index(img, pol), rows]
    ok = (img.algorithm_map[rows] != 0) & (np.asarray(values) != 0)
    lx = img.report.get("footprint_antenna_length_m")
    if lx:
        off_rail = np.maximum(np.abs(img.azimuth_m - img.rail_centre_m) - img.rail_length_m / 2, 0.0)
        ok &= off_rail[None, :] <= img.wavelength_m * img.range_m[rows, None] / (2 * lx)
    return ok


def surface_ranges(r0_a: np.ndarray, h_a: float, h_b: float, z_ref: float) -> np.ndarray:
    """Range from B's rail of the surface point (height z_ref) seen at range r0_a from A's rail (NaN if none)."""
    with np.errstate(invalid="ignore"):
        y2 = r0_a ** 2 - (h_a - z_ref) ** 2
    return np.where(y2 >= 0, np.sqrt(np.abs(y2) + (h_b - z_ref) ** 2), np.nan)


@dataclass
class Interferogram:
    phase: np.ndarray  # raw interferometric phase (rad), (n_r, n_x)
    coherence: np.ndarray
    model_phase: np.ndarray
    residual: np.ndarray  # phase after removing the model (rad, wrapped)
    value: np.ndarray  # converted: LOS mm | height m | range offset m
    value_name: str
    value_unit: str
    rate: dict
    support: np.ndarray  # bool, both images have data (phase, coherence, residual NaN elsewhere)
    unwrapped: np.ndarray  # residual unwrapped spatially (rad), NaN outside the connected components
    component: np.ndarray  # int32 connected component of each pixel (0: none)
    unwrap_method: str


#: independent looks of a w x w boxcar coherence on sarcli's GB-SAR images (about 1.7 x oversampled in
#: each axis by the Hamming-windowed focusing): w^2 / 2.8, ~9 looks for the default 5 x 5 window
LOOKS_PER_WINDOW_PIXEL = 1.0 / 2.8


def interfere(a: GbsarImage, b: GbsarImage, mode: str, pol: str, window: int = 5,
              z_ref_m: float = 0.0, min_coherence: float = 0.5) -> Interferogram:
    """Interferogram of B against A in ``mode`` (see the module docstring); the value is NaN outside
    the common support and where the coherence is below ``min_coherence`` (0 keeps every supported pixel)."""
    if not 0.0 <= min_coherence <= 1.0:
        raise SarcliError(f"the minimum coherence must be in [0, 1], not {min_coherence:g}")
    check_compatible(a, b, mode, pol)
    ia, ib = a.pol(pol), b.pol(pol)
    ok = support(a, pol) & support(b, pol)
    z = ib * np.conj(ia)
    phase = np.where(ok, np.angle(z), np.nan).astype(np.float32)
    coh = np.where(ok, coherence(ia, ib, window), np.nan).astype(np.float32)
    fa, fb = a.center_frequency_hz, b.center_frequency_hz
    r0 = a.range_m[:, None] * np.ones((1, a.azimuth_m.size))
    rb = surface_ranges(r0, a.rail_height_m, b.rail_height_m, z_ref_m)
    bv, dfreq = b.rail_height_m - a.rail_height_m, fb - fa
    if mode == "dinsar":
        model = np.zeros_like(r0)
    elif mode == "deltaf":
        model = -4 * np.pi * dfreq * r0 / C_LIGHT
    else:  # crosstrack (fa == fb) and combined
        model = -4 * np.pi * (fb * rb - fa * r0) / C_LIGHT
    resid = np.angle(z * np.exp(-1j * np.nan_to_num(model))).astype(np.float32)
    resid[~(np.isfinite(model) & ok)] = np.nan
    from sarcli.gbsar.unwrap import unwrap

    unw = unwrap(resid, coh, nlooks=window * window * LOOKS_PER_WINDOW_PIXEL)
    lam_a, lam_b = C_LIGHT / fa, C_LIGHT / fb
    uphase = unw.phase.astype(np.float64)
    if mode == "dinsar":
        value, name, unit = -uphase * lam_a / (4 * np.pi) * 1e3, "los_displacement", "mm"
        rate = {"deg_per_m_los": -720.0 / lam_a}
    elif mode == "deltaf":
        value, name, unit = -uphase * C_LIGHT / (4 * np.pi * dfreq), "range_offset", "m"
        rate = {"deg_per_m_range": -720.0 * dfreq / C_LIGHT, "ambiguity_m": C_LIGHT / (2 * abs(dfreq))}
    else:
        with np.errstate(invalid="ignore", divide="ignore"):
            dphi_dh = 4 * np.pi * bv / (lam_b * rb)
            value = z_ref_m + uphase / dphi_dh
        name, unit = "height", "m"
        rate = {"deg_per_m_height_at_100m": np.degrees(4 * np.pi * bv / (lam_b * 100.0)),
                "height_ambiguity_at_100m_m": abs(lam_b * 100.0 / (2 * bv))}
    rate.update({"vertical_baseline_m": bv, "delta_f_hz": dfreq})
    with np.errstate(invalid="ignore"):
        value = np.where(coh >= min_coherence, value, np.nan).astype(np.float32)  # NaN coherence fails too
    return Interferogram(phase=phase, coherence=coh, model_phase=np.nan_to_num(model).astype(np.float32),
                         residual=resid, value=value, value_name=name, value_unit=unit, rate=rate, support=ok,
                         unwrapped=unw.phase, component=unw.component, unwrap_method=unw.method)
