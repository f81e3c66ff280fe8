"""Correlation Doppler Estimator (CDE, Madsen 1989) and sign Doppler estimator (SDE), per block.

For a block of complex samples h(m, k) (azimuth line m, range sample k) the lag-1 azimuth correlation

    C = sum_{m,k} h(m+1, k) * conj(h(m, k))                       ([Madsen1989]; [Koh2003, §3.2])

has phase 2*pi*fdc/PRF for a stationary azimuth signal whose power spectrum is centred on fdc, so
``fdc_baseband = PRF * arg(C) / (2*pi)`` in [-PRF/2, PRF/2). The pairs are taken inside the block
(na lines give na-1 pairs per range sample).

Quality q = |C| / E with E = sum_{m,k} (|h(m+1,k)|^2 + |h(m,k)|^2) / 2 (0..1). With signal lag-1
correlation rho_s and signal-to-noise ratio snr, q = rho_s * snr / (1 + snr); for pure white noise q is
Rayleigh distributed with scale 1/sqrt(2 N) (N pairs), so a block is only *valid* when q exceeds
``noise_sigmas / sqrt(2 N)`` (the SNR-aware flag) and ``min_quality``.
The phase variance of the estimate is approximately (1 - q^2) / (2 N_eff q^2); its inverse is the
block weight used by the fits (low-signal blocks count less; invalid blocks get weight 0).

SDE: replace h by s = sign(Re h) + j sign(Im h) (1 bit per rail, cheaper on integer hardware). For a
circular complex Gaussian signal with correlation coefficient rho, the arcsine law gives
E[s(m+1) conj(s(m))] / 2 = (2/pi) (asin(Re rho) + j asin(Im rho)); the kernel inverts it:
rho = sin(pi/2 Re r) + j sin(pi/2 Im r), r = C_s / (2 N).

Kernels are numba (``@njit(cache=True, parallel=True)``; float32 sums over one line of a range
block, float64 accumulation over lines; a software prefetch of the memory stream, a hint that changes
no result); ``*_numpy`` are the plain-numpy references used by the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from llvmlite import ir
from numba import njit, prange, types
from numba.extending import intrinsic

from sarcli.errors import SarcliError


@dataclass
class BlockCorrelation:
    """Lag-1 correlation sums on a (n_az_blocks, n_rg_blocks) grid.

    ``corr`` complex128 sums C, ``energy`` float64 E, ``pairs`` int64 N; ``line0``/``sample0`` first
    line/sample of each block and ``n_lines``/``n_samples`` its extent (1-D, per axis);
    ``line_energy`` (n_lines, n_rg_blocks) float64: the energy sum |h(l)|^2 of every line over each range
    block's samples (of the complex samples, also for the SDE), 0 for the lines of a block without pairs
    (the scene-contrast error of a block, ``sarcli.doppler.contrast``, reads the azimuth power profile
    from it).
    """

    corr: np.ndarray
    energy: np.ndarray
    pairs: np.ndarray
    line0: np.ndarray
    n_lines: np.ndarray
    sample0: np.ndarray
    n_samples: np.ndarray
    estimator: str = "cde"
    line_energy: np.ndarray | None = None

    def phase_rho(self) -> np.ndarray:
        """Complex lag-1 correlation coefficient per block (CDE: C/E; SDE: arcsine-corrected)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            if self.estimator == "sde":
                r = self.corr / np.maximum(2.0 * self.pairs, 1)
                rho = np.sin(0.5 * np.pi * r.real) + 1j * np.sin(0.5 * np.pi * r.imag)
            else:
                rho = np.where(self.energy > 0, self.corr / np.where(self.energy > 0, self.energy, 1), 0)
        return rho

    def baseband(self, prf: float) -> np.ndarray:
        """Baseband centroid per block, Hz, in [-PRF/2, PRF/2)."""
        return wrap_frequency(prf * np.angle(self.phase_rho()) / (2 * np.pi), prf)

    def quality(self) -> np.ndarray:
        """|rho| per block (0..1)."""
        return np.abs(self.phase_rho())

    def valid(self, noise_sigmas: float = 5.0, min_quality: float = 0.02) -> np.ndarray:
        """SNR-aware validity: quality above the white-noise floor and ``min_quality``."""
        q = self.quality()
        floor = noise_sigmas / np.sqrt(2.0 * np.maximum(self.pairs, 1))
        return (self.pairs > 0) & (q > np.maximum(floor, min_quality))

    def weight(self, noise_sigmas: float = 5.0, min_quality: float = 0.02) -> np.ndarray:
        """Inverse phase variance 2 N q^2 / (1 - q^2) (rad^-2); 0 for invalid blocks."""
        q = np.clip(self.quality(), 0.0, 0.999999)
        w = 2.0 * self.pairs * q**2 / (1.0 - q**2)
        return np.where(self.valid(noise_sigmas, min_quality), w, 0.0)

    def scene_sum(self, mask: np.ndarray) -> tuple[complex, float]:
        """(correlation, normalization) summed over the blocks in ``mask``: CDE (C, E); SDE the
        arcsine-corrected coefficient weighted by the pairs, (sum rho N, sum N). |sum| / norm is the
        scene quality and arg(sum) gives the scene centroid."""
        if self.estimator == "sde":
            return np.sum(np.where(mask, self.phase_rho() * self.pairs, 0)), float(np.sum(self.pairs[mask]))
        return np.sum(np.where(mask, self.corr, 0)), float(np.sum(self.energy[mask]))

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(line centre, sample centre) of each block, as fractional indices (1-D per axis)."""
        return self.line0 + 0.5 * (self.n_lines - 1), self.sample0 + 0.5 * (self.n_samples - 1)


def wrap_frequency(f: np.ndarray | float, prf: float) -> np.ndarray:
    """Wrap to [-PRF/2, PRF/2)."""
    return np.mod(np.asarray(f, dtype=np.float64) + 0.5 * prf, prf) - 0.5 * prf


def block_edges(n: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Start indices and lengths of blocks of ``size`` covering ``n`` (last block takes the remainder
    if it is at least half a block, else it is merged into the previous one). A scene shorter than a
    block gives one block of length ``n``."""
    if n <= 0 or size <= 0:
        raise SarcliError(f"block size {size} and extent {n} must be positive")
    nb = max(1, int(round(n / size)))
    starts = np.arange(nb, dtype=np.int64) * size
    starts = starts[starts < n]
    lengths = np.diff(np.append(starts, n)).astype(np.int64)
    return starts, lengths


