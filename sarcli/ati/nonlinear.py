"""Full nonlinear fit of the exact two-channel range histories (the accurate estimation knob).

Parameters ``(vx, vy, x0, y0, c)`` (SI; ``c`` the arbitrary phase constant of channel 0). Data and
models (see :mod:`sarcli.ati.estimate` for the reduction):

    psi0(eta) = -(4*pi/lam)*R(eta) + c                 R exact, :func:`geometry.range_history`
    phi(eta)  = -(4*pi/lam)*(R1(eta) - R(eta))         R1 = channel 1 co-registered by d/(2*Vp):
              R1(eta) = (|r1(eta-D) - r2(eta-D)| + |r1(eta-D) + (0, d, 0) - r2(eta-D)|)/2, D = d/(2*Vp)
    mean r_track = weighted mean of R*sqrt(1 - R'^2/Vp^2)     range position after RCMC (estimate.py)

weighted by the inverse variances; solved by scipy's Levenberg-Marquardt. The covariance is
``(J^T J)^-1`` scaled by ``max(1, chi2_red)``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from sarcli.ati import fit as _fit
from sarcli.ati.geometry import Mover, coefficients, range_history


def _histories(q: np.ndarray, eta: np.ndarray, obs) -> tuple[np.ndarray, np.ndarray]:
    p = obs.platform
    m = Mover(q[2], q[3], q[0], q[1])
    r = range_history(eta, m, p)
    dly = 0.5 * obs.baseline_m / p.speed
    e = eta - dly
    xr = m.x0 + m.vx * e
    yr = m.y0 + (m.vy - p.speed) * e
    r_tx = np.sqrt(xr * xr + yr * yr + p.height ** 2)
    r_rx = np.sqrt(xr * xr + (yr - obs.baseline_m) ** 2 + p.height ** 2)
    return r, 0.5 * (r_tx + r_rx)


def _derived(q: np.ndarray, obs) -> np.ndarray:
    c = coefficients(Mover(q[2], q[3], q[0], q[1]), obs.platform)
    return np.array([q[0], q[1], q[2], q[3], c.r0, c.vr, c.ar])


def fit_exact_history(obs, eta: np.ndarray, psi0: np.ndarray, w0: np.ndarray, phi: np.ndarray,
                      w_ati: np.ndarray, r_mean: float, start: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Refine ``start`` = (vx, vy, x0, y0, ...) -> (values, covariance, chi2_red) as in estimate.py."""
    k = 4.0 * np.pi / obs.platform.wavelength
    use = (w0 > 0) | (w_ati > 0)
    eta, psi0, phi = eta[use], psi0[use], phi[use]
    s0, sa = np.sqrt(w0[use]), np.sqrt(w_ati[use])
    q0 = np.asarray(start[:4], np.float64)
    r_start, _ = _histories(np.r_[q0, 0.0], eta, obs)
    c0 = float(np.average(psi0 + k * r_start, weights=w0[use] + 1e-300))

    wr = w0[use] + 1e-300
    vp = obs.platform.speed

    def resid(q: np.ndarray) -> np.ndarray:
        r, r1 = _histories(q, eta, obs)
        u = q[1] - vp
        rdot = ((q[2] + q[0] * eta) * q[0] + (q[3] + u * eta) * u) / r
        r_img = float(np.average(r * np.sqrt(np.maximum(1.0 - (rdot / vp) ** 2, 1e-12)), weights=wr))
        return np.concatenate([s0 * (psi0 - (-k * r + q[4])), sa * (phi + k * (r1 - r)),
                               [(r_img - r_mean) / obs.r_sigma]])

    q_init = np.r_[q0, c0]
    scale = np.array([0.1, 0.1, 1.0, 1.0, 0.1])
    sol = least_squares(resid, q_init, method="lm", x_scale=scale, xtol=1e-12, ftol=1e-12)
    jac = sol.jac
    dof = max(sol.fun.size - q_init.size, 1)
    chi2 = float(sol.fun @ sol.fun) / dof
    cov_q = np.linalg.pinv(jac.T @ jac) * max(1.0, chi2)
    y, cov = _fit.propagate(lambda v: _derived(v, obs), sol.x, cov_q)
    deg = float(start[7]) if len(start) > 7 else 0.0
    cov8 = np.zeros((8, 8))
    cov8[:7, :7] = cov
    return np.r_[y, deg], cov8, chi2
