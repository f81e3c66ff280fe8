"""Mover parameters (vx, vy, x0, y0) from its two-channel slow-time signals ([Ryu2017, §III]).

Input (:class:`SlowTime`): the slow-time signals of the mover's range bin in channel 0 (the
monostatic channel, receiver on the transmitter, range history R(eta) of
:mod:`sarcli.ati.geometry`) and channel 1 (receiver ``d`` along-track, already co-registered by
``d/(2*Vp)``), the slow times ``eta`` (s from the reference time), the mover's tracked range
position in the RCMC'd data ``r_track(eta)`` (m) and the platform.

Range position after RCMC: the RDA moves the energy at Doppler f = -2R'/lam from range R to
``R*D``, D = sqrt(1 - (R'/Vp)^2) (a stationary point's R*D is its closest range, exactly), so a mover
is seen at ``r_track = R(eta)*sqrt(1 - R'(eta)^2/Vp^2)``. With R' and R - R(eta_m) known from the phase
fit, the weighted mean of ``r_track`` fixes the absolute range rho = R(eta_m) (linear in rho). This
holds whether or not the mover's closest approach lies inside the aperture (vy -> Vp included).

Data reduced from the signals:
- the unwrapped phase psi0(eta) of channel 0: R(eta) = -lam/(4*pi)*psi0(eta) + const (the constant
  is lost to the 2*pi ambiguity, so absolute range comes only from ``r_track``);
- the ATI phase history phi(eta) = arg(s1*conj(s0)) = (4*pi/lam)*(d/(2*Vp))*vm(eta) - bistatic term,
  with vm(eta) the mover-induced range rate (see geometry.py) and the bistatic term
  (4*pi/lam)*d**2/(8*R) (half-sum of transmit and receive ranges exceeds the phase-centre range).

Routes (knob ``route``):
``seed``      the chain of [Ryu2017, §III] with the printed typos fixed: quadratic LS at eta = 0 -> vR, aR;
              R0 = mean r_track; vx = vr_los*R0/x0 from the mean ATI phase (neglects vy*y/R over the
              aperture, as the paper does); vy = Vp - sqrt(R0*aR - vx^2) (eq. 15 with aR the full
              second derivative; drops vR^2); azimuth angle phi = (vR/cos_g)/(vy - Vp) (eq. 17 with
              cos_g = ground/slant range = sin(look), the printed cos(theta) uses an angle from the
              horizontal) and x0 = R0*cos_g, y0 = R0*cos_g*phi (eq. 18-19, small angle; neglects
              the vx*x0 term of vR).
``exact``     (default) closed-form exact geometry: polynomial WLS at the weighted centre eta_m of
              the data -> R'(eta_m), R''(eta_m); rho = R(eta_m) from r_track; V2 = rho*R'' + R'^2
              (exact: R*R'' + R'^2 = V2 for straight-line motion); vm(eta_m) from a quadratic fit of
              the ATI phase history; the along-track separation Y = rho*(vm - R')/Vp (since
              R' - vm = vs = -Vp*Y/R), the ground distance X = sqrt(rho^2 - H^2 - Y^2) on the look
              side, vx, vy from R'*rho = vx*X + (vy - Vp)*Y and vx^2 + (vy - Vp)^2 = V2, and finally
              x0, y0, R0, vR, aR at eta = 0.
``nonlinear`` full weighted nonlinear LS of the exact (bistatic) range histories of both channels
              to psi0(eta), phi(eta) and mean r_track, started from ``exact``.
Every route returns 1-sigma uncertainties (propagated covariance, inflated by the reduced
chi-square when the residuals exceed the noise model). vy is taken below Vp (a mover faster than the
platform along-track is indistinguishable); when V2 <= vx^2 (vy -> Vp) the square root is clamped to
0 and ``vy_degenerate`` is set instead of returning NaN.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from sarcli.ati import fit as _fit
from sarcli.ati.geometry import Mover, Platform, blind_speed, coefficients, los_rate_from_phase
from sarcli.ati.unwrap import chirp_phase, dominant_chirp, unwrap, unwrap_slow
from sarcli.errors import SarcliError

ROUTES = ("seed", "exact", "nonlinear")
#: the ATI velocity is reported ambiguous when |phase| + 3 sigma exceeds this fraction of pi: the
#: measured phase is then close enough to the wrap that phase + 2*pi*k is a plausible truth.
AMBIGUITY_FRACTION = 0.8
#: samples whose normalized fit residual exceeds CLIP sigma are dropped and the fit repeated
CLIP = 4.5
#: systematic floor (rad, added in quadrature) of the ATI phase of a mover: inter-channel focusing and
#: co-registration residuals; y0 errors of 0.05-0.3 m (= 0.2-1 mrad) beyond the thermal sigma in the
#: 50-run Monte-Carlo of the paper scenario (bench_ati)
ATI_PHASE_FLOOR = 1e-3


@dataclass
class SlowTime:
    """Two-channel slow-time observation of one mover (see module docstring).

    ``noise_dof``: independent noise samples behind the signals when fewer than their length (a
    slow-time signal recovered from an image sub-window of N lines carries N noise degrees of
    freedom, not one per sample); the fit covariances are scaled by n_used/noise_dof. None = white.
    """

    eta: np.ndarray
    s0: np.ndarray
    s1: np.ndarray
    r_track: np.ndarray
    r_sigma: float
    platform: Platform
    baseline_m: float
    look_sign: float = 1.0
    noise_dof: int | None = None


@dataclass
class Estimate:
    """Estimated mover at the reference time with 1-sigma uncertainties (SI units)."""

    vx_mps: float
    vy_mps: float
    x0_m: float
    y0_m: float
    r0_m: float
    vx_mps_sigma: float
    vy_mps_sigma: float
    x0_m_sigma: float
    y0_m_sigma: float
    r0_m_sigma: float
    vr_mps: float
    ar_mps2: float
    route: str
    vy_degenerate: bool = False
    ati_phase_rad: float = 0.0
    ati_ambiguous: bool = False
    blind_speed_mps: float = 0.0
    chi2_red: float = 1.0
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class _Reduced:
    """Unwrapped phase, ATI phase history and their weights."""

    eta: np.ndarray
    psi0: np.ndarray
    w0: np.ndarray
    phi: np.ndarray
    w_ati: np.ndarray
    sigma2: float
    r_mean: float


def _reduce(obs: SlowTime, unwrap_method: str) -> _Reduced:
    eta = np.asarray(obs.eta, np.float64)
    s0 = np.asarray(obs.s0, np.complex128)
    s1 = np.asarray(obs.s1, np.complex128)
    if eta.shape != s0.shape or s0.shape != s1.shape or np.shape(obs.r_track) != eta.shape or eta.size < 8:
        raise SarcliError("slow-time signals and range track must be 1-D, of equal length >= 8")
    chirp = dominant_chirp(s0, eta)
    psi0 = unwrap(s0, eta, unwrap_method, chirp)
    model = chirp_phase(eta, chirp)
    sigma2 = _fit.noise_power(s0 * np.exp(-1j * model))
    w0 = _fit.phase_weights(s0, sigma2)
    ati = s1 * np.conj(s0)
    ref = np.angle(np.sum(ati * (w0 > 0)))
    phi = unwrap_slow(ati * np.exp(-1j * ref)) + ref
    phi -= 2.0 * np.pi * np.round((np.average(phi, weights=w0 + 1e-300) - ref) / (2.0 * np.pi))
    sigma2_1 = _fit.noise_power(s1 * np.exp(-1j * model))
    w1 = _fit.phase_weights(s1, sigma2_1)
    with np.errstate(divide="ignore", invalid="ignore"):
        w_ati = np.where((w0 > 0) & (w1 > 0), 1.0 / (1.0 / np.maximum(w0, 1e-300) + 1.0 / np.maximum(w1, 1e-300)),
                         0.0)
    r = np.asarray(obs.r_track, np.float64)
    ok = (w0 > 0) & np.isfinite(r)
    if not ok.any():
        raise SarcliError("no slow-time sample carries the mover's signal")
    return _Reduced(eta, psi0, w0, phi, w_ati, sigma2, float(np.average(r[ok], weights=w0[ok])))


def _bistatic_phase(r: float, obs: SlowTime) -> float:
    """ATI phase (rad) of the transmit/receive half-sum excess d^2/(8R) (channel 1 minus 0)."""
    return -4.0 * np.pi / obs.platform.wavelength * obs.baseline_m ** 2 / (8.0 * r)


def _solve_velocities(r0: float, vr: float, y0: float, x0: float, v2: float, vp: float
                      ) -> tuple[float, float, bool]:
    """(vx, vy, degenerate) from vR*R0 = vx*x0 + u*y0 and vx^2 + u^2 = V2, u = vy - Vp < 0."""
    a = 1.0 + (y0 / x0) ** 2
    b = -2.0 * vr * r0 * y0 / x0 ** 2
    c = (vr * r0 / x0) ** 2 - v2
    disc = b * b - 4.0 * a * c
    degenerate = disc <= 0.0
    u = -b / (2.0 * a) if degenerate else (-b - math.sqrt(disc)) / (2.0 * a)
    if u > 0.0:
        u, degenerate = 0.0, True
    vx = (vr * r0 - u * y0) / x0
    return vx, u + vp, degenerate


def _ground(r0: float, obs: SlowTime) -> float:
    g2 = r0 * r0 - obs.platform.height ** 2
    if g2 <= 0:
        raise SarcliError(f"range {r0:.1f} m is shorter than the platform height {obs.platform.height:.1f} m")
    return g2


def _rho(b1: float, b2: float, r_mean: float, fit: tuple, vp: float) -> float:
    """R(eta_m) from the weighted mean tracked range: mean(r) = rho*mean(D) + mean(dR*D)."""
    tau, w, c3, c4 = fit
    dr = b1 * tau + 0.5 * b2 * tau ** 2 + c3 * tau ** 3 + c4 * tau ** 4
    rdot = b1 + b2 * tau + 3.0 * c3 * tau ** 2 + 4.0 * c4 * tau ** 3
    d = np.sqrt(np.maximum(1.0 - (rdot / vp) ** 2, 1e-12))
    return float((r_mean - np.average(dr * d, weights=w)) / np.average(d, weights=w))


def _exact_map(x: np.ndarray, obs: SlowTime, eta_m: float, fit: tuple) -> np.ndarray:
    """(b1, b2, mean r_track, phi_m) -> (vx, vy, x0, y0, R0, vR, aR, degenerate) at eta = 0.

    At eta_m: rho = R, b1 = R', b2 = R''; vm = mover-induced range rate from the ATI phase phi_m;
    the along-track separation Y = y_target - y_platform obeys vs = R' - vm = -Vp*Y/rho, the ground
    distance X^2 = rho^2 - H^2 - Y^2, then vx, u from b1*rho = vx*X + u*Y and vx^2 + u^2 = V2;
    finally x0 = X - vx*eta_m, y0 = Y - u*eta_m.
    """
    b1, b2, r_mean, phi_m = x
    p = obs.platform
    rho = _rho(b1, b2, r_mean, fit, p.speed)
    v2 = rho * b2 + b1 * b1
    vm = float(los_rate_from_phase(phi_m - _bistatic_phase(rho, obs), obs.baseline_m, p))
    y = rho * (vm - b1) / p.speed
    g2 = _ground(rho, obs)
    xg = obs.look_sign * math.sqrt(max(g2 - y * y, 0.0))
    if xg == 0.0:
        raise SarcliError("estimated along-track offset exceeds the ground range: inconsistent data")
    vx, vy, deg = _solve_velocities(rho, b1, y, xg, v2, p.speed)
    x0 = xg - vx * eta_m
    y0 = y - (vy - p.speed) * eta_m
    c = coefficients(Mover(x0, y0, vx, vy), p)
    return np.array([vx, vy, x0, y0, c.r0, c.vr, c.ar, float(deg)])


def _seed_map(x: np.ndarray, obs: SlowTime) -> np.ndarray:
    """(vR, aR, mean r_track, mean ATI phase) -> (vx, vy, x0, y0, R0, vR, aR, degenerate), paper's chain."""
    vr, ar, r0, phi = x
    p = obs.platform
    cos_g = math.sqrt(_ground(r0, obs)) / r0
    vr_los = float(los_rate_from_phase(phi - _bistatic_phase(r0, obs), obs.baseline_m, p))
    vx = obs.look_sign * vr_los / cos_g
    arg = r0 * ar - vx * vx
    deg = arg <= 0.0
    vy = p.speed - math.sqrt(max(arg, 0.0))
    u = vy - p.speed
    az = (vr / cos_g) / u if u != 0.0 else 0.0
    x0 = obs.look_sign * r0 * cos_g
    return np.array([vx, vy, x0, r0 * cos_g * az, r0, vr, ar, float(deg)])