def check_finite(echo: np.ndarray, where: str = "echo") -> None:
    """Raise a one-line error if ``echo`` holds NaN or inf samples."""
    a = np.asarray(echo)
    flat = a.view(a.real.dtype) if np.iscomplexobj(a) else a
    if not np.isfinite(flat).all():
        bad = int(np.count_nonzero(~np.isfinite(flat)))
        raise SarcliError(f"{where}: {bad} NaN/inf sample value(s); repair or mask the input before "
                          "Doppler estimation")


@njit(cache=True, inline="always")
def _sgn(x):
    return np.float32((x > 0) - (x < 0))


#: pair lines per task of the kernel: an azimuth block is cut into tasks of this many lines so that
#: every thread gets an equal share (11 blocks of 2048 lines on 2 threads would leave one idle 1/12
#: of the time); the partial sums of a block's tasks are added in task order (deterministic)
CHUNK_LINES = 256

#: software prefetch distance of the kernel's read stream, float32 elements (8 KiB): the kernel asks
#: for the memory this far ahead of the later line it is reading. Without it the streaming loads of a
#: core waiting on its vectorized sums ran at 70 % of a plain parallel read of the same array; with it
#: at 90-100 % (bench_doppler, interleaved; flat from 4 to 32 KiB, so not tuned to one machine)
PREFETCH_FLOATS = 2048
#: float32 elements per 64-byte cache line: one prefetch per line
CACHE_LINE_FLOATS = 16


