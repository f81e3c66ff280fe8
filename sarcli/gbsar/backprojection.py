"""Time-domain backprojection (BP): the exact GB-SAR focusing reference, on any set of pixels.

A pixel at azimuth x and range R0 from the rail line (image plane through the rail at the mean
antenna height) is at distance ``R_i = sqrt((x - x_i)^2 + R0^2 + (h_i - h_mean)^2)`` from stop i. With
the baseband range profiles P_i of :mod:`sarcli.gbsar.rangecomp` (``P_i(R) = a exp(-j 4 pi R/lam) W``),

    g(x, R0) = exp(-j 4 pi R0/lam) * sum_i w_i P_i(R_i) exp(+j 4 pi R_i/lam) / sum_i w_i

over the stops of the pixel's synthetic aperture (rail within the beam footprint, [LeeGBSAR-II-2007, Fig. 2]),
``w_i`` the azimuth taper over that aperture, so a scatterer focuses to its (pattern-weighted)
reflectivity (times its aperture fraction at the rail ends) with the phase
``-4 pi R0/lam`` of the RD image of [LeeGBSAR-II-2007, eq. 21] at every range: no approximation but the linear
interpolation of the (oversampled) profile and the centre wavelength in the carrier term, which is
exact because the profile is referenced to f_c. The kernel evaluates ``exp(+j 4 pi (R_i - R0)/lam)``
in float32 (``R_i - R0`` stays below ~5 m, so the phase error is < 1e-4 rad) and accumulates in
complex64. Flagged stops are left out.

Grid backprojection (:func:`backproject_grid`): any 3-D track, a reference range per sweep, a
horizontal Cartesian grid, every sweep integrated (spotlight: no beam footprint), the image the
complex reflectivity; phase model and derivation in its docstring. Two kernels: float32
(:func:`bp_grid_kernel32`, the default: float64 ranges, the phasor by the float32 recurrence of
:mod:`sarcli.focus.phasor`, float32 interpolation and sums, tiled) and float64 (:func:`bp_grid_kernel`).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from sarcli.errors import ConfigError
from sarcli.focus.backprojection import FLOAT32_FLAGS, lerp_pairs
from sarcli.focus.phasor import advance_phasor, anchor_interval, anchor_phasor, cis
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.gbsar.windows import taper, taper_at, taper_table

#: the float32 grid kernel's tile (rows, columns): rows a multiple of the anchor interval (1 or
#: ANCHOR_EVERY = 16), the accumulators (16 bytes a pixel) within a core's L1/L2
GRID_TILE = (32, 64)
_W_MIN = 1e-9  # apertures whose taper weights sum below this (e.g. one stop on a Hann edge) give 0


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy")
def bp_kernel(prof, dr, xs, dz, valid, px, pr, kc, half_beam, table, out):
    """Backproject ``prof`` (n_stops, n_r) complex64 (ranges n*dr) onto pixels (px, pr) -> out (n_p,).

    Each pixel integrates the stops of its synthetic aperture ``[a, b]`` = rail ``[xs[0], xs[-1]]``
    intersected with the beam footprint ``|x - px| <= half_beam * pr`` ([LeeGBSAR-II-2007, eq. 22-40]), weighted by
    the taper ``table`` (sampled on [0, 1]) over [a, b], normalized by the sum of the weights used and
    scaled by ``(b - a) / min(X, 2 half_beam R0)``: a pixel whose aperture is cut by a rail end
    (regions III/IV) is attenuated by its aperture fraction, as in DF and RD, instead of amplifying
    the leakage of bright targets seen by a few stops at the beam edge.
    """
    n_s, n_r = prof.shape
    for p in prange(px.shape[0]):
        a = max(xs[0], px[p] - half_beam * pr[p])
        b = min(xs[n_s - 1], px[p] + half_beam * pr[p])
        span = b - a
        acc = np.complex64(0j)
        wsum = 0.0
        r0sq = pr[p] * pr[p]
        for i in range(n_s):
            if valid[i] == 0.0 or xs[i] < a or xs[i] > b:
                continue
            w = 1.0
            if span > 0:
                q = (xs[i] - a) / span * (table.size - 1)
                k = min(int(q), table.size - 2)
                w = table[k] + (q - k) * (table[k + 1] - table[k])
            d = px[p] - xs[i]
            r = np.sqrt(d * d + r0sq + dz[i] * dz[i])
            f = r / dr
            j = int(f)
            if j >= n_r - 1:
                continue
            t = np.float32(f - j)
            v = prof[i, j] * (np.float32(1.0) - t) + prof[i, j + 1] * t
            # r - R0 < ~1.2e3 rad / kc: a float32 phase is good to 1e-4 rad, and complex64 math is faster
            ph = np.float32(kc * (r - pr[p]))
            acc += np.float32(w) * v * np.complex64(complex(np.cos(ph), np.sin(ph)))
            wsum += w
        nominal = min(xs[n_s - 1] - xs[0], 2.0 * half_beam * pr[p])
        frac = span / nominal if nominal > 0 else 1.0
        out[p] = acc * frac / wsum if wsum > _W_MIN else 0j


def bp_reference(prof: np.ndarray, dr: float, xs, dz, valid, px, pr, kc, half_beam, taper_spec: str) -> np.ndarray:
    """Plain-numpy reference of :func:`bp_kernel` (the taper evaluated exactly, not tabulated)."""
    rgrid = np.arange(prof.shape[1]) * dr
    a = np.maximum(xs[0], px - half_beam * pr)
    b = np.minimum(xs[-1], px + half_beam * pr)
    span = b - a
    acc = np.zeros(px.shape, np.complex128)
    wsum = np.zeros(px.shape)
    for i in range(prof.shape[0]):
        t = np.where(span > 0, (xs[i] - a) / np.where(span > 0, span, 1.0), 0.0)
        w = taper_at(taper_spec, t)
        r = np.sqrt((px - xs[i]) ** 2 + pr ** 2 + dz[i] ** 2)
        use = (valid[i] != 0) & (xs[i] >= a) & (xs[i] <= b) & (r < rgrid[-1])
        v = np.interp(r, rgrid, prof[i].real) + 1j * np.interp(r, rgrid, prof[i].imag)
        acc += np.where(use, w * v * np.exp(1j * kc * r), 0)
        wsum += np.where(use, w, 0)
    nominal = np.minimum(xs[-1] - xs[0], 2.0 * half_beam * pr)
    frac = np.where(nominal > 0, span / np.where(nominal > 0, nominal, 1.0), 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(wsum > _W_MIN, acc * np.exp(-1j * kc * pr) * frac / wsum, 0)


def backproject(prof: RangeProfiles, px: np.ndarray, pr: np.ndarray, antenna_length_m: float | None,
                azimuth_window: str = "hamming", device: str = "cpu") -> np.ndarray:
    """BP onto pixels at azimuth ``px`` and range ``pr`` (any equal shapes) -> complex64 of that shape.

    ``antenna_length_m`` = L_x limits each pixel's aperture to the beam footprint; None uses the whole rail.
    ``azimuth_window``: a taper spec (:mod:`sarcli.gbsar.windows`) over each pixel's aperture.
    ``device``: cpu, or cuda (:func:`sarcli.gpu.bp_cuda.backproject_rail`, the same arithmetic).
    """
    table = taper_table(azimuth_window)
    px = np.asarray(px, np.float64)
    shape = px.shape
    flat_x = np.ascontiguousarray(px.ravel())
    flat_r = np.ascontiguousarray(np.broadcast_to(np.asarray(pr, np.float64), shape).ravel())
    out = np.zeros(flat_x.size, np.complex64)
    dz = prof.heights_m - prof.heights_m.mean()
    kc = 4 * np.pi / prof.wavelength_m
    half = prof.wavelength_m / (2 * antenna_length_m) if antenna_length_m else 1e30
    if device == "cuda":
        from sarcli.gpu import bp_cuda
        from sarcli.gpu.device import require_cuda

        out = bp_cuda.backproject_rail(require_cuda(), prof.data, prof.dr_m, prof.positions_m, dz, prof.weights,
                                       flat_x, flat_r, kc, half, table, _W_MIN)
    else:
        bp_kernel(np.ascontiguousarray(prof.data), prof.dr_m, prof.positions_m, dz, prof.weights, flat_x, flat_r, kc,
                  half, table, out)
    return out.reshape(shape)


def backproject_polar(prof: RangeProfiles, rc: np.ndarray, sines: np.ndarray, antenna_length_m: float | None,
                      azimuth_window: str = "hamming") -> np.ndarray:
    """BP on a polar grid about the rail centre (DF's native grid): rows ``rc`` (distance from the rail
    centre, m), columns ``sines`` (sin of the angle from boresight) -> (n_rc, n_s) complex64.

    The phase convention stays ``-4 pi R0/lam`` (R0 = rc cos(theta)); multiply by
    ``exp(-j 4 pi (rc - R0)/lam)`` for DF's ``-4 pi Rc/lam``."""
    centre = 0.5 * (prof.positions_m[0] + prof.positions_m[-1])
    rc2, s2 = np.meshgrid(np.asarray(rc, np.float64), np.asarray(sines, np.float64), indexing="ij")
    return backproject(prof, centre + rc2 * s2, rc2 * np.sqrt(1.0 - s2 ** 2), antenna_length_m, azimuth_window)