def _degenerate_vy_sigma(fn, x: np.ndarray, cx: np.ndarray) -> float:
    """1-sigma of vy where the square root is clamped (vy -> Vp): the linearized propagation gives 0
    there, so take half the largest change of vy over +-2 sigma steps of each input."""
    sd = np.sqrt(np.maximum(np.diag(cx), 0.0))
    vy0 = fn(x)[1]
    worst = 0.0
    for i in range(x.size):
        for sgn in (-2.0, 2.0):
            xp = x.copy()
            xp[i] += sgn * sd[i]
            try:
                worst = max(worst, abs(fn(xp)[1] - vy0))
            except SarcliError:
                continue
    return 0.5 * worst


def _finish(route: str, y: np.ndarray, cov: np.ndarray, obs: SlowTime, phi_mean: float,
            chi2: float, extra: dict, vy_sigma: float | None = None) -> Estimate:
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    if vy_sigma is not None:
        sd[1] = max(sd[1], vy_sigma)
    vb = blind_speed(obs.baseline_m, obs.platform)
    phi_sd = extra.get("ati_phase_sigma_rad", 0.0)
    return Estimate(
        vx_mps=float(y[0]), vy_mps=float(y[1]), x0_m=float(y[2]), y0_m=float(y[3]), r0_m=float(y[4]),
        vx_mps_sigma=float(sd[0]), vy_mps_sigma=float(sd[1]), x0_m_sigma=float(sd[2]),
        y0_m_sigma=float(sd[3]), r0_m_sigma=float(sd[4]), vr_mps=float(y[5]), ar_mps2=float(y[6]),
        route=route, vy_degenerate=bool(y[7] > 0.5), ati_phase_rad=float(phi_mean),
        ati_ambiguous=bool(abs(phi_mean) + 3.0 * phi_sd > AMBIGUITY_FRACTION * np.pi), blind_speed_mps=vb,
        chi2_red=float(chi2), extra=extra)