@intrinsic
def _prefetch(typingctx, arr, index):
    """Hint that element ``index`` (flat) of the C-contiguous ``arr`` will be read soon: LLVM's
    ``llvm.prefetch`` (read, keep in all cache levels). A hint only: never faults, changes no result."""
    if not (isinstance(arr, types.Array) and arr.layout == "C" and isinstance(index, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        i8p, i32 = ir.IntType(8).as_pointer(), ir.IntType(32)
        fn = builder.module.declare_intrinsic("llvm.prefetch", [i8p],
                                              ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]))
        builder.call(fn, [builder.bitcast(builder.gep(data, [args[1]]), i8p), i32(0), i32(3), i32(1)])
        return context.get_dummy_value()

    return types.void(arr, index), codegen


@njit(cache=True, inline="always")
def _line_energy(v, k0, n):
    e = np.float32(0.0)
    w = v[2 * k0:2 * (k0 + n)]
    for k in range(2 * n):
        e += w[k] * w[k]
    return e


@njit(cache=True, inline="always")
def _line_energy_sign(v, k0, n):
    e = np.float32(0.0)
    w = v[2 * k0:2 * (k0 + n)]
    for k in range(2 * n):
        e += _sgn(w[k]) * _sgn(w[k])
    return e


@njit(cache=True, parallel=True, fastmath=True)
def _lag_kernel(x, task_m0, task_m1, samp0, nsamp, sign_mode, lag, part, line_en):
    # x is the echo viewed as float32 (n_lines, 2 n_samples): interleaved re, im (SIMD-friendly).
    # Tasks (runs of pair lines [m0, m1) inside one azimuth block) in parallel; inside a task the lines
    # are streamed in memory order (line m and m+lag whole, the later one still in cache when its turn
    # comes) with one accumulator per range block. One line of one range block (<= a few hundred
    # products) is summed in float32 (fastmath lets the reduction vectorize), every line's partial sum
    # is added in float64. The energy sum_m (|h(m+lag)|^2 + |h(m)|^2)/2 is formed from each line's
    # energy, computed once: line l counts 1/2 as a "later" line (l in [m0+lag, m1+lag)) and 1/2 as
    # an "earlier" line (l in [m0, m1)); part[t] = (re C, im C, E) per range block of task t.
    # line_en[l] gets each line's energy of the complex samples (also in sign mode) exactly once: the
    # task's earlier-only lines [m0, m0 + lag) and its later lines below m1; the last lag lines of a
    # block (later lines at or beyond the block's last pair line) are filled by the caller.
    # Each range block first prefetches the cache lines PREFETCH_FLOATS ahead of its part of the later
    # line (the stream from memory; the earlier line is still in cache), clamped to the array.
    nrb = samp0.shape[0]
    last = x.size - 1
    for t in prange(task_m0.shape[0]):
        m0 = task_m0[t]
        m1 = task_m1[t]
        for m in range(m0, min(m0 + lag, m1)):  # earlier-only lines of this task
            for jb in range(nrb):
                e = _line_energy(x[m], samp0[jb], nsamp[jb])
                line_en[m, jb] = np.float64(e)
                if sign_mode:
                    part[t, 2, jb] += 0.5 * np.float64(_line_energy_sign(x[m], samp0[jb], nsamp[jb]))
                else:
                    part[t, 2, jb] += 0.5 * np.float64(e)
        for m in range(m0, m1):
            la = x[m + lag]
            lb = x[m]
            we = 1.0 if m + lag < m1 else 0.5
            ahead = (m + lag) * x.shape[1] + PREFETCH_FLOATS
            for jb in range(nrb):
                # slices start at 0, so numba can drop the negative-index wraparound test and the
                # loops vectorize (2.6x faster than indexing the whole line from k0)
                n = nsamp[jb]
                for c in range(2 * samp0[jb], 2 * (samp0[jb] + n), CACHE_LINE_FLOATS):
                    _prefetch(x, min(ahead + c, last))
                a = la[2 * samp0[jb]:2 * (samp0[jb] + n)]
                b = lb[2 * samp0[jb]:2 * (samp0[jb] + n)]
                sr = np.float32(0.0)
                si = np.float32(0.0)
                se = np.float32(0.0)
                if sign_mode:
                    for k in range(n):
                        ar = _sgn(a[2 * k])
                        ai = _sgn(a[2 * k + 1])
                        br = _sgn(b[2 * k])
                        bi = _sgn(b[2 * k + 1])
                        sr += ar * br + ai * bi
                        si += ai * br - ar * bi
                        se += ar * ar + ai * ai
                    if m + lag < m1:
                        line_en[m + lag, jb] = np.float64(_line_energy(la, samp0[jb], n))
                else:
                    for k in range(n):
                        ar = a[2 * k]
                        ai = a[2 * k + 1]
                        br = b[2 * k]
                        bi = b[2 * k + 1]
                        sr += ar * br + ai * bi
                        si += ai * br - ar * bi
                        se += ar * ar + ai * ai
                    if m + lag < m1:
                        line_en[m + lag, jb] = np.float64(se)
                part[t, 0, jb] += np.float64(sr)
                part[t, 1, jb] += np.float64(si)
                part[t, 2, jb] += we * np.float64(se)


