"""Echo kernels: numba (production) and a plain-numpy reference of the same physics (tests, bench).

Signal of target i in pulse k, channel c (stop-and-hop: platform frozen at r_k while the pulse
travels; times relative to the scene centre):

    p_k     = M_k (q_i + u_i (t_k - t_ref_i))                     target in the simulation frame
    R_tx    = |p_k - r_k|,  R_rx = |p_k - (r_k + off_c x_k)|,  R_c = (R_tx + R_rx)/2
    R_env   = R_c with range_migration, else R0_i (closest approach)
    s[c, k, n] += a_i G_ik exp(-j 4 pi R_c / lam) exp(+j pi K tau^2),  tau = ws + n/fs - 2 R_env/c,
                  for the samples with |tau| <= T/2 only (pulse centred on its delay)
    G_ik    = sinc^2(L_az sin(psi_az)/lam) sinc^2(L_el sin(psi_el)/lam) with antenna_pattern, else 1,
              sin(psi_az) = d.x_k/|d|, sin(psi_el) = d.e_k/|d|; G = 0 outside the elevation main lobe
              |sin(psi_el)| > emax = beam_extent lam/L_el (so the far side of the track stays dark)

Only the pulses with |sin(psi_az)| <= smax = beam_extent lam/L_az (the processed beam, found by
bisection since sin(psi_az) decreases monotonically as the target passes) and only the samples
inside the pulse are computed. Cost model: sum over targets of (pulses in beam) x (T fs samples) x (channels),
about 2 complex multiplies and one add per sample (the chirp phasor is advanced by recurrence:
z_{n+1} = z_n w_n, w_{n+1} = w_n exp(j 2 pi K dt^2), exact in exact arithmetic, drift ~1e-12 in
float64 over a pulse; two interleaved chains, see ``_add_chirp``), plus O(log n_lines) per target
for the beam search. Parallel over blocks of lines (each block owns its output lines: no races).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from sarcli.model.constants import C_LIGHT as C


@njit(cache=True, inline="always")
def _target_at(rot, k, tp, tv, i, dt, out):
    q0 = tp[i, 0] + tv[i, 0] * dt
    q1 = tp[i, 1] + tv[i, 1] * dt
    q2 = tp[i, 2] + tv[i, 2] * dt
    for j in range(3):
        out[j] = rot[k, j, 0] * q0 + rot[k, j, 1] * q1 + rot[k, j, 2] * q2


@njit(cache=True)
def _sin_az(t, rp, ux, rot, tp, tv, tref, i, k, buf):
    _target_at(rot, k, tp, tv, i, t[k] - tref[i], buf)
    d0 = buf[0] - rp[k, 0]
    d1 = buf[1] - rp[k, 1]
    d2 = buf[2] - rp[k, 2]
    return (d0 * ux[k, 0] + d1 * ux[k, 1] + d2 * ux[k, 2]) / math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit(cache=True, parallel=True)
def beam_windows(t, rp, ux, rot, tp, tv, tref, smax):  # pragma: no cover - compiled
    """[k0, k1) per target: the pulses with |sin(psi_az)| <= smax (bisection on a decreasing function)."""
    n_t = tp.shape[0]
    n = t.shape[0]
    k0 = np.empty(n_t, np.int64)
    k1 = np.empty(n_t, np.int64)
    for i in prange(n_t):
        buf = np.empty(3)
        lo, hi = 0, n
        while lo < hi:
            mid = (lo + hi) // 2
            if _sin_az(t, rp, ux, rot, tp, tv, tref, i, mid, buf) <= smax:
                hi = mid
            else:
                lo = mid + 1
        k0[i] = lo
        hi = n
        while lo < hi:
            mid = (lo + hi) // 2
            if _sin_az(t, rp, ux, rot, tp, tv, tref, i, mid, buf) < -smax:
                hi = mid
            else:
                lo = mid + 1
        k1[i] = lo
    return k0, k1


@njit(cache=True, inline="always")
def _sinc2(x):
    if x == 0.0:
        return 1.0
    y = math.pi * x
    s = math.sin(y) / y
    return s * s


@njit(cache=True, inline="always")
def _geometry(t, rp, ux, ue, rot, tp, tv, tref, i, k, pattern, laz, lel, emax, p):
    """(R_tx, gain) of target i seen from pulse k, d = p_k - r_k returned in p; gain 0 outside the
    elevation main lobe |sin(psi_el)| > emax (e.g. the other side of the track)."""
    _target_at(rot, k, tp, tv, i, t[k] - tref[i], p)
    p[0] -= rp[k, 0]
    p[1] -= rp[k, 1]
    p[2] -= rp[k, 2]
    rtx = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    se = (p[0] * ue[k, 0] + p[1] * ue[k, 1] + p[2] * ue[k, 2]) / rtx
    if abs(se) > emax:
        return rtx, 0.0
    g = 1.0
    if pattern:
        sa = (p[0] * ux[k, 0] + p[1] * ux[k, 1] + p[2] * ux[k, 2]) / rtx
        g = _sinc2(laz * sa) * _sinc2(lel * se)
    return rtx, g


@njit(cache=True, inline="always")
def _carrier(rc, lam):
    """exp(-j 4 pi rc/lam), with the phase reduced to one cycle first (2 rc/lam - floor: exact in float64)
    so that cos/sin see a small argument (faster, and no worse than the float64 value of 2 rc/lam)."""
    x = 2.0 * rc / lam
    ph = -2.0 * math.pi * (x - math.floor(x))
    return complex(math.cos(ph), math.sin(ph))


@njit(cache=True, inline="always")
def _channel_range(d, rtx, off, ux, k):
    """Bistatic mean range (R_tx + R_rx)/2 for a receiver ``off`` metres along the antenna axis."""
    if off == 0.0:
        return rtx
    e0 = d[0] - off * ux[k, 0]
    e1 = d[1] - off * ux[k, 1]
    e2 = d[2] - off * ux[k, 2]
    return 0.5 * (rtx + math.sqrt(e0 * e0 + e1 * e1 + e2 * e2))


@njit(cache=True, fastmath=True)
def _add_chirp(row, n_lo, n_hi, z, w, ww):  # pragma: no cover - compiled
    """row[n] += z_n for n = n_lo..n_hi, z_{n+1} = z_n w_n, w_{n+1} = w_n ww (the chirp by recurrence).

    Two interleaved chains (even and odd samples, steps W = w_n w_{n+1} = w_n^2 ww and W ww^2, both
    advanced by ww^4) halve the dependency chain; fastmath lets the complex products use FMA.
    """
    we = w * w * ww
    wo = we * ww * ww
    ww4 = (ww * ww) * (ww * ww)
    ze = z
    zo = z * w
    n = n_lo
    while n < n_hi:
        row[n] += ze
        row[n + 1] += zo
        ze *= we
        zo *= wo
        we *= ww4
        wo *= ww4
        n += 2
    if n == n_hi:
        row[n] += ze


@njit(cache=True, inline="always")
def _pulse(row, renv, z, kr, plen, fs, ws, ww):
    """Add the chirp of a target at envelope range renv (carrier/gain already in z) to one echo line."""
    n_s = row.shape[0]
    dts = 1.0 / fs
    td = 2.0 * renv / C
    n_lo = max(0, math.ceil((td - 0.5 * plen - ws) * fs))
    n_hi = min(n_s - 1, math.floor((td + 0.5 * plen - ws) * fs))
    if n_hi < n_lo:
        return
    tau = ws + n_lo * dts - td
    a = math.pi * kr * tau * tau
    wa = math.pi * kr * (2.0 * tau * dts + dts * dts)
    _add_chirp(row, n_lo, n_hi, z * complex(math.cos(a), math.sin(a)), complex(math.cos(wa), math.sin(wa)), ww)


@njit(cache=True, inline="always")
def _splat(row, renv, z, fq, x0, n_l):
    """Split z linearly between the two grid bins around x = 2 renv/c fq - x0 (bins < n_l only)."""
    x = 2.0 * renv / C * fq - x0
    j = math.floor(x)
    if j < 0 or j + 1 >= n_l:
        return
    f = x - j
    row[j] += z * (1.0 - f)
    row[j + 1] += z * f


@njit(cache=True, parallel=True)
def _traverse(out, row0, splat, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, migrate, pattern,
              laz, lel, emax, kr, plen, fs, ws, fq, x0, n_l, block, line0, line1):  # pragma: no cover - compiled
    """Every (target, pulse in its beam, channel) of lines [line0, line1): chirp into out[c, k - row0]
    (echo) or splat into it (binned clutter grid). Parallel over blocks of lines (no write races)."""
    n_ch = out.shape[0]
    n_t = tp.shape[0]
    n_blocks = (line1 - line0 + block - 1) // block
    ww_arg = 2.0 * math.pi * kr / (fs * fs)
    ww = complex(math.cos(ww_arg), math.sin(ww_arg))
    for b in prange(n_blocks):
        a0 = line0 + b * block
        a1 = min(line1, a0 + block)
        d = np.empty(3)
        for i in range(n_t):
            for k in range(max(k0[i], a0), min(k1[i], a1)):
                rtx, g = _geometry(t, rp, ux, ue, rot, tp, tv, tref, i, k, pattern, laz, lel, emax, d)
                if g == 0.0:
                    continue
                for c in range(n_ch):
                    rc = _channel_range(d, rtx, rx_off[c], ux, k)
                    renv = rc if migrate else r0[i]
                    z = amp[i] * g * _carrier(rc, lam)
                    if splat:
                        _splat(out[c, k - row0], renv, z, fq, x0, n_l)
                    else:
                        _pulse(out[c, k - row0], renv, z, kr, plen, fs, ws, ww)


@njit(cache=True)
def echo_kernel(out, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, kr, plen, fs, ws,
                migrate, pattern, laz, lel, emax, block, line0, line1):  # pragma: no cover - compiled
    """Accumulate every target's echo into lines [line0, line1) of out (n_channels, n_lines, n_samples)."""
    _traverse(out, 0, False, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, migrate, pattern,
              laz, lel, emax, kr, plen, fs, ws, 0.0, 0.0, 0, block, line0, min(line1, out.shape[1]))


