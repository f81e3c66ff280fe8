"""``estimate_doppler(raw) -> PolyDoppler`` (contract 4): the seed's hybrid method, plus data-only routes.

Pipeline
1. Baseband centroid per (azimuth block, range block): CDE on the raw echo (default, the seed's
   2048 x 128 blocks), SDE, or CDE after range compression ("rc-cde", over every sample a recorded
   echo reaches, partially compressed window edges included); quality, SNR-aware validity,
   inverse-variance weights (``cde``).
2. Unwrap the baseband centroids over the block grid (``ambiguity.unwrap_blocks``).
3. Ambiguity: from the orbit + attitude model (full vector form by default, or the closed form eq. 6),
   one integer for the scene with its margin; the half-integer case is declared and, when possible,
   broken by the data-only estimate. Without a usable orbit: MLCC + MLBF (``dataonly``) with their
   confidence. ``ambiguity="none"`` keeps the baseband centroid (source "none", confidence 0).
4. Absolute centroid per block, weighted 2-D polynomial fit in (slant range, azimuth time) with
   outlier flags (``polyfit``).
5. Doppler rate: exactly -(2/lam) d2R/deta2 at the target of the fitted absolute centroid (orbit),
   also the seed's route (look angle re-solved from fdc) for comparison; without an orbit, map-drift
   autofocus (``mapdrift``) per range segment and one effective velocity fitted over the swath,
   fr = -2 Vr^2/(lam R) at every range.

Block coordinates: slant range of the block's centre sample (raw sample k <-> two-way time
window_start + k/fs; for the raw echo, energy at sample k comes from scatterers at that range, the
pulse being centred on its delay) and the azimuth (pulse) time of its centre line.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

from sarcli.doppler import ambiguity as amb
from sarcli.doppler.cde import block_correlation, wrap_frequency
from sarcli.doppler.dataonly import combine_estimates, mlbf, mlcc
from sarcli.doppler.polyfit import fit_poly2d
from sarcli.errors import SarcliError
from sarcli.model.constants import C_LIGHT as C
from sarcli.model.doppler import PolyDoppler
from sarcli.model.poly import Poly2D
from sarcli.model.raw import RawProduct

ESTIMATORS = ("cde", "sde", "rc-cde", "lb")
GAIN_STEP_MODES = ("auto", "on", "off")
AMBIGUITY_MODES = ("auto", "orbit", "data", "none")
FR_METHODS = ("auto", "orbit", "seed", "mapdrift")
FDC_MODELS = ("vector", "closed")


def _has_orbit(raw: RawProduct) -> bool:
    return raw.orbit is not None and raw.orbit.frame in ("ECI", "ECEF") and raw.orbit.time.size >= 2


def _can_compress(raw: RawProduct) -> bool:
    n_ref = raw.replica.size if raw.replica is not None and raw.replica.size > 1 else int(
        round(raw.radar.pulse_length_s * raw.radar.range_sampling_rate_hz))
    return raw.echo.shape[1] > n_ref + 16


def _data_for(raw: RawProduct, estimator: str) -> tuple[np.ndarray, int]:
    """(array to correlate, index of its first range sample in the raw echo; negative for rc-cde, whose
    extended compression starts half a pulse before the window)."""
    if estimator != "rc-cde":
        return raw.echo, 0
    if not _can_compress(raw):
        raise SarcliError("rc-cde needs a range extent longer than the pulse")
    from sarcli.doppler.rangecomp import range_compress_extended

    # every scatterer the raw CDE sees, not only the fully compressed ones: on the narrow 384-sample
    # test swath the valid part alone (222 samples) gave 0.58 % PRF, the extended one 0.15 %
    rc, extent = range_compress_extended(raw.echo, raw.radar, raw.replica)
    return rc, extent.start


def estimate_doppler(raw: RawProduct, *, az_block: int = 2048, rg_block: int = 128, estimator: str = "cde",
                     ambiguity: str = "auto", ambiguity_value: int | None = None, fr_method: str = "auto",
                     fdc_model: str = "vector", fit_degree: tuple[int, int] = (2, 1),
                     resid_degree: tuple[int, int] = (0, 0), model_degree: tuple[int, int] = (4, 2),
                     n_nodes: int | None = None, exact_attitude: bool = True, height_m: float | None = None,
                     half_tolerance: float = 0.02, orbit_sigma_hz: float = 140.0, noise_sigmas: float = 5.0,
                     min_quality: float = 0.02, outlier_sigma: float = 4.0, velocity_guess_mps: float = 7000.0,
                     mapdrift_segments: int = 4, dataonly_rg_block: int | None = None,
                     max_lines: int = 4096, gain_steps: str = "auto", lb_band_fraction: float = 0.6,
                     progress: Callable[[str], None] | None = None,
                     _look_balance: tuple | None = None) -> PolyDoppler:
    """Estimate the absolute Doppler centroid and the Doppler rate of a raw product (module docstring).

    ``ambiguity_value`` forces the scene ambiguity (source "user"). ``orbit_sigma_hz`` is the assumed
    1-sigma error of the geometric centroid (default: Radarsat-1's 0.03 deg pitch knowledge, ~140 Hz);
    it sets the orbit route's ambiguity confidence together with the block scatter. The data-only
    ambiguity and map-drift work on the central ``max_lines`` lines (bounded memory on full scenes).
    ``progress(stage)`` is called after each of the 5 stages (for a progress bar).

    ``gain_steps``: "auto" recovers receiver-gain steps from the echo (``agcsteps``) when the product is
    quantized and records no AGC, "on" always, "off" never. ``estimator="lb"`` runs the CDE pipeline
    first (for the Doppler rate and the starting centroid), then replaces every block's baseband
    centroid by the look-balance estimate (``lookbalance``, band ``lb_band_fraction`` x PRF) and runs
    the ambiguity, fit and rate stages again on it.
    """
    def step(stage: str) -> None:
        if progress is not None:
            progress(stage)

    for name, val, allowed in (("estimator", estimator, ESTIMATORS), ("ambiguity", ambiguity, AMBIGUITY_MODES),
                               ("fr_method", fr_method, FR_METHODS), ("fdc_model", fdc_model, FDC_MODELS),
                               ("gain_steps", gain_steps, GAIN_STEP_MODES)):
        if val not in allowed:
            raise SarcliError(f"unknown {name} {val!r}; choose one of {', '.join(allowed)}")
    if estimator == "lb" and not 0.1 <= lb_band_fraction <= 0.9:
        raise SarcliError(f"look-balance band fraction must be in [0.1, 0.9], got {lb_band_fraction}")
    if az_block < 2 or rg_block < 1:
        raise SarcliError(f"block size must be at least 2 lines x 1 sample, got {az_block} x {rg_block}")
    # the AGC changes line by line as bright targets cross the beam: left in, it re-weights the azimuth
    # spectrum asymmetrically (20 Hz on samples/rs1_point.toml)
    has_agc = raw.agc_db is not None
    raw = raw.calibrated()
    steps = None
    if gain_steps == "on" or (gain_steps == "auto" and not has_agc and raw.radar.quantization_bits > 0):
        from sarcli.doppler.agcsteps import detect_gain_steps, undo_gain_steps

        steps = detect_gain_steps(raw.echo)
        if steps.lines.size:
            raw = dataclasses.replace(raw, echo=undo_gain_steps(raw.echo, steps))
    radar = raw.radar
    prf, lam = radar.prf_hz, radar.wavelength_m
    n_lines, n_samples = raw.echo.shape
    if n_lines < 2:
        raise SarcliError(f"the product has {n_lines} azimuth line(s); the Doppler estimate needs at least 2")
    if height_m is None:
        height_m = float(np.asarray(raw.truth.get("reference_height_m", 0.0))) if raw.truth else 0.0
    params: dict[str, Any] = dict(az_block=az_block, rg_block=rg_block, estimator=estimator, ambiguity=ambiguity,
                                  ambiguity_value=ambiguity_value, fr_method=fr_method, fdc_model=fdc_model,
                                  fit_degree=list(fit_degree), resid_degree=list(resid_degree),
                                  model_degree=list(model_degree), n_nodes=n_nodes, exact_attitude=exact_attitude,
                                  height_m=height_m, half_tolerance=half_tolerance, orbit_sigma_hz=orbit_sigma_hz,
                                  noise_sigmas=noise_sigmas, min_quality=min_quality, outlier_sigma=outlier_sigma,
                                  velocity_guess_mps=velocity_guess_mps, mapdrift_segments=mapdrift_segments,
                                  dataonly_rg_block=dataonly_rg_block, max_lines=max_lines,
                                  gain_steps=gain_steps, lb_band_fraction=lb_band_fraction)
    if estimator == "lb" and _look_balance is None:
        return _two_pass_look_balance(raw, params, progress, steps)

    # 1. baseband centroid per block
    data, s_off = _data_for(raw, estimator)
    bc = block_correlation(data, az_block, rg_block, "sde" if estimator == "sde" else "cde")
    fbb = bc.baseband(prf)
    q = bc.quality()
    valid = bc.valid(noise_sigmas, min_quality)
    w = bc.weight(noise_sigmas, min_quality)
    lb_info: dict[str, Any] = {}
    if _look_balance is not None:  # second pass of estimator "lb": its centroids, weights and times
        lb, lb_info = _look_balance
        valid = valid & lb.valid()  # the CDE's noise-floor test stays: LB alone cannot tell noise
        fbb = np.where(valid, lb.fbb_hz, fbb)
        w = np.where(valid, lb.phase_weight(prf), 0.0)
    lc, sc = bc.centres()
    t_blk = np.interp(lc, np.arange(n_lines), raw.azimuth_time)
    r_blk = radar.first_range_m + (sc + s_off) * C / (2.0 * radar.range_sampling_rate_hz)
    T, Rg = np.meshgrid(t_blk, r_blk, indexing="ij")
    if _look_balance is not None:  # a look-balance block is at the centre of the pixels it used
        T = np.where(valid, np.interp(lb.centre_line, np.arange(n_lines), raw.azimuth_time), T)
    if not np.any(valid):
        raise SarcliError("no block has a usable Doppler signal (all blocks are noise or zero); "
                          "try larger blocks (--az-block/--rg-block)")
    sum_corr = np.sum(np.where(valid, bc.corr, 0))
    if estimator == "sde":
        sum_corr = np.sum(np.where(valid, bc.phase_rho() * bc.pairs, 0))
    fbb_scene = float(wrap_frequency(prf * np.angle(sum_corr) / (2 * np.pi), prf))
    if _look_balance is not None:  # inverse-variance circular mean of the look-balance blocks
        fbb_scene = float(wrap_frequency(prf * np.angle(np.sum(w * np.exp(2j * np.pi * fbb / prf))) / (2 * np.pi),
                                         prf))

    step("baseband centroid")

    # 2. unwrap
    fu = amb.unwrap_blocks(np.where(valid, fbb, np.nan), w, prf, Rg, T)
    fu = np.where(valid, fu, fbb_scene + wrap_frequency(fbb - fbb_scene, prf))

    # 3. ambiguity
    geo = None
    if _has_orbit(raw):
        from sarcli.doppler.geometry import OrbitGeometry

        geo = OrbitGeometry.from_raw(raw, height_m, n_nodes, exact_attitude)
    mode = ambiguity
    if mode == "auto":
        mode = "orbit" if geo is not None else ("data" if _can_compress(raw) else "none")
    if mode == "orbit" and geo is None:
        raise SarcliError("ambiguity from the orbit needs ECI/ECEF state vectors; use --ambiguity data")
    if mode == "data" and not _can_compress(raw):
        raise SarcliError("data-only ambiguity needs a range extent longer than the pulse")
    summary: dict[str, Any] = {}
    fdc_orbit = np.full(fbb.shape, np.nan)
    data_only: list = []
    if geo is not None:
        fdc_orbit = geo.fdc_vector(Rg, T) if fdc_model == "vector" else geo.fdc_closed(Rg, T)

    def run_data_only():
        if not data_only and _can_compress(raw):
            sub = _central_lines(raw.echo, max_lines)
            data_only.extend([mlcc(sub, radar, fbb_scene, dataonly_rg_block, raw.replica),
                              mlbf(sub, radar, fbb_scene, dataonly_rg_block, raw.replica)])
        return combine_estimates(data_only)

    if ambiguity_value is not None:
        res = amb.resolve(fbb, fu, fbb_scene + int(ambiguity_value) * prf, w, prf, half_tolerance)
        source, conf = "user", 1.0
    elif mode == "orbit":
        res = amb.resolve(fbb, fu, fdc_orbit, w, prf, half_tolerance)
        xi = (fdc_orbit - fu) / prf
        ww = np.where(w > 0, w, 0)
        scatter = np.sqrt(np.sum(ww * (xi - res.offset_prf) ** 2) / np.sum(ww))
        sigma = np.hypot(orbit_sigma_hz / prf, scatter)
        conf = amb.rounding_confidence(res.offset_prf, sigma)
        source = "orbit"
        if not res.resolved and _can_compress(raw):
            n_d, c_d, _ = run_data_only()
            n_lo, n_hi = int(np.floor(res.offset_prf)), int(np.ceil(res.offset_prf))
            if n_d in (n_lo, n_hi) and c_d > 0:  # keep the orbit margin: it is what was ambiguous
                res_d = amb.resolve(fbb, fu, fbb_scene + n_d * prf, w, prf, half_tolerance)
                res = dataclasses.replace(res_d, margin=res.margin, offset_prf=res.offset_prf, resolved=False)
                source, conf = "orbit+data", c_d
    elif mode == "data":
        n_d, conf, _ = run_data_only()
        res = amb.resolve(fbb, fu, fbb_scene + n_d * prf, w, prf, half_tolerance)
        source = "data"
    else:
        res = amb.resolve(fbb, fu, fbb_scene, w, prf, half_tolerance)
        source, conf = "none", 0.0
    fdc_abs = fbb + res.block_ambiguity * prf
    step("ambiguity")

    # 4. 2-D fit with outlier flags. With an orbit the geometric model gives the SHAPE of the centroid
    # over the scene (exact to < 0.001 Hz) and the data its offset: the blocks fit a residual (data -
    # model), by default a constant: it is the attitude-knowledge offset, whose variation across a
    # swath is a few per cent of itself, while a fitted slope follows scene content (bright targets)
    # and is extrapolated by the focuser to zero-Doppler ranges outside the swath; with
    # resid_degree > 0 a slope needs >= 8 distinct block coordinates on its axis. The model + residual
    # is sampled on a dense grid and
    # fitted by a higher-order polynomial (noise-free, fit error reported). Without an orbit the blocks
    # are fitted directly.
    GR, GT = _model_grid(raw)
    fit_info: dict[str, Any] = {}
    if geo is not None:
        resid, outl = fit_poly2d(Rg, T, fdc_abs - fdc_orbit, w, resid_degree, k_sigma=outlier_sigma,
                                 floor=0.002 * prf, points_per_coef=4)
        g_orbit = geo.fdc_vector(GR, GT) if fdc_model == "vector" else geo.fdc_closed(GR, GT)
        target = g_orbit + resid(GR, GT)
        fdc_poly, _ = fit_poly2d(GR, GT, target, np.ones_like(GR), model_degree, k_sigma=np.inf)
        fit_info["fdc_grid_fit_max_abs_hz"] = float(np.max(np.abs(fdc_poly(GR, GT) - target)))
        fit_info["residual_coef_hz"] = resid.coef
    else:
        fdc_poly, outl = fit_poly2d(Rg, T, fdc_abs, w, fit_degree, k_sigma=outlier_sigma, floor=0.002 * prf,
                                    points_per_coef=2)
    outl = outl.reshape(fbb.shape)
    step("fit")

    # 5. Doppler rate
    fr_blk, fr_seed, look_seed, rho_seed = (np.full(fbb.shape, np.nan) for _ in range(4))
    fr_info: dict[str, Any] = {}
    fdc_fit = fdc_poly(Rg, T)
    fmethod = fr_method
    if fmethod == "auto":
        fmethod = "orbit" if geo is not None else ("mapdrift" if _can_compress(raw) else "nominal")
    if fmethod in ("orbit", "seed") and geo is None:
        raise SarcliError(f"fr method {fmethod!r} needs ECI/ECEF state vectors; use --fr-method mapdrift")
    if geo is not None:
        fr_seed, look_seed, rho_seed = geo.fr_seed(fdc_fit, Rg, T)
        fr_exact = geo.fr_exact(Rg, T, fdc_fit)
        fr_blk = fr_seed if fmethod == "seed" else fr_exact
        fr_info["seed_vs_exact_max_rel"] = float(np.nanmax(np.abs(fr_seed / fr_exact - 1.0))) if np.any(
            np.isfinite(fr_seed)) else None
        fr_info["seed_domain_failures"] = int(np.count_nonzero(~np.isfinite(fr_seed)))
        if fmethod in ("orbit", "seed"):
            gf = geo.fr_exact(GR, GT, fdc_poly(GR, GT)) if fmethod == "orbit" else \
                geo.fr_seed(fdc_poly(GR, GT), GR, GT)[0]
            if not np.all(np.isfinite(gf)):
                raise SarcliError("the seed's look-angle inversion left its asin/sqrt domain inside the scene; "
                                  "use --fr-method orbit")
            fr_poly, _ = fit_poly2d(GR, GT, gf, np.ones_like(gf), model_degree, k_sigma=np.inf)
            fit_info["fr_grid_fit_max_rel"] = float(np.max(np.abs(fr_poly(GR, GT) / gf - 1.0)))
    if fmethod == "mapdrift":
        fr_poly, fr_blk, fr_info["mapdrift"] = _mapdrift(raw, fdc_poly, geo, Rg, T, velocity_guess_mps,
                                                         mapdrift_segments, max_lines)
    elif fmethod == "nominal":
        v = radar.platform_velocity_mps or velocity_guess_mps
        fr_blk = -2.0 * v**2 / (lam * Rg)
        fr_poly, _ = fit_poly2d(GR, GT, -2.0 * v**2 / (lam * GR), np.ones_like(GR), model_degree, k_sigma=np.inf)
        fr_info["nominal_velocity_mps"] = v

    step("Doppler rate")
    r_c = radar.first_range_m + 0.5 * (n_samples - 1) * C / (2.0 * radar.range_sampling_rate_hz)
    t_c = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
    geo_cmp = {}
    if geo is not None:
        other = geo.fdc_closed(Rg, T) if fdc_model == "vector" else geo.fdc_vector(Rg, T)
        geo_cmp["closed_minus_vector_max_abs_hz"] = float(np.max(np.abs(other - fdc_orbit)))
        geo_cmp["fdc_data_minus_orbit_rms_hz"] = float(np.sqrt(np.average((fdc_abs - fdc_orbit) ** 2,
                                                                          weights=np.where(w > 0, w, 0) + 1e-300)))
    fdc_c = float(fdc_poly(r_c, t_c))
    norm = np.sum(bc.energy[valid]) if estimator != "sde" else np.sum(bc.pairs[valid])
    summary.update(
        prf_hz=prf, fdc_baseband_hz=fbb_scene, quality=float(np.abs(sum_corr) / max(norm, 1e-300)),
        ambiguity=int(np.rint((fdc_c - fbb_scene) / prf)), ambiguity_source=source,
        ambiguity_confidence=float(conf), ambiguity_margin_prf=float(res.margin),
        ambiguity_resolved=bool(res.resolved), fdc_hz=fdc_c, fr_hz_per_s=float(fr_poly(r_c, t_c)),
        scene_range_m=float(r_c), scene_time_s=t_c, fdc_method=estimator,
        fdc_model=fdc_model if geo else None, fr_method=fmethod, n_blocks=int(fbb.size),
        n_az_blocks=int(fbb.shape[0]), n_rg_blocks=int(fbb.shape[1]), n_valid_blocks=int(valid.sum()),
        n_outlier_blocks=int(outl.sum()), data_only=[e.as_dict() for e in data_only], fr_info=fr_info,
        geometry=geo_cmp, fit=fit_info, gain_steps=steps.as_list() if steps is not None else None,
        look_balance=lb_info or None)
    blocks = {
        "range_m": Rg.ravel(), "azimuth_time_s": T.ravel(), "fdc_baseband_hz": fbb.ravel(), "quality": q.ravel(),
        "weight": w.ravel(), "valid": valid.ravel(), "ambiguity": res.block_ambiguity.ravel(),
        "margin_prf": res.block_margin.ravel(), "fdc_hz": fdc_abs.ravel(), "fdc_fit_hz": fdc_fit.ravel(),
        "fdc_orbit_hz": fdc_orbit.ravel(), "fr_hz_per_s": np.asarray(fr_blk, float).ravel(),
        "fr_seed_hz_per_s": fr_seed.ravel(), "look_seed_rad": look_seed.ravel(), "range_seed_m": rho_seed.ravel(),
        "outlier": outl.ravel(),
    }
    step("summary")
    return PolyDoppler(fdc_poly, fr_poly, prf, lam, blocks, summary, params)


def _two_pass_look_balance(raw: RawProduct, params: dict[str, Any], progress, steps) -> PolyDoppler:
    """Estimator "lb": CDE pipeline, look balance per block started from the CDE's range-block centroids
    with the first pass's Doppler rate at the scene-centre time, then the pipeline again on it."""
    from sarcli.doppler.cde import combine
    from sarcli.doppler.lookbalance import look_balance

    opts = {k: (tuple(v) if isinstance(v, list) else v) for k, v in params.items()}
    first = estimate_doppler(raw, **{**opts, "estimator": "cde", "gain_steps": "off"})
    radar = raw.radar
    bc = block_correlation(raw.echo, opts["az_block"], opts["rg_block"])
    r_blk = radar.first_range_m + (bc.sample0 + 0.5 * (bc.n_samples - 1)) * C / (2.0 * radar.range_sampling_rate_hz)
    t_c = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
    ka = np.asarray(first.fr(r_blk, np.full_like(r_blk, t_c)), float)
    lb = look_balance(raw.echo, radar.prf_hz, bc.line0, bc.n_lines, bc.sample0, bc.n_samples,
                      combine(bc, 0).baseband(radar.prf_hz)[0], ka, opts["lb_band_fraction"])
    if not np.any(lb.valid()):
        raise SarcliError(f"look balance: no block owns 32+ lines farther than {lb.margin_lines.max()} lines from "
                          f"the scene ends (scene {raw.echo.shape[0]} lines, blocks of {opts['az_block']}); use a "
                          "longer scene or larger --az-block, a smaller --lb-band, or the CDE")
    info = {"band_fraction": opts["lb_band_fraction"], "margin_lines": lb.margin_lines.tolist(),
            "sigma_hz": lb.sigma_hz.tolist(), "pixels": lb.pixels.tolist(),
            "cde_fdc_baseband_hz": first.summary["fdc_baseband_hz"]}
    model = estimate_doppler(raw, **{**opts, "gain_steps": "off"}, progress=progress, _look_balance=(lb, info))
    model.summary["gain_steps"] = steps.as_list() if steps is not None else None  # found before the passes
    model.parameters["gain_steps"] = params["gain_steps"]
    return model


def _model_grid(raw: RawProduct, n_r: int = 24, n_t: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Dense (time, range) grid on which the smooth orbit-based models are sampled: the scene, extended
    in range by 2 % of the range (+-20 km at 1000 km: a focuser evaluates the model at zero-Doppler
    ranges R0 = Rc cos(squint), below the raw swath) and in time by 1 s, within the orbit span."""
    r = raw.slant_range()
    t = raw.azimuth_time
    pad_r = 0.02 * r[-1]
    t_lo, t_hi = t[0] - 1.0, t[-1] + 1.0
    if raw.orbit is not None:
        t_lo, t_hi = max(t_lo, float(raw.orbit.time[0])), min(t_hi, float(raw.orbit.time[-1]))
    T, R = np.meshgrid(np.linspace(t_lo, t_hi, n_t), np.linspace(r[0] - pad_r, r[-1] + pad_r, n_r),
                       indexing="ij")
    return R, T


def _central_lines(echo: np.ndarray, max_lines: int) -> np.ndarray:
    """The central ``max_lines`` lines of the echo (a view)."""
    n = echo.shape[0]
    a = max(0, (n - max_lines) // 2)
    return echo[a:a + max_lines]


def _mapdrift(raw: RawProduct, fdc_poly: Poly2D, geo, Rg, T, v_guess: float, n_seg: int, max_lines: int):
    """Map-drift rate per range segment over the central ``max_lines`` lines, and ONE effective velocity
    for the swath: fr(R) = -2 Vr^2/(lam R) (flat-earth / effective-velocity model, constant in time).

    Fit: c = -2 Vr^2/lam by weighted least squares of the per-segment rates fr_k against c/R_k over the
    segments that converged to within 30 % of their start value, weights w_k = the segment's number of
    range samples (the drift sums independent range bins): c = sum w fr/R / sum w/R^2. Its standard
    error comes from the scatter of the segments about the model, s^2 = sum w (fr - c/R)^2 / (n - 1),
    sigma_c = s / sqrt(sum w/R^2); sigma_Vr = lam sigma_c / (4 Vr) (from Vr = sqrt(-c lam/2)); not
    defined for a single segment. The model is c R^-1 at every range (no clipping, no flat hold): a
    free slope (fr R linear in R) fitted to a few noisy segments of a narrow swath had the wrong sign on
    the Vancouver block, and a 1/R law cannot be held flat physically.
    """
    from sarcli.doppler.mapdrift import map_drift
    from sarcli.doppler.rangecomp import range_compress_valid

    radar = raw.radar
    lam = radar.wavelength_m
    a0 = max(0, (raw.echo.shape[0] - max_lines) // 2)
    rc, valid = range_compress_valid(_central_lines(raw.echo, max_lines), radar, raw.replica)
    dr = C / (2.0 * radar.range_sampling_rate_hz)
    t_c = float(np.mean(raw.azimuth_time[a0:a0 + rc.shape[0]]))
    edges = np.linspace(0, rc.shape[1], max(1, n_seg) + 1).astype(int)
    rng, frs, wts, segments = [], [], [], []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if b - a < 8:
            continue
        r_seg = radar.first_range_m + (valid.start + 0.5 * (a + b - 1)) * dr
        fdc = float(fdc_poly(r_seg, t_c))
        if geo is not None:
            fr0 = float(geo.fr_exact(r_seg, t_c, fdc))
        else:
            v = radar.platform_velocity_mps or v_guess
            fr0 = -2.0 * v**2 / (lam * r_seg)
        res = map_drift(rc[:, a:b], radar.prf_hz, lam, r_seg, dr, fdc, fr0)
        ok = res.converged and res.fr_hz_per_s < 0 and abs(res.fr_hz_per_s / fr0 - 1.0) < 0.3
        segments.append({"range_m": r_seg, "fr_hz_per_s": res.fr_hz_per_s, "start_hz_per_s": fr0,
                         "iterations": res.iterations, "converged": res.converged, "used": bool(ok)})
        if ok:  # a segment without focusable content (noise, dark sea) does not converge: dropped
            rng.append(r_seg)
            frs.append(res.fr_hz_per_s)
            wts.append(float(b - a))
    if not frs:
        raise SarcliError("map-drift did not converge in any range segment (no focusable scene content?); "
                          "give the Doppler rate another way (--fr-method orbit needs state vectors)")
    rr, ff, ww = np.array(rng), np.array(frs), np.array(wts)
    swr = np.sum(ww / rr**2)
    c = float(np.sum(ww * ff / rr) / swr)
    vr = float(np.sqrt(-c * lam / 2.0))
    sigma_v = None
    if rr.size > 1:
        s2 = np.sum(ww * (ff - c / rr) ** 2) / (rr.size - 1)
        sigma_v = float(lam * np.sqrt(s2 / swr) / (4.0 * vr))
    for seg in segments:
        seg["model_hz_per_s"] = c / seg["range_m"]
    GR, GT = _model_grid(raw)
    x0, xs = 0.5 * (GR.min() + GR.max()), 0.5 * (GR.max() - GR.min())
    y0, ys = 0.5 * (GT.min() + GT.max()), max(0.5 * (GT.max() - GT.min()), 1e-12)
    poly = Poly2D(np.array([[c]]), x0, xs, y0, ys, x_power=-1)
    info = {"velocity_mps": vr, "velocity_sigma_mps": sigma_v, "n_segments_used": int(rr.size),
            "segments": segments}
    return poly, poly(Rg, T), info
