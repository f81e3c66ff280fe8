"""Fast factorized backprojection of GB-SAR scans and imported phase histories (``gbsar focus --algorithm ffbp``).

The same images as :mod:`sarcli.gbsar.backprojection`, by :func:`sarcli.focus.ffbp.ffbp` [UlaHelSte2003]
(derivation, knobs and error model there):

- :func:`ffbp_slant`, the rail's slant-plane grid of :func:`sarcli.gbsar.backprojection.backproject`:
  pixels (x, R0, 0), stops (x_i, 0, h_i - h_mean), phase reference R0. Beam-limited (``antenna_length_m``)
  each pixel integrates the stops of its footprint [a, b] with the taper over [a, b]: FFBP's aperture
  window of mode 2, applied per top subaperture; the image is divided by the sum of the weights used
  and scaled by the aperture fraction (b - a)/min(X, 2 hb R0), as BP does. Whole rail: the taper over
  the rail is a per-stop weight.
- :func:`ffbp_grid`, the horizontal grid of :func:`sarcli.gbsar.backprojection.backproject_grid` (any
  3-D track, reference ranges, the reflectivity: phase reference 0), divided by the taper's sum; the
  fraction of the weights whose profile covers each pixel is exact (:func:`coverage`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from sarcli.focus.ffbp import ApertureWindow, FfbpKnobs, ffbp
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.windows import taper, taper_at, taper_table

_W_MIN = 1e-9  # as sarcli.gbsar.backprojection: apertures whose weights sum below this give 0


def _band(prof: RangeProfiles) -> tuple[float, float]:
    """(range cell v/(2 N df), shortest wavelength v/f_max) of the sweep."""
    v = prof.wave_speed_m_s
    f_max = prof.center_frequency_hz + 0.5 * (prof.n_freq - 1) * prof.frequency_step_hz
    return v / (2 * prof.n_freq * prof.frequency_step_hz), v / f_max


def ffbp_slant(prof: RangeProfiles, px: np.ndarray, pr: np.ndarray, antenna_length_m: float | None,
               azimuth_window: str = "hamming", knobs: FfbpKnobs | None = None,
               stats: dict | None = None, device: str = "cpu") -> np.ndarray:
    """FFBP onto the slant-plane pixels ``px`` (azimuth) x ``pr`` (range R0), 2-D arrays of one shape ->
    complex64 of that shape (module docstring; the image of :func:`sarcli.gbsar.backprojection.backproject`);
    ``device``: cpu or cuda (:func:`sarcli.focus.ffbp.ffbp`)."""
    knobs = knobs or FfbpKnobs()
    px = np.asarray(px, np.float64)
    pr = np.broadcast_to(np.asarray(pr, np.float64), px.shape)
    xs = prof.positions_m
    dz = prof.heights_m - prof.heights_m.mean()
    pos = np.stack([xs, np.zeros_like(xs), dz], axis=1)
    pix = np.stack([px, pr, np.zeros_like(px)], axis=-1)
    cell, lam_min = _band(prof)
    rail = float(xs[-1] - xs[0])
    if antenna_length_m:
        hb = prof.wavelength_m / (2 * antenna_length_m)
        dx = rail / max(xs.size - 1, 1)
        window = ApertureWindow(mode=2, par=np.array([hb, xs[0], xs[-1]]), table=taper_table(azimuth_window),
                                aperture_pulses=2 * hb * float(np.median(pr)) / max(dx, 1e-12))
        weights = prof.weights
    else:
        hb, window = 1e30, None
        t = (xs - xs[0]) / rail if rail > 0 else np.zeros_like(xs)
        weights = prof.weights * taper_at(azimuth_window, t)
    img, wsum = ffbp(prof.data, prof.first_range_m, prof.dr_m, cell, prof.wavelength_m, lam_min, pos,
                     np.zeros(xs.size), weights, pix, pr, knobs, window, stats=stats, device=device)
    span = np.minimum(xs[-1], px + hb * pr) - np.maximum(xs[0], px - hb * pr)
    nominal = np.minimum(rail, 2.0 * hb * pr)
    frac = np.where(nominal > 0, span / np.where(nominal > 0, nominal, 1.0), 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(wsum > _W_MIN, img * frac / wsum, 0).astype(np.complex64)


@njit(cache=True, parallel=True)
def coverage(r_first, dr, n_r, ant, ref, w, xs, ys, z, out):
    """out[iy, ix] = sum of w_i over the sweeps whose profile holds the pixel's relative range (as
    :func:`sarcli.gbsar.backprojection.bp_grid_kernel`'s ``used``)."""
    top = n_r - 1.0
    for iy in prange(ys.size):
        for ix in range(xs.size):
            acc = 0.0
            for i in range(ant.shape[0]):
                if w[i] == 0.0:
                    continue
                dx = xs[ix] - ant[i, 0]
                dy = ys[iy] - ant[i, 1]
                dzz = z - ant[i, 2]
                u = (math.sqrt(dx * dx + dy * dy + dzz * dzz) - ref[i] - r_first) / dr
                if u >= 0.0 and u < top:
                    acc += w[i]
            out[iy, ix] = acc