# --- backprojection on a Cartesian grid from any 3-D track (airborne phase histories, lab and GPR rails) ---


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy")
def bp_grid_kernel(prof_re, prof_im, r_first, dr, ant, ref, w, xs, ys, z, kc, out, used):
    """Backproject profiles (``prof_re + j prof_im``, (n_s, n_r) float64 on relative ranges
    ``r_first + n dr``) from antenna positions ``ant`` (n_s, 3) with reference ranges ``ref`` (n_s,)
    onto the plane z of the grid ``ys`` x ``xs``: ``out[iy, ix] = sum_i w_i P_i(rho_i) exp(+j kc rho_i)``,
    ``rho_i = |p - a_i| - ref_i``, P linearly interpolated, a stop left out where rho_i is outside the
    profile; ``used[iy, ix]`` = the sum of the weights of the stops used. Rows in parallel; per stop, a
    vectorized pass over the row computes rho and the phasor (:func:`cis`), a scalar pass gathers."""
    n_s, n_r = prof_re.shape
    nx = xs.size
    inv_dr = 1.0 / dr
    top = n_r - 1.0
    for iy in prange(ys.size):
        acc_re = np.zeros(nx)
        acc_im = np.zeros(nx)
        acc_w = np.zeros(nx)
        uu = np.empty(nx)
        cc = np.empty(nx)
        ss = np.empty(nx)
        for i in range(n_s):
            wi = w[i]
            if wi == 0.0:
                continue
            ay = ys[iy] - ant[i, 1]
            az = z - ant[i, 2]
            yz2 = ay * ay + az * az
            ax = ant[i, 0]
            rf = ref[i]
            for k in range(nx):
                dx = xs[k] - ax
                rho = np.sqrt(dx * dx + yz2) - rf
                uu[k] = (rho - r_first) * inv_dr
                cc[k], ss[k] = cis(kc * rho)
            pr = prof_re[i]
            pim = prof_im[i]
            for k in range(nx):
                u = uu[k]
                if u >= 0.0 and u < top:
                    j = int(u)
                    t = u - j
                    vr = pr[j] + t * (pr[j + 1] - pr[j])
                    vi = pim[j] + t * (pim[j + 1] - pim[j])
                    acc_re[k] += wi * (vr * cc[k] - vi * ss[k])
                    acc_im[k] += wi * (vr * ss[k] + vi * cc[k])
                    acc_w[k] += wi
        for k in range(nx):
            out[iy, k] = complex(acc_re[k], acc_im[k])
            used[iy, k] = acc_w[k]


