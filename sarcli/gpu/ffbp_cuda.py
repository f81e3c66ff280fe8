"""Fast factorized backprojection on CUDA (numba.cuda): the stage-0, merge and last-stage kernels of
:mod:`sarcli.focus.ffbp` [UlaHelSte2003], one thread per polar row (stage 0 and the merges, their scratch rows in
device memory) or pixel (last stage).

**One source, two targets.** The arithmetic of a sample lives once, in the ``@njit`` helpers of
:mod:`sarcli.focus.ffbp` (``_stage0_row``, ``_merge_row``, ``_final_pixels`` and what they call). The CPU
kernels call them from ``prange`` loops; here the same Python source of each helper (its ``py_func``) is
compiled a second time as a CUDA device function (:func:`_twin`), its calls to the other helpers bound to their
CUDA twins. The kernels below only map a thread to its sample, give it ``cuda.local.array`` scratch instead of
``np.empty`` and store the result: no arithmetic is written twice. Under numba's CUDA simulator
(``NUMBA_ENABLE_CUDASIM=1``) the device functions run as that Python source, which is what CI tests; their
compiled CUDA form has not yet been built on a card (no GPU machine was lent to the session that wrote this).

**Precision, and the bound the tests use.** Unlike :mod:`sarcli.gpu.bp_cuda`, FFBP on the GPU keeps the CPU's
precisions exactly: float64 geometry and phase (the same polynomial ``_cis``, no float32 cosine), complex128
sums, and complex64 polar images between stages (both paths round the same float64 sums to complex64). The two
images therefore differ only where float64 operations round differently (the card contracts multiply-adds to
FMA, its ``sqrt``/``floor`` are correctly rounded as on the CPU), and by what such differences do downstream:

- float64: a phase ``k (rho - r)`` is formed from coordinates and ranges <= R_max through fewer than 8
  roundings, so it differs by at most 8 eps64 k R_max (rad); the interpolation weights and sums of a sample,
  fewer than 64 + N operations (N pulses), by (64 + N) eps64 of the sum of the magnitudes of its terms;
- float32: a stored polar sample v is the complex64 rounding of a float64 value; two float64 values that
  differ in the last bits can round to neighbouring float32 numbers, |difference| <= eps32 |v| (one ulp per
  component).

Magnitudes. Let W = sum_n |w_n| max_i |line_n[i]| and Lambda = Lambda_u Lambda_r the product of the angular and
range kernels' Lebesgue constants (max over the offset of sum |h|, :func:`lebesgue`). A stage-0 sample of
subaperture s is at most W_s (its pulses' share of W); a sample of stage l at most Lambda^l W_s (its children
partition its pulses, each interpolated with gain <= Lambda); the last stage multiplies by window means <= 1.
Differences: stage l's samples inherit stage l-1's differences times Lambda and add their own rounding
eps32 Lambda^l W_s, so after S merges D_S <= (S + 1) eps32 Lambda^S W_s, and the pixel

    |GPU - CPU| <= (S + 1) eps32 Lambda^(S+1) W + (8 k R_max + 64 + N) eps64 Lambda^(S+1) W   (:func:`ffbp_bound`).

This is a worst case (every rounding flipped the same way); under the simulator the two agree far closer.
"""

from __future__ import annotations

import types
from typing import Any

import numpy as np
from numba import complex128, cuda, float64

from sarcli.focus import ffbp as cpu
from sarcli.gpu.device import Cuda

EPS32 = float(np.finfo(np.float32).eps)
EPS64 = float(np.finfo(np.float64).eps)
THREADS = 128  # threads per block (one sample, row or pixel each)
SCRATCH_BYTES = 1 << 28  # device scratch of one merge batch
MAX_ORDER = cpu.MAX_ORDER

# the @njit helpers of sarcli.focus.ffbp (cis: of sarcli.focus.phasor), callees before callers
_HELPERS = ("_weights", "cis", "_polar_point", "_row_points", "_phasors", "_band_u", "_cum", "_table", "_window_mean",
            "_inside", "_interp", "_line_at", "_stage0_row", "_child_polar", "_ray_is_separable", "_column_along_ray",
            "_merge_child_along_ray", "_merge_row", "_final_pixels")
_TWINS: dict[str, Any] = {}


def _twin(name: str) -> Any:
    """The CUDA device function compiled from the Python source of the @njit helper ``name`` of
    :mod:`sarcli.focus.ffbp` (in its own module's globals), whose calls to other helpers resolve to their CUDA
    twins (``_TWINS``)."""
    py = getattr(cpu, name).py_func
    fn = types.FunctionType(py.__code__, {**py.__globals__, **_TWINS}, py.__name__, py.__defaults__, py.__closure__)
    dev = cuda.jit(device=True)(fn)
    _TWINS[name] = dev
    return dev


_D = {name: _twin(name) for name in _HELPERS}
_stage0_row = _D["_stage0_row"]
_merge_row = _D["_merge_row"]
_final_pixels = _D["_final_pixels"]