def _tasks(line0: np.ndarray, nlines: np.ndarray, lag: int, chunk: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first pair line, end pair line, first task of each block): each azimuth block's pair lines
    [l0, l0 + n - lag) cut into runs of ``chunk`` (a block without pairs keeps one empty task)."""
    m0s, m1s, first = [], [], []
    for l0, n in zip(line0.tolist(), nlines.tolist(), strict=True):
        first.append(len(m0s))
        end = l0 + max(n - lag, 0)
        starts = list(range(l0, end, chunk)) or [l0]
        m0s += starts
        m1s += [min(s + chunk, end) for s in starts]
    return np.asarray(m0s, np.int64), np.asarray(m1s, np.int64), np.asarray(first, np.int64)


def _grid(shape: tuple[int, int], az_block: int, rg_block: int, lag: int = 1):
    n_lines, n_samples = shape
    if n_lines < lag + 1:
        raise SarcliError(f"need at least {lag + 1} azimuth lines for a lag-{lag} correlation, got {n_lines}")
    l0, nl = block_edges(n_lines, az_block)
    s0, ns = block_edges(n_samples, rg_block)
    # a trailing block too short for a pair: merge it into the previous block
    if nl[-1] < lag + 1 and nl.size > 1:
        nl[-2] += nl[-1]
        l0, nl = l0[:-1], nl[:-1]
    return l0, nl, s0, ns


def block_correlation(echo: np.ndarray, az_block: int = 2048, rg_block: int = 128,
                      estimator: str = "cde", lag: int = 1) -> BlockCorrelation:
    """Lag-``lag`` azimuth correlation sums per block (numba). ``estimator`` is "cde" or "sde".
    (The CDE uses lag 1; longer lags serve MLBF, whose phase is then ``lag`` times larger.)

    Default block (2048 azimuth x 128 range) is that of [Koh2003, §5]. NaN/inf input raises SarcliError.
    """
    if estimator not in ("cde", "sde"):
        raise SarcliError(f"unknown correlation estimator {estimator!r} (use cde or sde)")
    h = np.ascontiguousarray(echo)
    if h.ndim != 2:
        raise SarcliError(f"echo must be 2-D (azimuth, range), got shape {h.shape}")
    if h.dtype != np.complex64:
        h = h.astype(np.complex64)
    if lag < 1:
        raise SarcliError(f"correlation lag must be >= 1, got {lag}")
    l0, nl, s0, ns = _grid(h.shape, az_block, rg_block, lag)
    m0, m1, first = _tasks(l0, nl, lag, CHUNK_LINES)
    part = np.zeros((m0.size, 3, s0.size))
    le = np.zeros((h.shape[0], s0.size))
    _lag_kernel(h.view(np.float32), m0, m1, s0, ns, estimator == "sde", lag, part, le)
    for a, n in zip(l0, nl, strict=True):  # each block's last lag lines: later lines of its last task only
        if n > lag:
            tail = np.abs(h[a + n - lag:a + n].astype(np.complex128)) ** 2
            le[a + n - lag:a + n] = np.add.reduceat(tail, s0, axis=1)
    sums = np.add.reduceat(part, first, axis=0)  # tasks of a block, in order
    cr, ci, en = sums[:, 0], sums[:, 1], sums[:, 2]
    pr = np.maximum(nl - lag, 0)[:, None] * ns[None, :]
    if estimator == "sde" or not (np.isfinite(en).all() and np.isfinite(cr).all() and np.isfinite(ci).all()):
        # every sample enters some block energy, so a NaN/inf input shows up there for free (CDE);
        # the sign estimator maps NaN to 0 and needs the explicit pass
        check_finite(h)
    return BlockCorrelation(cr + 1j * ci, en, pr, l0, nl, s0, ns, estimator, le)


def block_correlation_numpy(echo: np.ndarray, az_block: int = 2048, rg_block: int = 128,
                            estimator: str = "cde", lag: int = 1) -> BlockCorrelation:
    """Plain-numpy reference of :func:`block_correlation` (same block grid)."""
    x = np.asarray(echo).astype(np.complex128)
    h = np.sign(x.real) + 1j * np.sign(x.imag) if estimator == "sde" else x
    l0, nl, s0, ns = _grid(h.shape, az_block, rg_block, lag)
    corr = np.zeros((l0.size, s0.size), complex)
    en = np.zeros(corr.shape)
    pr = np.zeros(corr.shape, np.int64)
    le = np.zeros((h.shape[0], s0.size))
    for i, (a, na) in enumerate(zip(l0, nl, strict=True)):
        for j, (b, nb) in enumerate(zip(s0, ns, strict=True)):
            blk = h[a:a + na, b:b + nb]
            corr[i, j] = np.sum(blk[lag:] * np.conj(blk[:-lag]))
            en[i, j] = 0.5 * np.sum(np.abs(blk[lag:]) ** 2 + np.abs(blk[:-lag]) ** 2)
            pr[i, j] = max(na - lag, 0) * nb
            if na > lag:
                le[a:a + na, j] = np.sum(np.abs(x[a:a + na, b:b + nb]) ** 2, axis=1)
    return BlockCorrelation(corr, en, pr, l0, nl, s0, ns, estimator, le)


def combine(bc: BlockCorrelation, axis: int) -> BlockCorrelation:
    """Merge all blocks along ``axis`` (0: azimuth, 1: range): sums add, so the result is the
    signal-weighted estimate over the merged area."""
    keep = dict(line0=bc.line0, n_lines=bc.n_lines, sample0=bc.sample0, n_samples=bc.n_samples)
    if axis == 0:
        keep["line0"] = bc.line0[:1]
        keep["n_lines"] = np.array([bc.n_lines.sum()])
    else:
        keep["sample0"] = bc.sample0[:1]
        keep["n_samples"] = np.array([bc.n_samples.sum()])
    le = bc.line_energy
    if le is not None and axis == 1:
        le = le.sum(axis=1, keepdims=True)
    return BlockCorrelation(bc.corr.sum(axis, keepdims=True), bc.energy.sum(axis, keepdims=True),
                            bc.pairs.sum(axis, keepdims=True), estimator=bc.estimator, line_energy=le, **keep)