@njit(cache=True)
def splat_kernel(grid, line0, n_l, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, fq, x0,
                 migrate, pattern, laz, lel, emax, block):  # pragma: no cover - compiled
    """Binned clutter: add a_i G exp(-j 4 pi R_c/lam) at fractional delay bin x = 2 R_env/c * fq - x0 of
    grid (n_channels, lines line0.., >= n_l), split linearly between the two neighbouring bins < n_l."""
    _traverse(grid, line0, True, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, migrate, pattern,
              laz, lel, emax, 0.0, 0.0, 1.0, 0.0, fq, x0, n_l, block, line0, line0 + grid.shape[1])


def _gain_reference(d, rtx, ux, ue, pattern, laz, lel, emax):
    """Numpy twin of the gain of :func:`_geometry` for a vector of pulses."""
    se = np.einsum("ki,ki->k", d, ue) / rtx
    g = np.sinc(laz * np.einsum("ki,ki->k", d, ux) / rtx) ** 2 * np.sinc(lel * se) ** 2 if pattern else 1.0
    return np.where(np.abs(se) > emax, 0.0, g)


def echo_reference(out, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, kr, plen, fs, ws,
                   migrate, pattern, laz, lel, emax):
    """Plain-numpy reference of :func:`echo_kernel` (same arguments, no block): vectorized per target."""
    n_ch, n_lines, n_s = out.shape
    for i in range(tp.shape[0]):
        ks = np.arange(k0[i], k1[i])
        if ks.size == 0:
            continue
        q = tp[i] + tv[i] * (t[ks] - tref[i])[:, None]
        p = np.einsum("kij,kj->ki", rot[ks], q)
        d = p - rp[ks]
        rtx = np.linalg.norm(d, axis=1)
        g = _gain_reference(d, rtx, ux[ks], ue[ks], pattern, laz, lel, emax)
        for c in range(n_ch):
            rc = rtx if rx_off[c] == 0 else 0.5 * (rtx + np.linalg.norm(d - rx_off[c] * ux[ks], axis=1))
            renv = rc if migrate else np.full_like(rc, r0[i])
            td = 2.0 * renv / C
            n_lo = np.maximum(0, np.ceil((td - 0.5 * plen - ws) * fs)).astype(np.int64)
            n_hi = np.minimum(n_s - 1, np.floor((td + 0.5 * plen - ws) * fs)).astype(np.int64)
            if np.all(n_hi < n_lo):
                continue
            n = np.arange(n_lo.min(), n_hi.max() + 1)  # the band of samples this target touches
            tau = ws + n[None, :] / fs - td[:, None]
            inside = (n[None, :] >= n_lo[:, None]) & (n[None, :] <= n_hi[:, None])
            sig = (amp[i] * g * np.exp(-4j * np.pi * rc / lam))[:, None] * np.exp(1j * np.pi * kr * tau**2)
            out[c, ks[:, None], n[None, :]] += np.where(inside, sig, 0)