@cuda.jit
def stage0_kernel(lines, r_first, dr_in, k, pos, ref, w, sub_start, sub_stop, frames, p0, nrm, g_r0, g_u0, g_du,
                  g_nr, g_off, dr, row_sub, row_iu, q0, n_q, pts, r, rcs, cr, ci, acc, out):
    """:func:`sarcli.focus.ffbp.stage0_kernel`, one thread per row q0 + t (t < n_q), its scratch row t of the
    global arrays ``pts`` .. ``acc``."""
    t = cuda.grid(1)
    if t >= n_q:
        return
    q = q0 + t
    s = row_sub[q]
    n = g_nr[s]
    _stage0_row(lines, r_first, dr_in, k, pos, ref, w, sub_start[s], sub_stop[s], frames[s], p0, nrm, g_r0[s],
                g_u0[s] + row_iu[q] * g_du[s], n, dr, pts[t], r[t], rcs[t], cr[t], ci[t], acc[t])
    base = g_off[s] + row_iu[q] * n
    for i in range(n):
        out[base + i] = acc[t, i]


@cuda.jit
def merge_kernel(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start, kid_stop, frames, p0, nrm, g_r0,
                 g_u0, g_du, g_nr, g_off, dr, k, order, range_order, tab_u, tab_r, row_sub, row_iu, gamma_max, q0, n_q,
                 pts, r, rcs, ucs, cr, ci, col, acc, out):
    """:func:`sarcli.focus.ffbp.merge_kernel`, one thread per parent row q0 + t (t < n_q), its scratch row t of
    the global arrays ``pts`` .. ``acc``."""
    t = cuda.grid(1)
    if t >= n_q:
        return
    q = q0 + t
    s = row_sub[q]
    n = g_nr[s]
    wr = cuda.local.array(MAX_ORDER, float64)
    wu = cuda.local.array(MAX_ORDER, float64)
    _merge_row(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start[s], kid_stop[s], frames[s], p0, nrm,
               g_r0[s], g_u0[s] + row_iu[q] * g_du[s], n, dr, k, order, range_order, tab_u, tab_r, gamma_max, wr, wu,
               pts[t], r[t], rcs[t], ucs[t], cr[t], ci[t], col[t], acc[t])
    base = g_off[s] + row_iu[q] * n
    for i in range(n):
        out[base + i] = acc[t, i]


@cuda.jit
def final_kernel(img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix, r_out, dr, k,
                 order, range_order, tab_u, tab_r, mode, bpar, pos, vel, par, wtab, ctab, span_max, lines, r_first,
                 dr_in, ref, w, out, wsum):
    """:func:`sarcli.focus.ffbp.final_kernel`, one thread per pixel."""
    m = cuda.grid(1)
    if m >= pix.shape[0]:
        return
    wr = cuda.local.array(MAX_ORDER, float64)
    wu = cuda.local.array(MAX_ORDER, float64)
    rcs = cuda.local.array(1, float64)
    frs = cuda.local.array(1, float64)
    fus = cuda.local.array(1, float64)
    cr = cuda.local.array(1, float64)
    ci = cuda.local.array(1, float64)
    acc = cuda.local.array(1, complex128)
    wsa = cuda.local.array(1, float64)
    _final_pixels(img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix, r_out, m, m + 1,
                  dr, k, order, range_order, tab_u, tab_r, mode, bpar, pos, vel, par, wtab, ctab, span_max, lines,
                  r_first, dr_in, ref, w, wr, wu, rcs, frs, fus, cr, ci, acc, wsa, out, wsum)


