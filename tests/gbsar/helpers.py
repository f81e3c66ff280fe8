"""Small scenes and measurements shared by the GB-SAR tests (no expected values computed here)."""

from __future__ import annotations

import numpy as np

from sarcli.gbsar.scene import scene_from_dict
from sarcli.gbsar.simulate import simulate


def scene_dict(points, *, bw=600e6, n=201, rail=4.0, step=0.05, height=0.0, effects=None, antenna=None,
               walls=None, pols=("VV",), seed=1, fc=5.3e9):
    d = {
        "scene": {"seed": seed},
        "sweep": {"center_frequency_hz": fc, "bandwidth_hz": bw, "points": n, "polarizations": list(pols)},
        "rail": {"length_m": rail, "step_m": step, "height_m": height},
        "antenna": antenna or {},
        "points": [dict(p) if isinstance(p, dict) else {"x_m": p[0], "y_m": p[1]} for p in points],
        "effects": effects or {},
    }
    if walls:
        d["walls"] = walls
    return d


def scan_of(points, **kw):
    return simulate(scene_from_dict(scene_dict(points, **kw)))


def peak_near(img: np.ndarray, ranges: np.ndarray, azimuths: np.ndarray, r0: float, x0: float,
              dr: int = 3, dc: int = 6):
    """(row, col, |value|) of the amplitude peak in a window around (r0, x0)."""
    ri, ci = int(np.argmin(abs(ranges - r0))), int(np.argmin(abs(azimuths - x0)))
    r1, c1 = max(ri - dr, 0), max(ci - dc, 0)
    sub = np.abs(img[r1:ri + dr + 1, c1:ci + dc + 1])
    i, j = np.unravel_index(int(np.argmax(sub)), sub.shape)
    return r1 + i, c1 + j, float(sub[i, j])


def width_at(values: np.ndarray, axis: np.ndarray, level: float) -> float:
    """Width of the main lobe of |values| at ``level`` times its peak (linear interpolation)."""
    a = np.abs(values)
    k = int(np.argmax(a))
    thr = level * a[k]
    i = k
    while i > 0 and a[i] > thr:
        i -= 1
    j = k
    while j < a.size - 1 and a[j] > thr:
        j += 1
    left = axis[i] + (thr - a[i]) / (a[i + 1] - a[i]) * (axis[i + 1] - axis[i])
    right = axis[j - 1] + (a[j - 1] - thr) / (a[j - 1] - a[j]) * (axis[j] - axis[j - 1])
    return float(right - left)


def pslr_db(values: np.ndarray, null_halfwidth: int) -> float:
    """Peak sidelobe ratio (dB) of a 1-D cut: largest |v|^2 outside +-null_halfwidth samples of the peak."""
    a = np.abs(values) ** 2
    k = int(np.argmax(a))
    side = np.r_[a[:max(k - null_halfwidth, 0)], a[k + null_halfwidth + 1:]]
    return float(10 * np.log10(side.max() / a[k]))


def fft_upsample(row: np.ndarray, factor: int) -> np.ndarray:
    """Band-limited (zero-padded spectrum) interpolation of a complex 1-D signal."""
    n = row.size
    s = np.fft.fftshift(np.fft.fft(row))
    pad = (factor - 1) * n
    s = np.r_[np.zeros(pad // 2), s, np.zeros(pad - pad // 2)]
    return np.fft.ifft(np.fft.ifftshift(s)) * factor