def splat_reference(grid, line0, n_l, t, rp, ux, ue, rot, tp, tv, tref, amp, k0, k1, r0, rx_off, lam, fq, x0,
                    migrate, pattern, laz, lel, emax):
    """Plain-numpy reference of :func:`splat_kernel` (same arguments, no block)."""
    n_ch, n_lines, _ = grid.shape
    for i in range(tp.shape[0]):
        ks = np.arange(max(k0[i], line0), min(k1[i], line0 + n_lines))
        if ks.size == 0:
            continue
        q = tp[i] + tv[i] * (t[ks] - tref[i])[:, None]
        d = np.einsum("kij,kj->ki", rot[ks], q) - rp[ks]
        rtx = np.linalg.norm(d, axis=1)
        g = _gain_reference(d, rtx, ux[ks], ue[ks], pattern, laz, lel, emax)
        for c in range(n_ch):
            rc = rtx if rx_off[c] == 0 else 0.5 * (rtx + np.linalg.norm(d - rx_off[c] * ux[ks], axis=1))
            x = 2.0 * (rc if migrate else np.full_like(rc, r0[i])) / C * fq - x0
            j = np.floor(x).astype(np.int64)
            ok = (j >= 0) & (j + 1 < n_l)
            f = x - j
            z = amp[i] * g * np.exp(-4j * np.pi * rc / lam)
            rows = ks[ok] - line0
            np.add.at(grid[c], (rows, j[ok]), (z * (1.0 - f))[ok])
            np.add.at(grid[c], (rows, j[ok] + 1), (z * f)[ok])