def _covered_everywhere(prof: RangeProfiles, ant, ref, w, xs, ys, z) -> bool:
    """Whether every weighted sweep's profile holds the whole grid box (nearest and farthest points of
    the box from each antenna): then the coverage is the full weight sum without a per-pixel pass."""
    cx = np.clip(ant[:, 0], xs[0], xs[-1])
    cy = np.clip(ant[:, 1], ys[0], ys[-1])
    near = np.sqrt((cx - ant[:, 0]) ** 2 + (cy - ant[:, 1]) ** 2 + (z - ant[:, 2]) ** 2) - ref
    far = np.sqrt(np.maximum((xs[0] - ant[:, 0]) ** 2, (xs[-1] - ant[:, 0]) ** 2)
                  + np.maximum((ys[0] - ant[:, 1]) ** 2, (ys[-1] - ant[:, 1]) ** 2) + (z - ant[:, 2]) ** 2) - ref
    lo, hi = prof.first_range_m, prof.first_range_m + (prof.data.shape[1] - 1) * prof.dr_m
    use = w != 0
    return bool(np.all((near[use] >= lo) & (far[use] < hi)))


def ffbp_grid(prof: RangeProfiles, antenna_xyz: np.ndarray, reference_range: np.ndarray | None, xs: np.ndarray,
              ys: np.ndarray, z: float, azimuth_window: str = "hamming", knobs: FfbpKnobs | None = None,
              stats: dict | None = None, device: str = "cpu") -> tuple[np.ndarray, np.ndarray]:
    """FFBP of ``centred`` profiles onto the horizontal grid ``ys`` x ``xs`` at height ``z`` ->
    ``(image (n_y, n_x) complex64, fraction)``, the image and fraction of
    :func:`sarcli.gbsar.backprojection.backproject_grid`; ``device``: cpu or cuda."""
    knobs = knobs or FfbpKnobs()
    ant = np.ascontiguousarray(antenna_xyz, np.float64)
    ref = np.zeros(ant.shape[0]) if reference_range is None else np.ascontiguousarray(reference_range, np.float64)
    w = taper(azimuth_window, ant.shape[0]) * prof.weights
    total = float(w.sum())
    xs = np.ascontiguousarray(xs, np.float64)
    ys = np.ascontiguousarray(ys, np.float64)
    gx, gy = np.meshgrid(xs, ys)
    pix = np.stack([gx, gy, np.full_like(gx, z)], axis=-1)
    cell, lam_min = _band(prof)
    img, _ = ffbp(prof.data, prof.first_range_m, prof.dr_m, cell, prof.wavelength_m, lam_min, ant, ref, w, pix,
                  np.zeros(gx.shape), knobs, stats=stats, device=device)
    if _covered_everywhere(prof, ant, ref, w, xs, ys, z):
        used = np.full(gx.shape, total)
    else:
        used = np.zeros(gx.shape)
        coverage(prof.first_range_m, prof.dr_m, prof.data.shape[1], ant, ref, w, xs, ys, float(z), used)
    return (img / total).astype(np.complex64), used / total