def estimate(obs: SlowTime, route: str = "exact", unwrap_method: str = "dechirp",
             degree: int = 4) -> Estimate:
    """Estimate the mover's parameters by ``route`` (see module docstring).

    ``degree`` is the polynomial degree of the range-history fit of the ``exact`` route (2 = the
    quadratic of [Ryu2017, eq. 13]; 4 removes the quartic-term bias of R'' over long apertures). The ``seed``
    route always fits the quadratic of [Ryu2017, eq. 13].
    """
    if route not in ROUTES:
        raise SarcliError(f"unknown estimation route {route!r}; choose one of {', '.join(ROUTES)}")
    red = _reduce(obs, unwrap_method)
    lam = obs.platform.wavelength
    rng = -lam / (4.0 * np.pi) * red.psi0
    w_rng = red.w0 * (4.0 * np.pi / lam) ** 2
    used = red.w0 > 0
    phi_mean = float(np.angle(np.sum(np.exp(1j * red.phi) * red.w_ati)))
    wsum = float(np.sum(red.w_ati))
    phi_sd = 1.0 / math.sqrt(wsum) if wsum > 0 else float("inf")
    corr = max(1.0, used.sum() / obs.noise_dof) if obs.noise_dof else 1.0
    phi_sd *= math.sqrt(corr)
    extra = {"ati_phase_sigma_rad": phi_sd, "n_used": int(used.sum()), "noise_power": red.sigma2,
             "unwrap": unwrap_method, "noise_correlation_factor": corr}
    if route == "seed":
        q = _fit.wls_poly(red.eta, rng, w_rng, 2, clip=CLIP)
        x = np.array([q.coef[1], 2.0 * q.coef[2], red.r_mean, phi_mean])
        cx = np.zeros((4, 4))
        cx[0:2, 0:2] = q.cov[1:3, 1:3] * np.array([[1.0, 2.0], [2.0, 4.0]]) * corr
        cx[2, 2] = obs.r_sigma ** 2
        cx[3, 3] = phi_sd ** 2 + ATI_PHASE_FLOOR ** 2
        y, cov = _fit.propagate(lambda v: _seed_map(v, obs), x, cx)
        vys = _degenerate_vy_sigma(lambda v: _seed_map(v, obs), x, cx) if y[7] > 0.5 else None
        return _finish(route, y, cov, obs, phi_mean, q.chi2_red, extra, vys)
    eta_m = float(np.average(red.eta, weights=red.w0 + 1e-300))
    q = _fit.wls_poly(red.eta - eta_m, rng, w_rng, degree, clip=CLIP)
    qa = _fit.wls_poly(red.eta - eta_m, red.phi, red.w_ati, 2, clip=CLIP)
    x = np.array([q.coef[1], 2.0 * q.coef[2], red.r_mean, qa.coef[0]])
    cx = np.zeros((4, 4))
    cx[0:2, 0:2] = q.cov[1:3, 1:3] * np.array([[1.0, 2.0], [2.0, 4.0]]) * corr
    cx[2, 2] = obs.r_sigma ** 2
    cx[3, 3] = qa.cov[0, 0] * corr + ATI_PHASE_FLOOR ** 2
    hi = np.r_[q.coef, 0.0, 0.0]
    use = red.w0 > 0
    fit = (red.eta[use] - eta_m, red.w0[use], hi[3], hi[4])
    y, cov = _fit.propagate(lambda v: _exact_map(v, obs, eta_m, fit), x, cx)
    chi2 = max(q.chi2_red, qa.chi2_red)
    vys = _degenerate_vy_sigma(lambda v: _exact_map(v, obs, eta_m, fit), x, cx) if y[7] > 0.5 else None
    if route == "exact":
        return _finish(route, y, cov, obs, phi_mean, chi2, extra, vys)
    from sarcli.ati.nonlinear import fit_exact_history

    y, cov, chi2 = fit_exact_history(obs, red.eta, red.psi0, red.w0, red.phi, red.w_ati, red.r_mean, y)
    cov = cov * corr
    return _finish(route, y, cov, obs, phi_mean, chi2, extra, vys)
