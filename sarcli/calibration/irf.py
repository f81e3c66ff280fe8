"""The theoretical resolution (IRW) of a product from its processed bands and spectral windows.

(The measurement is ``sarcli.focus.quality.point_target_metrics``: peak search around the prediction,
carrier removal, x16 Fourier interpolation, IRW / PSLR / ISLR on the range and azimuth cuts.)

Theory: a processed band B weighted by a spectral window W(u), u = f / B in [-1/2, 1/2], gives the
impulse response ``h(x) = int W(u) exp(j 2 pi u B x) du``; its half-power width is ``k_W / B`` with
``k_W`` a property of the window alone (rect 0.886, the half-power width of sinc^2 [CumWong2005, ch. 2];
Hamming 0.54: 1.303; Kaiser beta 2.5: 1.042 by the same integral). :func:`window_irw_factor`
evaluates k_W numerically (the window sampled at the midpoints of 2049 equal cells of the band: rect
comes out 0.8858930, the sinc^2 value 0.8858929 to 1e-7). Range IRW = k_Wr c / (2 B_r) (slant range);
azimuth IRW = k_Wa V_g / B_a with V_g the ground speed of the zero-Doppler point (metres per second of
zero-Doppler time). The band and the
window come from the product:

- sarcli SLC (``parameters`` of the focuser): ``range_window``, ``azimuth_window`` (specs such as
  ``kaiser:2.5``), ``range_bandwidth_fraction`` x the chirp band |K| T (clipped to f_s),
  ``azimuth_bandwidth_hz``;
- NISAR RSLC (``parameters["nisar"]``): ``processedRangeBandwidth`` / ``processedAzimuthBandwidth``
  and ``rangeChirpWeighting`` / ``azimuthChirpWeighting`` (256 values over the sampling band; Kaiser or
  cosine by name when the attributes say so, else the tabulated shape inside the band); without a
  weighting the window is taken as rect and the result says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.errors import ProductError
from sarcli.model.constants import C_LIGHT
from sarcli.model.slc import SLC

_N_WINDOW = 2049


def band_grid(n: int = _N_WINDOW) -> np.ndarray:
    """n midpoints of equal cells covering u in [-1/2, 1/2] (each sample stands for 1/n of the band)."""
    return (np.arange(n) + 0.5) / n - 0.5


def window_irw_factor(values: np.ndarray) -> float:
    """k_W: half-power width x B of the IRF of a window sampled on :func:`band_grid` (len(values)):
    h(x) = sum_k W_k exp(j 2 pi u_k x) evaluated directly, the half-power point bracketed on a 0.01
    grid and solved by Brent's method (to 1e-12)."""
    from scipy.optimize import brentq

    w = np.asarray(values, np.float64)
    u = band_grid(w.size)
    h0 = abs(np.sum(w))
    if not h0 > 0:
        raise ProductError("spectral window is zero everywhere")

    def excess(x: float) -> float:
        return abs(np.sum(w * np.exp(2j * np.pi * u * x))) ** 2 / h0**2 - 0.5

    x = 0.01
    while excess(x) > 0:
        x += 0.01
        if x > 20:
            raise ProductError("spectral window has no half-power point within 20 resolution cells")
    return 2.0 * brentq(excess, x - 0.01, x, xtol=1e-12)


def window_values(spec: str, u: np.ndarray) -> np.ndarray:
    """The sarcli window ``spec`` at normalized frequencies u (``sarcli.focus.windows``)."""
    from sarcli.focus.windows import window

    return window(spec, u)


def _tabulated(weighting: dict, rate: float, band: float) -> np.ndarray:
    """A NISAR weighting (values over the sampling band, fftshifted order) resampled on u in [-1/2, 1/2]."""
    v = np.asarray(weighting["values"], np.float64)
    f = np.fft.fftshift(np.fft.fftfreq(v.size)) * rate
    return np.interp(band_grid() * band, f, v)


def _nisar_window(weighting: dict | None) -> tuple[str | None, str]:
    """(sarcli window spec or None, description) of a NISAR weighting's name/shape attributes."""
    if weighting is None:
        return "rect", "rect (the product records no weighting: assumed)"
    name = str(weighting.get("name", "")).lower()
    shape = float(weighting.get("shape", np.nan))
    if name == "kaiser" and np.isfinite(shape):
        return f"kaiser:{shape}", f"Kaiser beta {shape}"
    if name == "cosine" and np.isfinite(shape):
        return f"hamming:{(1.0 + shape) / 2.0}", f"cosine pedestal {shape}"
    return None, "tabulated weighting"


@dataclass
class AxisTheory:
    """Theoretical IRW along one axis: band (Hz), window description, k_W, IRW (m or s)."""

    bandwidth_hz: float
    window: str
    factor: float
    irw: float


def theory(slc: SLC) -> tuple[AxisTheory, AxisTheory]:
    """(range IRW theory in slant metres, azimuth IRW theory in SECONDS of zero-Doppler time: multiply
    by the ground speed at the reflector). Refuses a product whose processed bands are unknown."""
    from sarcli.focus.rangecomp import chirp_band

    p = slc.parameters or {}
    nisar = p.get("nisar", {})
    u = band_grid()
    fs = float(C_LIGHT / (2.0 * (slc.slant_range[1] - slc.slant_range[0])))
    line_rate = float(1.0 / np.median(np.diff(slc.azimuth_time)))
    out = []
    for axis, rate in (("range", fs), ("azimuth", line_rate)):
        spec = p.get(f"{axis}_window")
        if spec is not None:
            if axis == "range":
                band = chirp_band(slc.radar) * float(p.get("range_bandwidth_fraction", 1.0))
            else:
                band = float(p.get("azimuth_bandwidth_hz", np.nan))
            values, desc = window_values(spec, u), str(spec)
        else:
            band = float(nisar.get(f"processed_{axis}_bandwidth_hz", np.nan))
            weighting = nisar.get(f"{axis}_weighting")
            spec, desc = _nisar_window(weighting)
            values = window_values(spec, u) if spec is not None else _tabulated(weighting, rate, band)
        if not (np.isfinite(band) and band > 0):
            raise ProductError(f"the product does not record its processed {axis} bandwidth: no theoretical IRW")
        k = window_irw_factor(values)
        scale = C_LIGHT / (2.0 * band) if axis == "range" else 1.0 / band
        out.append(AxisTheory(band, desc, k, k * scale))
    return out[0], out[1]