def _blocks(n: int) -> int:
    return max(1, (n + THREADS - 1) // THREADS)


def _on(dev: Cuda, *arrays: Any) -> list[Any]:
    """Host arrays on the device (contiguous copies); device arrays as they are."""
    return [a if not isinstance(a, np.ndarray) else dev.asarray(np.ascontiguousarray(a)) for a in arrays]


def _row_scratch(xp: Any, rows: int, width: int, c_width: int) -> tuple[Any, ...]:
    """Device scratch of ``rows`` row threads (:func:`stage0_kernel`, :func:`merge_kernel`): pts, r, rcs, ucs,
    cr, ci, col, acc, as :func:`sarcli.focus.ffbp.merge_kernel` allocates per row."""
    return (xp.empty((rows, width, 3)), xp.empty((rows, width)), xp.empty((rows, width)), xp.empty((rows, width)),
            xp.empty((rows, width)), xp.empty((rows, width)), xp.empty((rows, c_width), xp.complex128),
            xp.empty((rows, width), xp.complex128))


def _row_batch(n_rows: int, width: int, c_width: int) -> int:
    """Rows per launch so that their scratch (:func:`_row_scratch`: 80 bytes per sample, 16 per child column)
    stays within :data:`SCRATCH_BYTES`."""
    return max(1, min(n_rows, SCRATCH_BYTES // (80 * width + 16 * c_width)))


def stage0(dev: Cuda, lines, r_first, dr_in, k, pos, ref, w, sub_start, sub_stop, frames, p0, nrm, g_r0, g_u0, g_du,
           g_nr, g_off, dr, row_sub, row_iu, size: int) -> Any:
    """Stage 0 on ``dev`` (arguments of :func:`sarcli.focus.ffbp.stage0_kernel`): the (size,) complex64 polar
    images, left on the device; rows in batches (:func:`_row_batch`)."""
    out = dev.xp.zeros(size, dev.xp.complex64)
    if not row_sub.size:
        return out
    width = max(1, int(np.max(g_nr)))
    batch = _row_batch(row_sub.size, width, 1)
    pts, r, rcs, _, cr, ci, _, acc = _row_scratch(dev.xp, batch, width, 1)
    args = (*_on(dev, lines), float(r_first), float(dr_in), float(k),
            *_on(dev, pos, ref, w, sub_start, sub_stop, frames, p0, nrm, g_r0, g_u0, g_du, g_nr, g_off), float(dr),
            *_on(dev, row_sub, row_iu))
    for q0 in range(0, row_sub.size, batch):
        n_q = min(batch, row_sub.size - q0)
        stage0_kernel[_blocks(n_q), THREADS](*args, q0, n_q, pts, r, rcs, cr, ci, acc, out)
    return out


def merge(dev: Cuda, child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start, kid_stop, frames, p0, nrm,
          g_r0, g_u0, g_du, g_nr, g_off, dr, k, order, range_order, tab_u, tab_r, row_sub, row_iu, gamma_max,
          size: int) -> Any:
    """One merge stage on ``dev`` (arguments of :func:`sarcli.focus.ffbp.merge_kernel`; ``child`` on the
    device): the (size,) complex64 parent images, left on the device; rows in batches (:func:`_row_batch`)."""
    out = dev.xp.zeros(size, dev.xp.complex64)
    if not row_sub.size:
        return out
    width = max(1, int(np.max(g_nr)))
    c_width = max(1, int(np.max(c_nr))) if c_nr.size else 1
    batch = _row_batch(row_sub.size, width, c_width)
    scratch = _row_scratch(dev.xp, batch, width, c_width)
    args = (child, *_on(dev, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start, kid_stop, frames, p0, nrm,
                        g_r0, g_u0, g_du, g_nr, g_off), float(dr), float(k), int(order), int(range_order),
            *_on(dev, tab_u, tab_r, row_sub, row_iu), float(gamma_max))
    for q0 in range(0, row_sub.size, batch):
        n_q = min(batch, row_sub.size - q0)
        merge_kernel[_blocks(n_q), THREADS](*args, q0, n_q, *scratch, out)
    return out


def final(dev: Cuda, img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix, r_out, dr, k,
          order, range_order, tab_u, tab_r, mode, bpar, pos, vel, par, wtab, ctab, span_max, lines, r_first, dr_in,
          ref, w) -> tuple[np.ndarray, np.ndarray]:
    """The last stage on ``dev`` (arguments of :func:`sarcli.focus.ffbp.final_kernel`; ``img`` on the device):
    (image complex128 (M,), weight sum (M,)) in host memory."""
    m = pix.shape[0]
    out = dev.xp.zeros(m, dev.xp.complex128)
    wsum = dev.xp.zeros(m, dev.xp.float64)
    if m:
        final_kernel[_blocks(m), THREADS](img, *_on(dev, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start,
                                                    sub_stop, sub_w, pix, r_out), float(dr), float(k), int(order),
                                          int(range_order), *_on(dev, tab_u, tab_r), int(mode),
                                          *_on(dev, bpar, pos, vel, par, wtab, ctab), float(span_max),
                                          *_on(dev, lines), float(r_first), float(dr_in), *_on(dev, ref, w), out, wsum)
    return dev.to_host(out), dev.to_host(wsum)


def lebesgue(order: int, oversample: float) -> float:
    """Lebesgue constant of the interpolation kernel of ``order`` taps (:func:`sarcli.focus.ffbp.kernel_table`):
    max over the offset mu in [0, 1) of sum_i |h(mu - node_i)|, on the table's own 1/TABLE_Q steps (the
    lookup interpolates the table linearly, so its sums are convex combinations of these)."""
    return float(np.max(np.abs(cpu.kernel_table(order, oversample)).sum(axis=1)))


def ffbp_bound(knobs: cpu.FfbpKnobs, stages: int, range_oversample: float, lines: np.ndarray, weights: np.ndarray,
               k: float, r_max: float) -> float:
    """Bound on |GPU - CPU| of an FFBP pixel after ``stages`` merges (module docstring): ``lines`` and
    ``weights`` as given to :func:`sarcli.focus.ffbp.ffbp`, ``k`` = 4 pi / lam, ``r_max`` the largest range or
    coordinate (m) that enters a phase."""
    lam = lebesgue(knobs.order, knobs.oversample) * lebesgue(knobs.range_order, range_oversample)
    big_w = float(np.sum(np.abs(weights) * np.abs(lines).max(axis=1)))
    n = len(weights)
    gain = lam ** (stages + 1) * big_w
    return (stages + 1) * EPS32 * gain + (8.0 * k * r_max + 64.0 + n) * EPS64 * gain

