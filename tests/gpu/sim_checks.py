"""Run under numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1`` must be set before numba is imported, so this
runs in its own process: tests/gpu/test_bp_cuda.py). Each check compares a numba.cuda kernel with the
plain-numpy reference on a tiny input and prints one JSON document: the largest error and the bound that
:func:`sarcli.gpu.bp_cuda.float32_bound` derives for it."""

from __future__ import annotations

import json
import sys

import numpy as np

from sarcli.focus.backprojection import backproject_grid as stripmap_bp
from sarcli.focus.backprojection import backproject_numpy, upsample_range
from sarcli.gbsar.backprojection import backproject as rail_bp
from sarcli.gbsar.backprojection import backproject_grid as grid_bp
from sarcli.gbsar.backprojection import bp_grid_reference, bp_reference
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.windows import taper
from sarcli.gpu.bp_cuda import float32_bound
from sarcli.gpu.device import require_cuda

TABLE = 1e-6  # window/taper tables (4097 points, linear) vs exact: (h^2/8) |W''| < 1e-7 of the weight


def _result(out, ref, n_terms, sum_abs):
    err = np.abs(np.asarray(out, np.complex128) - ref)
    bound = float32_bound(n_terms, sum_abs) + TABLE * sum_abs
    return {"max_error": float(err.max()), "worst_ratio": float(np.max(err / bound)), "peak": float(np.abs(ref).max())}


def stripmap(rng):
    na, nr = 60, 48
    rc = (rng.standard_normal((na, nr)) + 1j * rng.standard_normal((na, nr))).astype(np.complex64)
    t = np.arange(na) / 500.0
    pos = np.stack([0 * t, 200.0 * t, 3000 + 0 * t], 1)
    vel = np.tile([0.0, 200.0, 0.0], (na, 1))
    pix = np.array([[4000.0 + i, 5.0 + 0.3 * j, 0.0] for i in range(6) for j in range(5)])
    r_ref = np.linalg.norm(pix - [0, 0, 3000], axis=1)
    fdc = np.linspace(-50, 50, pix.shape[0])
    out = stripmap_bp(rc, 4990.0, 1.0, 0.03, pos, vel, pix, r_ref, fdc, 400.0, "kaiser:2.5", 2, device="cuda")
    up = upsample_range(rc.astype(np.complex128), 2)
    ref = backproject_numpy(up, 4990.0, 0.5, 0.03, pos, vel, pix, r_ref, fdc, 400.0, "kaiser:2.5")
    ones = backproject_numpy(np.abs(up), 4990.0, 0.5, 0.03, pos, vel, pix, r_ref, fdc, 400.0, "rect")
    return _result(out, ref, na, np.abs(ones) + 1e-30)  # |rect sum of |v|| bounds sum |w v| (w <= 1)


def _profiles(rng, n_s, n_r, dr, first=0.0):
    data = (rng.standard_normal((n_s, n_r)) + 1j * rng.standard_normal((n_s, n_r))).astype(np.complex64)
    return RangeProfiles(data=data, dr_m=dr, center_frequency_hz=10e9, frequency_step_hz=5e6, n_freq=n_r,
                         positions_m=np.linspace(-1.0, 1.0, n_s), heights_m=np.linspace(0.0, 0.01, n_s),
                         weights=np.r_[np.ones(n_s - 1), 0.0], skipped=[n_s - 1], first_range_m=first)


def rail(rng):
    prof = _profiles(rng, 24, 80, 0.05)
    px, pr = np.meshgrid(np.linspace(-0.8, 0.8, 7), np.linspace(1.0, 3.0, 6))
    out = rail_bp(prof, px, pr, 0.25, "hamming", device="cuda")
    dz = prof.heights_m - prof.heights_m.mean()
    ref = bp_reference(prof.data.astype(np.complex128), prof.dr_m, prof.positions_m, dz, prof.weights, px, pr,
                       4 * np.pi / prof.wavelength_m, prof.wavelength_m / 0.5, "hamming")
    mag = bp_reference(np.abs(prof.data).astype(np.complex128), prof.dr_m, prof.positions_m, dz, prof.weights, px,
                       pr, 0.0, prof.wavelength_m / 0.5, "hamming")
    return _result(out, ref, 24, np.abs(mag) + 1e-30)  # normalised by the weights: a mean of |v|


def grid(rng):
    prof = _profiles(rng, 30, 64, 0.1, first=-3.2)
    ant = np.c_[np.linspace(-5, 5, 30), np.full(30, -100.0), np.full(30, 10.0)]
    ref_r = np.full(30, np.hypot(100.0, 10.0))
    xs, ys = np.linspace(-2, 2, 9), np.linspace(-2, 2, 7)
    img, used = grid_bp(prof, ant, ref_r, xs, ys, 0.0, "hamming", device="cuda")
    w = taper("hamming", 30) * prof.weights
    ref, ref_used = bp_grid_reference(prof.data.astype(np.complex128), -3.2, 0.1, ant, ref_r, w, xs, ys, 0.0,
                                      4 * np.pi / prof.wavelength_m)
    mag, _ = bp_grid_reference(np.abs(prof.data).astype(np.complex128), -3.2, 0.1, ant, ref_r, w, xs, ys, 0.0, 0.0)
    res = _result(img * w.sum(), ref, 30, np.abs(mag) + 1e-30)
    res["used_error"] = float(np.max(np.abs(used * w.sum() - ref_used)))
    return res


if __name__ == "__main__":
    dev = require_cuda()
    assert dev.simulator, "run with NUMBA_ENABLE_CUDASIM=1"
    rng = np.random.default_rng(11)
    json.dump({"stripmap": stripmap(rng), "rail": rail(rng), "grid": grid(rng)}, sys.stdout)
