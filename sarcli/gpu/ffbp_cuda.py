"""Fast factorized backprojection on CUDA (numba.cuda): the stage-0, merge and last-stage kernels of
:mod:`sarcli.focus.ffbp` [UlaHelSte2003], one thread per output polar sample (stages) or pixel (last stage).

**One source, two targets.** The arithmetic of a sample lives once, in the ``@njit`` helpers of
:mod:`sarcli.focus.ffbp` (``_stage0_sample``, ``_merge_sample``, ``_final_pixel`` and what they call). The CPU
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
from numba import cuda, float64

from sarcli.focus import ffbp as cpu
from sarcli.gpu.device import Cuda

EPS32 = float(np.finfo(np.float32).eps)
EPS64 = float(np.finfo(np.float64).eps)
THREADS = 128  # threads per block (one sample or pixel each)
MAX_ORDER = cpu.MAX_ORDER

# the @njit helpers of sarcli.focus.ffbp, callees before callers
_HELPERS = ("_weights", "_cis", "_polar_point", "_band_u", "_cum", "_table", "_window_mean", "_inside", "_interp",
            "_stage0_sample", "_merge_sample", "_final_pixel")
_GLOBALS: dict[str, Any] = dict(vars(cpu))


def _twin(name: str) -> Any:
    """The CUDA device function compiled from the Python source of the @njit helper ``name`` of
    :mod:`sarcli.focus.ffbp`, whose calls to other helpers resolve to their CUDA twins (``_GLOBALS``)."""
    py = getattr(cpu, name).py_func
    fn = types.FunctionType(py.__code__, _GLOBALS, py.__name__, py.__defaults__, py.__closure__)
    dev = cuda.jit(device=True)(fn)
    _GLOBALS[name] = dev
    return dev


_D = {name: _twin(name) for name in _HELPERS}
_stage0_sample = _D["_stage0_sample"]
_merge_sample = _D["_merge_sample"]
_final_pixel = _D["_final_pixel"]


@cuda.jit
def stage0_kernel(lines, r_first, dr_in, k, pos, ref, w, sub_start, sub_stop, frames, p0, nrm, g_r0, g_u0, g_du,
                  g_nr, g_off, dr, row_sub, row_iu, width, out):
    """:func:`sarcli.focus.ffbp.stage0_kernel`: thread t is sample ir = t mod width of row q = t div width."""
    t = cuda.grid(1)
    q = t // width
    ir = t - q * width
    if q >= row_sub.size:
        return
    s = row_sub[q]
    if ir >= g_nr[s]:
        return
    iu = row_iu[q]
    out[g_off[s] + iu * g_nr[s] + ir] = _stage0_sample(lines, r_first, dr_in, k, pos, ref, w, sub_start[s],
                                                       sub_stop[s], frames[s], p0, nrm, g_r0[s] + ir * dr,
                                                       g_u0[s] + iu * g_du[s])


@cuda.jit
def merge_kernel(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start, kid_stop, frames, p0, nrm, g_r0,
                 g_u0, g_du, g_nr, g_off, dr, k, order, range_order, tab_u, tab_r, row_sub, row_iu, width, out):
    """:func:`sarcli.focus.ffbp.merge_kernel`, one thread per parent polar sample (as :func:`stage0_kernel`)."""
    t = cuda.grid(1)
    q = t // width
    ir = t - q * width
    if q >= row_sub.size:
        return
    s = row_sub[q]
    if ir >= g_nr[s]:
        return
    iu = row_iu[q]
    wr = cuda.local.array(MAX_ORDER, float64)
    wu = cuda.local.array(MAX_ORDER, float64)
    out[g_off[s] + iu * g_nr[s] + ir] = _merge_sample(child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off,
                                                      kid_start[s], kid_stop[s], frames[s], p0, nrm,
                                                      g_r0[s] + ir * dr, g_u0[s] + iu * g_du[s], dr, k, order,
                                                      range_order, tab_u, tab_r, wr, wu)


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
    acc, ws = _final_pixel(img, frames, g_r0, g_u0, g_du, g_nr, g_nu, g_off, sub_start, sub_stop, sub_w, pix[m, 0],
                           pix[m, 1], pix[m, 2], r_out[m], dr, k, order, range_order, tab_u, tab_r, mode, bpar[m],
                           pos, vel, par, wtab, ctab, span_max, lines, r_first, dr_in, ref, w, wr, wu)
    out[m] = acc
    wsum[m] = ws


def _blocks(n: int) -> int:
    return max(1, (n + THREADS - 1) // THREADS)


def _on(dev: Cuda, *arrays: Any) -> list[Any]:
    """Host arrays on the device (contiguous copies); device arrays as they are."""
    return [a if not isinstance(a, np.ndarray) else dev.asarray(np.ascontiguousarray(a)) for a in arrays]


def stage0(dev: Cuda, lines, r_first, dr_in, k, pos, ref, w, sub_start, sub_stop, frames, p0, nrm, g_r0, g_u0, g_du,
           g_nr, g_off, dr, row_sub, row_iu, size: int) -> Any:
    """Stage 0 on ``dev`` (arguments of :func:`sarcli.focus.ffbp.stage0_kernel`): the (size,) complex64 polar
    images, left on the device."""
    out = dev.xp.zeros(size, dev.xp.complex64)
    width = max(1, int(np.max(g_nr))) if g_nr.size else 1
    n = row_sub.size * width
    if n:
        stage0_kernel[_blocks(n), THREADS](*_on(dev, lines), float(r_first), float(dr_in), float(k),
                                           *_on(dev, pos, ref, w, sub_start, sub_stop, frames, p0, nrm, g_r0, g_u0,
                                                g_du, g_nr, g_off), float(dr), *_on(dev, row_sub, row_iu), width, out)
    return out


def merge(dev: Cuda, child, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start, kid_stop, frames, p0, nrm,
          g_r0, g_u0, g_du, g_nr, g_off, dr, k, order, range_order, tab_u, tab_r, row_sub, row_iu, size: int) -> Any:
    """One merge stage on ``dev`` (arguments of :func:`sarcli.focus.ffbp.merge_kernel`; ``child`` on the
    device): the (size,) complex64 parent images, left on the device."""
    out = dev.xp.zeros(size, dev.xp.complex64)
    width = max(1, int(np.max(g_nr))) if g_nr.size else 1
    n = row_sub.size * width
    if n:
        merge_kernel[_blocks(n), THREADS](child, *_on(dev, c_frames, c_r0, c_u0, c_du, c_nr, c_nu, c_off, kid_start,
                                                      kid_stop, frames, p0, nrm, g_r0, g_u0, g_du, g_nr, g_off),
                                          float(dr), float(k), int(order), int(range_order),
                                          *_on(dev, tab_u, tab_r, row_sub, row_iu), width, out)
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
    tab = np.abs(cpu.kernel_table(order, oversample))
    q = cpu.TABLE_Q
    idx = np.arange(q + 1)[:, None] + q * np.arange(order)[None, :]
    return float(np.max(tab[np.minimum(idx, tab.size - 1)].sum(axis=1)))


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