@njit(cache=True, parallel=True, fastmath=FLOAT32_FLAGS, error_model="numpy")
def bp_grid_kernel32(pairs, r_first, dr, ant, ref, w, xs, ys, z, kc, every, ty, tx, out, used):
    """Float32 twin of :func:`bp_grid_kernel`: ``out[iy, ix]`` (complex64) = the same sum, the phasor
    ``exp(+j kc rho)`` advanced down each column of the grid by the recurrence of
    :mod:`sarcli.focus.phasor` (float64 ranges, float32 phasors, a float64 anchor every ``every`` rows of
    the grid: rows ``g % every == 0``), the profiles read as :func:`sarcli.focus.backprojection.lerp_pairs`
    ``pairs`` (n_s, n_r) and interpolated and accumulated in float32; ``used`` as there (float64).

    Tiles of ``ty`` x ``tx`` pixels (``ty`` a multiple of ``every``) run in parallel; each integrates all
    sweeps in order, so the profile segments a tile touches (its range extent) stay in cache, and a pixel's
    arithmetic is the same whatever the tiling or the number of threads: the image is bit-identical across
    both (tested). Per sweep and row, one vectorized pass computes rho (float64 sqrt), the phasor and the
    interpolation index, a scalar pass reads the pairs, a vectorized pass interpolates and accumulates."""
    n_s, n_r = pairs.shape
    ny, nx = ys.size, xs.size
    nty = (ny + ty - 1) // ty
    ntx = (nx + tx - 1) // tx
    inv_dr = 1.0 / dr
    top = n_r - 1.0
    zero = np.float32(0.0)
    for t in prange(nty * ntx):
        r0 = (t // ntx) * ty
        c0 = (t % ntx) * tx
        nrw = min(ty, ny - r0)
        ncl = min(tx, nx - c0)
        acc_re = np.zeros((nrw, ncl), np.float32)
        acc_im = np.zeros((nrw, ncl), np.float32)
        acc_w = np.zeros((nrw, ncl))
        dx2 = np.empty(ncl)
        rho = np.empty(ncl)
        dlt = np.empty(ncl)
        pre = np.empty(ncl, np.float32)
        pim = np.empty(ncl, np.float32)
        dre = np.empty(ncl, np.float32)
        dim = np.empty(ncl, np.float32)
        jj = np.empty(ncl, np.uint64)
        ff = np.empty(ncl, np.float32)
        ww = np.empty(ncl, np.float32)
        val = np.empty(ncl, np.complex128)
        q = val.view(np.float32)
        for i in range(n_s):
            ax = ant[i, 0]
            ay = ant[i, 1]
            az = z - ant[i, 2]
            rf = ref[i]
            wd = w[i]
            wf = np.float32(wd)
            line = pairs[i]
            for c in range(ncl):
                d = xs[c0 + c] - ax
                dx2[c] = d * d + az * az
            for r in range(nrw):
                g = r0 + r
                yy = ys[g] - ay
                yy2 = yy * yy
                if g % every == 0:  # anchor: rho and delta from the row before (a virtual one before row 0)
                    if g > 0:
                        yp = ys[g - 1] - ay
                    elif ny > 1:
                        yp = 2.0 * ys[0] - ys[1] - ay
                    else:
                        yp = yy
                    yp2 = yp * yp
                    for c in range(ncl):
                        rh = np.sqrt(dx2[c] + yy2) - rf
                        anchor_phasor(kc, rh, rh - (np.sqrt(dx2[c] + yp2) - rf), c, pre, pim, dre, dim, rho, dlt)
                else:  # D <- D exp(j eps), P <- P D
                    for c in range(ncl):
                        advance_phasor(kc, np.sqrt(dx2[c] + yy2) - rf, c, pre, pim, dre, dim, rho, dlt)
                if wd == 0.0:
                    continue
                aw = acc_w[r]
                for c in range(ncl):
                    u = (rho[c] - r_first) * inv_dr
                    ok = (u >= 0.0) & (u < top)
                    uu = u if ok else 0.0
                    j = np.uint64(uu)
                    jj[c] = j
                    ff[c] = np.float32(uu - j)
                    ww[c] = wf if ok else zero
                    aw[c] += wd if ok else 0.0
                for c in range(ncl):
                    val[c] = line[jj[c]]
                ar = acc_re[r]
                ai = acc_im[r]
                for c in range(ncl):
                    f = ff[c]
                    vr = q[4 * c] + f * q[4 * c + 2]
                    vi = q[4 * c + 1] + f * q[4 * c + 3]
                    ar[c] += ww[c] * (vr * pre[c] - vi * pim[c])
                    ai[c] += ww[c] * (vr * pim[c] + vi * pre[c])
        for r in range(nrw):
            for c in range(ncl):
                out[r0 + r, c0 + c] = complex(acc_re[r, c], acc_im[r, c])
                used[r0 + r, c0 + c] = acc_w[r, c]


def grid_anchor_interval(ant: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float, kc: float) -> int:
    """Rows between float64 anchors for :func:`bp_grid_kernel32` on this geometry
    (:func:`sarcli.focus.phasor.anchor_interval`): the recurrence runs down the columns (steps ``diff(ys)``),
    ``rho_min`` the distance from the track to the grid's rectangle at height z."""
    near_x = np.clip(ant[:, 0], xs.min(), xs.max())
    near_y = np.clip(ant[:, 1], ys.min(), ys.max())
    rho_min = float(np.sqrt((near_x - ant[:, 0]) ** 2 + (near_y - ant[:, 1]) ** 2 + (z - ant[:, 2]) ** 2).min())
    return anchor_interval(kc, np.diff(ys), rho_min)


def bp_grid_reference(prof: np.ndarray, r_first: float, dr: float, ant: np.ndarray, ref: np.ndarray,
                      w: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float,
                      kc: float) -> tuple[np.ndarray, np.ndarray]:
    """Plain-numpy reference of :func:`bp_grid_kernel` (complex profiles, ``np.exp``), vectorized over
    the pixels, one stop at a time: the straightforward backprojection the benchmark compares with."""
    gx, gy = np.meshgrid(np.asarray(xs, np.float64), np.asarray(ys, np.float64))
    out = np.zeros(gx.shape, np.complex128)
    used = np.zeros(gx.shape)
    n_r = prof.shape[1]
    for i in np.flatnonzero(w):
        rho = np.sqrt((gx - ant[i, 0]) ** 2 + (gy - ant[i, 1]) ** 2 + (z - ant[i, 2]) ** 2) - ref[i]
        u = (rho - r_first) / dr
        ok = (u >= 0) & (u < n_r - 1)
        j = np.where(ok, u, 0).astype(np.int64)
        t = np.where(ok, u - j, 0.0)
        v = prof[i, j] + t * (prof[i, j + 1] - prof[i, j])
        out += np.where(ok, w[i] * v * np.exp(1j * kc * rho), 0)
        used += np.where(ok, w[i], 0.0)
    return out, used


def backproject_grid(prof: RangeProfiles, antenna_xyz: np.ndarray, reference_range: np.ndarray | None,
                     xs: np.ndarray, ys: np.ndarray, z: float, azimuth_window: str = "hamming",
                     precision: str = "single", device: str = "cpu") -> tuple[np.ndarray, np.ndarray]:
    """BP of ``centred`` profiles (:func:`sarcli.gbsar.rangecomp.range_compress`) onto the horizontal
    grid ``ys`` x ``xs`` at height ``z`` of the scan frame -> ``(image (n_y, n_x) complex64, fraction)``.

    Phase model (c -> v = c/sqrt(eps) in a medium): sweep i at antenna ``a_i`` with reference range
    ``r_i`` (0 without one) sees a scatterer of complex amplitude s at p as
    ``S21_ik = s exp(-j 4 pi f_k (|p - a_i| - r_i)/v)``; its profile is
    ``P_i(r) = s exp(-j kc rho_i) W(rho_i - r)``, ``rho_i = |p - a_i| - r_i``, ``kc = 4 pi f_c/v``, W
    real with W(0) = 1. So

        g(p) = sum_i w_i P_i(rho_i(p)) exp(+j kc rho_i(p)) / sum_i w_i

    gives g = s at the scatterer (no carrier phase left: the image is the complex reflectivity), with
    w_i the ``azimuth_window`` taper over the sweeps in their stored (track) order times their
    validity. A stop whose rho_i falls outside the profile ([-R_max, R_max)) is left out; ``fraction`` is
    the share of the weights a pixel used (1 inside the unambiguous window of every sweep). ``device``: cpu,
    or cuda (:func:`sarcli.gpu.bp_cuda.backproject_grid`, the same arithmetic, float32 accumulation).

    De-ramped phase histories are this model with r_i the de-ramp reference: dechirping on receive
    against a copy delayed by 2 r_i/c and removing the residual video phase leaves, at instantaneous
    frequency f_k, ``s exp(-j 4 pi f_k (R - r_i)/c)`` = the GB-SAR sweep times ``exp(+j 4 pi f_k r_i/c)``.
    AFRL GOTCHA's ``fp`` with ``r0`` (range to the scene centre, the frame origin) is that: AFRL's own
    backprojection [GorhamMoore2010] takes ``ifft(fp)`` as peaking at +dR, dR = |a - p| - r0, and
    multiplies by ``exp(+j 4 pi f_min dR/c)``, the same sign. Checked on the data
    (``tests/gbsar/test_gotcha.py``): the conjugate, i.e. the other sign, does not defocus at 10 km but
    mirrors the scene through its centre (dR(-p) = -dR(p) to first order in |p|/R), while reversing the
    range envelope alone against the carrier (the frequency axis) destroys the focus.

    ``precision``: ``single`` (:func:`bp_grid_kernel32`: float32 phasor recurrence, interpolation and sums,
    float64 ranges) or ``double`` (:func:`bp_grid_kernel`, float64 throughout).
    """
    ant = np.ascontiguousarray(antenna_xyz, np.float64)
    ref = np.zeros(ant.shape[0]) if reference_range is None else np.ascontiguousarray(reference_range, np.float64)
    w = taper(azimuth_window, ant.shape[0]) * prof.weights
    total = float(w.sum())
    xs = np.ascontiguousarray(xs, np.float64)
    ys = np.ascontiguousarray(ys, np.float64)
    kc = 4 * np.pi / prof.wavelength_m
    if device == "cuda":  # the same arithmetic on the GPU (sarcli.gpu.bp_cuda), float32 accumulation
        from sarcli.gpu import bp_cuda
        from sarcli.gpu.device import require_cuda

        img, used_gpu = bp_cuda.backproject_grid(require_cuda(), prof.data, prof.first_range_m, prof.dr_m, ant, ref, w,
                                                 xs, ys, float(z), kc)
        return (img / total).astype(np.complex64), used_gpu / total
    used = np.zeros((ys.size, xs.size))
    if precision == "single":
        every = grid_anchor_interval(ant, xs, ys, float(z), kc)
        out = np.zeros((ys.size, xs.size), np.complex64)
        bp_grid_kernel32(lerp_pairs(prof.data), prof.first_range_m, prof.dr_m, ant, ref, w, xs, ys, float(z), kc,
                         every, GRID_TILE[0], GRID_TILE[1], out, used)
        return (out / np.float32(total)).astype(np.complex64), used / total
    if precision != "double":
        raise ConfigError(f"precision must be 'single' or 'double', got {precision!r}")
    out = np.zeros((ys.size, xs.size), np.complex128)
    bp_grid_kernel(np.ascontiguousarray(prof.data.real, np.float64), np.ascontiguousarray(prof.data.imag, np.float64),
                   prof.first_range_m, prof.dr_m, ant, ref, w, xs, ys, float(z), kc, out, used)
    return (out / total).astype(np.complex64), used / total
