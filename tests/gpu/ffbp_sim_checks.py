"""Run under numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1`` must be set before numba is imported, so this
runs in its own process: tests/gpu/test_ffbp_cuda.py). Each check runs :func:`sarcli.focus.ffbp.ffbp` on a tiny
scene with ``device="cpu"`` and ``device="cuda"`` and prints one JSON document: the largest difference, the
bound of :func:`sarcli.gpu.ffbp_cuda.ffbp_bound` and the number of merge stages (the check must merge)."""

from __future__ import annotations

import json
import sys

import numpy as np

from sarcli.focus.ffbp import ApertureWindow, FfbpKnobs, ffbp
from sarcli.focus.ffbp_product import FfbpOptions
from sarcli.focus.windows import window_table
from sarcli.gpu.device import require_cuda
from sarcli.gpu.ffbp_cuda import ffbp_bound


def _run(lines, r_first, dr, cell, lam, pos, ref, w, pix, r_out, knobs, window=None):
    lam_min = lam * 0.95
    stats: dict = {}
    cpu, ws_cpu = ffbp(lines, r_first, dr, cell, lam, lam_min, pos, ref, w, pix, r_out, knobs, window, stats=stats)
    gpu, ws_gpu = ffbp(lines, r_first, dr, cell, lam, lam_min, pos, ref, w, pix, r_out, knobs, window,
                       device="cuda")
    r_max = float(np.max(np.abs(np.concatenate([pos.ravel(), pix.ravel()])))) + float(np.max(np.abs(r_out)))
    bound = ffbp_bound(knobs, stats["merge_stages"], cell / max(dr, cell / knobs.range_oversample), lines, w,
                       4 * np.pi / lam, r_max)
    return {"max_error": float(np.max(np.abs(gpu - cpu))), "bound": bound, "peak": float(np.abs(cpu).max()),
            "stages": stats["merge_stages"], "wsum_error": float(np.max(np.abs(ws_gpu - ws_cpu)))}


def _target_lines(pos, ref, target, r_first, dr, n_r, lam, cell):
    """Range-compressed lines of one point target (sinc envelope of resolution ``cell``, phase -k rho)."""
    rho = np.linalg.norm(pos - target, axis=1) - ref
    r = r_first + dr * np.arange(n_r)
    return (np.sinc((r[None, :] - rho[:, None]) / cell) * np.exp(-4j * np.pi * rho[:, None] / lam)).astype(np.complex64)


def grid(rng):
    """GB-SAR-like: a 3-D rail track 100 m from a horizontal grid at z = 0, no aperture window."""
    n, lam = 32, 0.03
    pos = np.c_[np.linspace(-0.8, 0.8, n), np.full(n, -40.0), np.full(n, 5.0)]
    ref = np.full(n, np.hypot(40.0, 5.0))
    lines = _target_lines(pos, ref, np.array([0.1, 0.2, 0.0]), -3.0, 0.05, 120, lam, 0.15)
    lines += (0.05 * (rng.standard_normal(lines.shape) + 1j * rng.standard_normal(lines.shape))).astype(np.complex64)
    xs, ys = np.linspace(-0.5, 0.5, 6), np.linspace(-0.6, 0.6, 5)
    gx, gy = np.meshgrid(xs, ys)
    pix = np.stack([gx, gy, np.zeros_like(gx)], axis=-1)
    w = np.hamming(n)
    w[5] = 0.0
    return _run(lines, -3.0, 0.05, 0.15, lam, pos, ref, w, pix, np.zeros(gx.shape), FfbpKnobs(base=2, order=4,
                                                                                                 range_order=4))


def stripmap(rng):
    """Stripmap-like: a straight track at 200 m/s, a Doppler-band aperture window (mode 1) per pixel."""
    n, lam, prf = 48, 0.03, 400.0
    t = (np.arange(n) - n / 2) / prf
    pos = np.c_[np.zeros(n), 200.0 * t, np.full(n, 300.0)]
    vel = np.tile([0.0, 200.0, 0.0], (n, 1))
    ref = np.zeros(n)
    lines = _target_lines(pos, ref, np.array([400.0, 0.0, 0.0]), 495.0, 0.5, 24, lam, 1.0)
    xs, ys = np.linspace(398.0, 402.0, 5), np.linspace(-1.0, 1.0, 6)
    gx, gy = np.meshgrid(xs, ys)
    pix = np.stack([gx, gy, np.zeros_like(gx)], axis=-1)
    r_out = np.linalg.norm(pix - np.array([0.0, 0.0, 300.0]), axis=-1)
    ba = 300.0
    win = ApertureWindow(mode=1, par=np.array([lam, ba, 0.0]), table=window_table("kaiser:2.5"),
                         aperture_pulses=float(n), per_pixel=np.zeros(gx.shape), vel=vel)
    return _run(lines, 495.0, 0.5, 1.0, lam, pos, ref, np.ones(n), pix, r_out,
                FfbpKnobs(base=2, order=4, range_order=4, aperture_split=4), win)


if __name__ == "__main__":
    dev = require_cuda()
    assert dev.simulator, "run with NUMBA_ENABLE_CUDASIM=1"
    rng = np.random.default_rng(7)
    accepted = FfbpOptions(device="cuda").device  # the stripmap focuser's refusal of cuda is gone
    json.dump({"grid": grid(rng), "stripmap": stripmap(rng), "stripmap_options_device": accepted}, sys.stdout)
