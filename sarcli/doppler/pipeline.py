"""The Doppler pipeline as named stages, each a function with typed inputs and outputs.

    prepare (``inputs``)  checks, receiver gain undone
    1. baseband           a centroid estimator (``estimators``): baseband centroid per block
    2. unwrap             continuous centroid over the block grid (``ambiguity.unwrap_blocks``)
    3. ambiguity          one PRF ambiguity for the scene: orbit + attitude model (vector form or the
                          closed form [Koh2003, eq. 6]) with its margin, the half-integer case declared and,
                          when possible, broken by the data-only estimate; without a usable orbit MLCC +
                          MLBF (``dataonly``) with their confidence; "none" keeps the baseband centroid
    4. fit                absolute centroid model fdc(range, time) (``polyfit``)
    5. rate               Doppler rate: exactly -(2/lam) d2R/deta2 at the target of the fitted centroid
                          (orbit), the route of [Koh2003, §4] (look angle re-solved from fdc), or, without an orbit,
                          map-drift autofocus (``mapdrift``) with one effective velocity for the swath
    assemble              :class:`PolyDoppler` with the block table and the :class:`DopplerSummary`

:func:`run` composes them. The geometry (orbit, attitude, and the terrain under every block and every
point of the model grid) is built once, between stages 1 and 2 (:func:`scene_geometry`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sarcli.doppler import ambiguity as amb
from sarcli.doppler.agcsteps import GainSteps
from sarcli.doppler.ambiguity import coverage_factor
from sarcli.doppler.cde import wrap_frequency
from sarcli.doppler.dataonly import combine_estimates, mlbf, mlcc
from sarcli.doppler.estimators import ESTIMATORS
from sarcli.doppler.estimators.base import BasebandBlocks, CentroidEstimator, EstimationInput
from sarcli.doppler.geometry import OrbitGeometry
from sarcli.doppler.options import DopplerOptions
from sarcli.doppler.polyfit import fit_poly2d
from sarcli.doppler.rangecomp import can_compress, range_looks
from sarcli.errors import ConfigError, ProductError
from sarcli.model.constants import C_LIGHT as C
from sarcli.model.doppler import PolyDoppler
from sarcli.model.doppler_summary import (
    DataOnlyEstimate,
    DopplerSummary,
    FitDiagnostics,
    GeometryDiagnostics,
    MapDriftFit,
    MapDriftSegment,
    RateDiagnostics,
)
from sarcli.model.poly import Poly2D
from sarcli.model.raw import RawProduct
from sarcli.model.terrain import Terrain
from sarcli.threads import one_thread_each

#: ``progress(stage, done, total)`` after each of the :data:`STAGES`
Progress = Callable[[str, int, int], None]
STAGES = ("baseband centroid", "unwrap", "ambiguity", "fit", "Doppler rate")


@dataclass(frozen=True)
class ModelGrid:
    """Dense (time, range) grid on which the smooth orbit-based models are sampled: the scene, extended
    in range by 2 % of the range (+-20 km at 1000 km: a focuser evaluates the model at zero-Doppler
    ranges R0 = Rc cos(squint), below the raw swath) and in time by 1 s, within the orbit span; arrays
    (n_t, n_r), slant range m and azimuth time s."""

    range_m: np.ndarray
    time_s: np.ndarray

    @classmethod
    def of(cls, raw: RawProduct, n_r: int = 24, n_t: int = 8) -> ModelGrid:
        r = raw.slant_range()
        t = raw.azimuth_time
        pad_r = 0.02 * r[-1]
        t_lo, t_hi = t[0] - 1.0, t[-1] + 1.0
        if raw.orbit is not None:
            t_lo, t_hi = max(t_lo, float(raw.orbit.time[0])), min(t_hi, float(raw.orbit.time[-1]))
        T, R = np.meshgrid(np.linspace(t_lo, t_hi, n_t), np.linspace(r[0] - pad_r, r[-1] + pad_r, n_r),
                           indexing="ij")
        return cls(R, T)


@dataclass(frozen=True)
class SceneGeometry:
    """Orbit + attitude of the scene and the terrain height (m) under the beam centre of every block and
    every model-grid point. Grid points outside the scene take the height at the nearest scene edge (in
    range and time): the terrain is only asked about the imaged area."""

    orbit: OrbitGeometry
    block_height_m: np.ndarray
    grid: ModelGrid
    grid_height_m: np.ndarray

    def fdc(self, model: str, on_grid: bool, rho: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Geometric centroid (``model`` vector | closed) at the blocks' or the grid's heights."""
        return self.orbit.fdc(model, rho, t, self.grid_height_m if on_grid else self.block_height_m)


@dataclass(frozen=True)
class AmbiguityStage:
    """Stage 3 output: ``result`` (scene and block ambiguities, margins), ``source`` (orbit |
    orbit+data | data | user | none), ``confidence`` (0..1), ``resolved`` (whether a source decided it:
    ``sarcli.model.doppler_summary``), the orbit model's centroid per block (NaN without an orbit), the
    absolute centroid per block, and the data-only estimates that were run."""

    result: amb.AmbiguityResult
    source: str
    confidence: float
    resolved: bool
    fdc_orbit_hz: np.ndarray
    fdc_hz: np.ndarray
    data_only: tuple[DataOnlyEstimate, ...]


@dataclass(frozen=True)
class FitStage:
    """Stage 4 output: the absolute centroid model, the blocks flagged as outliers, the fit diagnostics."""

    fdc_poly: Poly2D
    outlier: np.ndarray
    diagnostics: FitDiagnostics


@dataclass(frozen=True)
class RateStage:
    """Stage 5 output: the rate model, the rate per block (and the seed route's rate, look angle and
    range, NaN without an orbit), the method used (orbit | seed | mapdrift | nominal), its diagnostics
    and, for the orbit routes, the relative error of the model's grid fit."""

    fr_poly: Poly2D
    fr_hz_per_s: np.ndarray
    fr_seed_hz_per_s: np.ndarray
    look_seed_rad: np.ndarray
    range_seed_m: np.ndarray
    method: str
    diagnostics: RateDiagnostics
    grid_fit_max_rel: float | None


def has_orbit(raw: RawProduct) -> bool:
    """Whether the product has Earth state vectors (ECI/ECEF) for the geometric model."""
    return raw.orbit is not None and raw.orbit.frame in ("ECI", "ECEF") and raw.orbit.time.size >= 2


def central_lines(echo: np.ndarray, max_lines: int) -> np.ndarray:
    """The central ``max_lines`` lines of the echo (a view)."""
    n = echo.shape[0]
    a = max(0, (n - max_lines) // 2)
    return echo[a:a + max_lines]


# --- stage 1 ---------------------------------------------------------------------------------------

def baseband(estimator: CentroidEstimator, data: EstimationInput) -> BasebandBlocks:
    """Stage 1: the estimator's blocks, checked (shapes, a usable block)."""
    bb = estimator.baseband(data)
    shape = np.shape(bb.fbb_hz)
    for name in ("quality", "valid", "weight", "range_m", "time_s"):
        if np.shape(getattr(bb, name)) != shape or len(shape) != 2:
            raise ConfigError(f"Doppler centroid estimator {data.options.estimator!r} returned {name} of shape "
                              f"{np.shape(getattr(bb, name))} for centroids of shape {shape} (2-D, equal shapes)")
    if not np.any(bb.valid):
        raise ProductError("no block has a usable Doppler signal (all blocks are noise or zero); "
                           "try larger blocks (--az-block/--rg-block)")
    return bb


# --- stage 2 ---------------------------------------------------------------------------------------

def unwrap(bb: BasebandBlocks, prf: float) -> np.ndarray:
    """Stage 2: fdc_bb + k PRF per block, continuous over the grid (valid blocks fitted; the others
    wrapped around the scene centroid)."""
    fu = amb.unwrap_blocks(np.where(bb.valid, bb.fbb_hz, np.nan), bb.weight, prf, bb.range_m, bb.time_s)
    return np.where(bb.valid, fu, bb.scene_fbb_hz + wrap_frequency(bb.fbb_hz - bb.scene_fbb_hz, prf))


def scene_geometry(raw: RawProduct, options: DopplerOptions, terrain: Terrain, bb: BasebandBlocks
                   ) -> SceneGeometry | None:
    """Orbit, attitude and terrain heights of the blocks and the model grid; None without an orbit."""
    if not has_orbit(raw):
        return None
    geo = OrbitGeometry.from_raw(raw, terrain, options.n_nodes, options.exact_attitude)
    grid = ModelGrid.of(raw)
    r, t = raw.slant_range(), raw.azimuth_time
    h_grid = geo.heights(np.clip(grid.range_m, r[0], r[-1]), np.clip(grid.time_s, t[0], t[-1]))
    return SceneGeometry(geo, geo.heights(bb.range_m, bb.time_s), grid, h_grid)


# --- stage 3 ---------------------------------------------------------------------------------------

#: the orbit/attitude centroid and the data-only one disagree when they differ by more than this many
#: standard errors (both errors combined): the prediction is then not trusted to resolve the ambiguity
DISAGREE_SIGMAS = 3.0


def _orbit_agrees_with_data(run_data_only: Callable[[], tuple[int, float]], data_only: list[DataOnlyEstimate],
                            fdc_orbit_hz: float, orbit_sigma_hz: float, prf: float) -> bool:
    """Cross-check an orbit-resolved scene centroid ``fdc_orbit_hz`` against the data-only estimate
    (MLCC + MLBF combined, run here): False, with a warning saying both, when they differ by more than
    :data:`DISAGREE_SIGMAS` combined standard errors (a wrong attitude, e.g. a yaw off by 180 degrees,
    predicts a centroid whole PRFs away from the echo's) and by at least half a PRF."""
    import logging

    run_data_only()
    best = next((e for e in data_only if e.method == "combined"), None)
    if best is None or not (np.isfinite(best.fdc_hz) and np.isfinite(best.sigma_hz)):
        return True
    gap = abs(best.fdc_hz - fdc_orbit_hz)
    bound = DISAGREE_SIGMAS * float(np.hypot(orbit_sigma_hz, best.sigma_hz))
    if gap <= bound or gap < 0.5 * prf:  # within their errors, or the same ambiguity
        return True
    logging.getLogger(__name__).warning(
        "the orbit/attitude predict a centroid of %.0f Hz, the echo (data-only %s) %.0f +- %.0f Hz: they disagree "
        "by %.0f Hz (more than %.0f sigma): the PRF ambiguity is NOT resolved; check the attitude, or decide it "
        "with --ambiguity data or --ambiguity-value N", fdc_orbit_hz, best.method, best.fdc_hz, best.sigma_hz, gap,
        DISAGREE_SIGMAS)
    return False


def resolve_ambiguity(raw: RawProduct, options: DopplerOptions, bb: BasebandBlocks, fu: np.ndarray,
                      geo: SceneGeometry | None) -> AmbiguityStage:
    """Stage 3: one ambiguity for the scene (module docstring), per-block ambiguities and absolute
    centroids. ``options.ambiguity_value`` forces it (source "user")."""
    radar = raw.radar
    prf = radar.prf_hz
    compress = can_compress(raw)
    fbb, w, fbb_scene = bb.fbb_hz, bb.weight, bb.scene_fbb_hz
    mode = options.ambiguity
    if mode == "auto":
        mode = "orbit" if geo is not None else ("data" if compress else "none")
    if mode == "orbit" and geo is None:
        raise ConfigError("ambiguity from the orbit needs ECI/ECEF state vectors; use --ambiguity data")
    if mode == "data" and not compress:
        raise ConfigError("data-only ambiguity needs a range extent longer than the pulse")
    fdc_orbit = np.full(fbb.shape, np.nan)
    if geo is not None:
        fdc_orbit = geo.fdc(options.fdc_model, False, bb.range_m, bb.time_s)
    data_only: list[DataOnlyEstimate] = []

    def run_data_only() -> tuple[int, float]:
        if not data_only and compress:
            sub = central_lines(raw.echo, options.max_lines)
            looks = range_looks(sub, radar, raw.replica)  # one pair of sub-looks for both estimators
            data_only.extend([mlcc(sub, radar, fbb_scene, options.dataonly_rg_block, looks=looks),
                              mlbf(sub, radar, fbb_scene, options.dataonly_rg_block, looks=looks)])
            both = combine_estimates(data_only, fbb_scene, prf)
            if both is not None:
                data_only.append(both)
        best = next((e for e in data_only if e.method == "combined"), None)
        return (0, 0.0) if best is None else (best.ambiguity, best.confidence)

    tol = options.half_tolerance
    if options.ambiguity_value is not None:
        res = amb.resolve(fbb, fu, fbb_scene + int(options.ambiguity_value) * prf, w, prf, tol)
        source, conf, resolved = "user", 1.0, True
    elif mode == "orbit":
        res = amb.resolve(fbb, fu, fdc_orbit, w, prf, tol)
        xi = (fdc_orbit - fu) / prf
        ww = np.where(w > 0, w, 0)
        scatter = np.sqrt(np.sum(ww * (xi - res.offset_prf) ** 2) / np.sum(ww))
        sigma = np.hypot(options.orbit_sigma_hz / prf, scatter)
        conf = amb.rounding_confidence(res.offset_prf, sigma)
        source, resolved = "orbit", res.resolved
        if not res.resolved and compress:
            n_d, c_d = run_data_only()
            n_lo, n_hi = int(np.floor(res.offset_prf)), int(np.ceil(res.offset_prf))
            if n_d in (n_lo, n_hi) and c_d > 0:  # keep the orbit margin: it is what was ambiguous
                res_d = amb.resolve(fbb, fu, fbb_scene + n_d * prf, w, prf, tol)
                res = dataclasses.replace(res_d, margin=res.margin, offset_prf=res.offset_prf, resolved=False)
                source, conf, resolved = "orbit+data", c_d, True
        elif res.resolved and compress:
            resolved = _orbit_agrees_with_data(run_data_only, data_only, fbb_scene + res.n0 * prf,
                                               options.orbit_sigma_hz, prf)
            if resolved:  # a check only: the summary keeps the data-only estimates where they decided or disagree
                data_only.clear()
    elif mode == "data":
        n_d, conf = run_data_only()
        res = amb.resolve(fbb, fu, fbb_scene + n_d * prf, w, prf, tol)
        source, resolved = "data", res.resolved and conf > 0
    else:
        res = amb.resolve(fbb, fu, fbb_scene, w, prf, tol)
        source, conf, resolved = "none", 0.0, False
    fdc_abs = fbb + res.block_ambiguity * prf
    f_max = max_doppler_hz(raw, options, geo)
    worst = float(np.max(np.abs(fdc_abs)))
    if not worst <= f_max:
        err = ConfigError if source == "user" else ProductError
        raise err(f"absolute Doppler centroid {worst:.6g} Hz (ambiguity {res.n0}) is beyond the largest Doppler the "
                  f"platform can produce (2V/lam = {f_max:.6g} Hz): the PRF ({prf:.6g} Hz), the wavelength or the "
                  "ambiguity is wrong")
    return AmbiguityStage(res, source, float(conf), bool(resolved), fdc_orbit, fdc_abs, tuple(data_only))


def max_doppler_hz(raw: RawProduct, options: DopplerOptions, geo: SceneGeometry | None) -> float:
    """2 V / lam, the largest Doppler any target can have for a platform at ground speed V: the orbit's
    ECEF speed at the scene centre; without an orbit the larger of the product's platform velocity and
    the velocity guess (an upper bound is all this needs)."""
    if geo is not None:
        t_c = 0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1])
        v = float(np.linalg.norm(geo.orbit.sv_ecef.interpolate(t_c)[1]))
    else:
        v = max(raw.radar.platform_velocity_mps or 0.0, options.velocity_guess_mps)
    return 2.0 * v / raw.radar.wavelength_m


# --- stage 4 ---------------------------------------------------------------------------------------

def fit_centroid(raw: RawProduct, options: DopplerOptions, bb: BasebandBlocks, ambs: AmbiguityStage,
                 geo: SceneGeometry | None) -> FitStage:
    """Stage 4: the absolute centroid model with outlier flags.

    With an orbit the geometric model gives the SHAPE of the centroid over the scene (exact to
    < 0.001 Hz) and the data its offset: the blocks fit a residual (data - model), by default a
    constant: it is the attitude-knowledge offset, whose variation across a swath is a few per cent of
    itself, while a fitted slope follows scene content (bright targets) and is extrapolated by the
    focuser to zero-Doppler ranges outside the swath; with ``resid_degree`` > 0 a slope needs >= 8
    distinct block coordinates on its axis. The model + residual is sampled on the model grid and
    fitted by a ``model_degree`` polynomial (noise-free, fit error reported). Without an orbit the
    blocks are fitted directly (``fit_degree``)."""
    prf = raw.radar.prf_hz
    Rg, T, w = bb.range_m, bb.time_s, bb.weight
    if geo is not None:
        resid, outl = fit_poly2d(Rg, T, ambs.fdc_hz - ambs.fdc_orbit_hz, w, options.resid_degree,
                                 k_sigma=options.outlier_sigma, floor=0.002 * prf, points_per_coef=4)
        GR, GT = geo.grid.range_m, geo.grid.time_s
        target = geo.fdc(options.fdc_model, True, GR, GT) + resid(GR, GT)
        fdc_poly, _ = fit_poly2d(GR, GT, target, np.ones_like(GR), options.model_degree, k_sigma=np.inf)
        diag = FitDiagnostics(fdc_grid_fit_max_abs_hz=float(np.max(np.abs(fdc_poly(GR, GT) - target))),
                              residual_coef_hz=resid.coef)
    else:
        fdc_poly, outl = fit_poly2d(Rg, T, ambs.fdc_hz, w, options.fit_degree, k_sigma=options.outlier_sigma,
                                    floor=0.002 * prf, points_per_coef=2)
        diag = FitDiagnostics()
    return FitStage(fdc_poly, outl.reshape(bb.shape), diag)


# --- stage 5 ---------------------------------------------------------------------------------------

def doppler_rate(raw: RawProduct, options: DopplerOptions, bb: BasebandBlocks, fit: FitStage,
                 geo: SceneGeometry | None) -> RateStage:
    """Stage 5: the Doppler rate model by ``options.fr_method`` (auto: orbit if present, else map-drift
    when the swath is longer than the pulse, else the nominal velocity -2 V^2/(lam R))."""
    radar = raw.radar
    lam = radar.wavelength_m
    Rg, T = bb.range_m, bb.time_s
    fr_blk, fr_seed, look_seed, rho_seed = (np.full(bb.shape, np.nan) for _ in range(4))
    fdc_fit = fit.fdc_poly(Rg, T)
    method: str = options.fr_method
    if method == "auto":
        method = "orbit" if geo is not None else ("mapdrift" if can_compress(raw) else "nominal")
    if method in ("orbit", "seed") and geo is None:
        raise ConfigError(f"fr method {method!r} needs ECI/ECEF state vectors; use --fr-method mapdrift")
    seed_vs_exact = seed_failures = grid_rel = mapdrift_fit = nominal_v = None
    if geo is not None:  # the seed route ([Koh2003, §4]) next to the exact one, for comparison
        hb = geo.block_height_m
        fr_seed, look_seed, rho_seed = geo.orbit.fr_seed(fdc_fit, Rg, T, hb)
        fr_exact = geo.orbit.fr_exact(Rg, T, fdc_fit, hb)
        fr_blk = fr_seed if method == "seed" else fr_exact
        seed_vs_exact = float(np.nanmax(np.abs(fr_seed / fr_exact - 1.0))) if np.any(np.isfinite(fr_seed)) else None
        seed_failures = int(np.count_nonzero(~np.isfinite(fr_seed)))
    if method in ("orbit", "seed") and geo is not None:
        GR, GT, hg = geo.grid.range_m, geo.grid.time_s, geo.grid_height_m
        gf = geo.orbit.fr_exact(GR, GT, fit.fdc_poly(GR, GT), hg) if method == "orbit" else \
            geo.orbit.fr_seed(fit.fdc_poly(GR, GT), GR, GT, hg)[0]
        if not np.all(np.isfinite(gf)):
            raise ConfigError("the look-angle inversion of [Koh2003, §4] left its asin/sqrt domain inside the scene; "
                              "use --fr-method orbit")
        fr_poly, _ = fit_poly2d(GR, GT, gf, np.ones_like(gf), options.model_degree, k_sigma=np.inf)
        grid_rel = float(np.max(np.abs(fr_poly(GR, GT) / gf - 1.0)))
    elif method == "mapdrift":
        fr_poly, fr_blk, mapdrift_fit = _mapdrift(raw, options, fit.fdc_poly, geo, Rg, T)
    else:  # nominal: no orbit, no swath to compress
        v = radar.platform_velocity_mps or options.velocity_guess_mps
        grid = ModelGrid.of(raw)
        fr_blk = -2.0 * v**2 / (lam * Rg)
        fr_poly, _ = fit_poly2d(grid.range_m, grid.time_s, -2.0 * v**2 / (lam * grid.range_m),
                                np.ones_like(grid.range_m), options.model_degree, k_sigma=np.inf)
        nominal_v = v
    diag = RateDiagnostics(seed_vs_exact, seed_failures, mapdrift_fit, nominal_v)
    return RateStage(fr_poly, np.asarray(fr_blk, float), fr_seed, look_seed, rho_seed, method, diag, grid_rel)


def _mapdrift(raw: RawProduct, options: DopplerOptions, fdc_poly: Poly2D, geo: SceneGeometry | None,
              Rg: np.ndarray, T: np.ndarray) -> tuple[Poly2D, np.ndarray, MapDriftFit]:
    """Map-drift rate per range segment over the central ``max_lines`` lines, and ONE effective velocity
    for the swath: fr(R) = -2 Vr^2/(lam R) (flat-earth / effective-velocity model, constant in time).

    Fit: c = -2 Vr^2/lam by weighted least squares of the per-segment rates fr_k against c/R_k over the
    segments that converged to within 30 % of their start value, weights w_k = the segment's number of
    range samples (the drift sums independent range bins): c = sum w fr/R / sum w/R^2. Its standard
    error comes from the scatter of the segments about the model, s^2 = sum w (fr - c/R)^2 / (n - 1),
    sigma_c = s / sqrt(sum w/R^2); sigma_Vr = lam sigma_c / (4 Vr) (from Vr = sqrt(-c lam/2)), times the
    coverage factor t_{0.975, n-1} / 1.96 (``ambiguity.coverage_factor``: 1.21 for the default 8
    segments) so that 2 sigma stays a 95 % interval although s has only n - 1 degrees of freedom; not
    defined for a single segment. The model is c R^-1 at every range (no clipping, no flat hold): a
    free slope (fr R linear in R) fitted to a few noisy segments of a narrow swath had the wrong sign on
    the Vancouver block, and a 1/R law cannot be held flat physically.
    """
    from sarcli.doppler.mapdrift import MapDriftResult, map_drift
    from sarcli.doppler.rangecomp import range_compress_valid

    radar = raw.radar
    lam = radar.wavelength_m
    a0 = max(0, (raw.echo.shape[0] - options.max_lines) // 2)
    rc, valid = range_compress_valid(central_lines(raw.echo, options.max_lines), radar, raw.replica)
    dr = C / (2.0 * radar.range_sampling_rate_hz)
    t_c = float(np.mean(raw.azimuth_time[a0:a0 + rc.shape[0]]))
    edges = np.linspace(0, rc.shape[1], max(1, options.mapdrift_segments) + 1).astype(int)
    jobs = []  # (samples a:b, segment range, starting rate)
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if b - a < 8:
            continue
        r_seg = radar.first_range_m + (valid.start + 0.5 * (a + b - 1)) * dr
        fdc = float(fdc_poly(r_seg, t_c))
        if geo is not None:
            fr0 = float(geo.orbit.fr_exact(r_seg, t_c, fdc))
        else:
            v = radar.platform_velocity_mps or options.velocity_guess_mps
            fr0 = -2.0 * v**2 / (lam * r_seg)
        jobs.append((a, b, r_seg, fdc, fr0))

    def drift(job: tuple[int, int, float, float, float]) -> MapDriftResult:
        a, b, r_seg, fdc, fr0 = job
        return map_drift(rc[:, a:b], radar.prf_hz, lam, r_seg, dr, fdc, fr0)

    rng, frs, wts, segments = [], [], [], []
    # one thread per segment: a 1-D FFT is computed alike on any thread, so the rates are the serial ones
    for (a, b, r_seg, _, fr0), res in zip(jobs, one_thread_each(drift, jobs), strict=True):
        ok = res.converged and res.fr_hz_per_s < 0 and abs(res.fr_hz_per_s / fr0 - 1.0) < 0.3
        segments.append((r_seg, res.fr_hz_per_s, fr0, res.iterations, res.converged, bool(ok)))
        if ok:  # a segment without focusable content (noise, dark sea) does not converge: dropped
            rng.append(r_seg)
            frs.append(res.fr_hz_per_s)
            wts.append(float(b - a))
    if not frs:
        raise ProductError("map-drift did not converge in any range segment (no focusable scene content?); "
                           "give the Doppler rate another way (--fr-method orbit needs state vectors)")
    rr, ff, ww = np.array(rng), np.array(frs), np.array(wts)
    swr = np.sum(ww / rr**2)
    c = float(np.sum(ww * ff / rr) / swr)
    vr = float(np.sqrt(-c * lam / 2.0))
    sigma_v = None
    if rr.size > 1:
        s2 = np.sum(ww * (ff - c / rr) ** 2) / (rr.size - 1)
        sigma_v = float(lam * np.sqrt(s2 / swr) / (4.0 * vr)) * coverage_factor(rr.size - 1)
    segs = tuple(MapDriftSegment(r, fr, f0, it, conv, used, c / r) for r, fr, f0, it, conv, used in segments)
    grid = geo.grid if geo is not None else ModelGrid.of(raw)
    GR, GT = grid.range_m, grid.time_s
    x0, xs = 0.5 * (GR.min() + GR.max()), 0.5 * (GR.max() - GR.min())
    y0, ys = 0.5 * (GT.min() + GT.max()), max(0.5 * (GT.max() - GT.min()), 1e-12)
    poly = Poly2D(np.array([[c]]), x0, xs, y0, ys, x_power=-1)
    return poly, poly(Rg, T), MapDriftFit(vr, sigma_v, int(rr.size), segs)


# --- assemble --------------------------------------------------------------------------------------

def assemble(raw: RawProduct, options: DopplerOptions, bb: BasebandBlocks, ambs: AmbiguityStage, fit: FitStage,
             rate: RateStage, geo: SceneGeometry | None, gain_steps: GainSteps | None,
             parameters: dict) -> PolyDoppler:
    """The model, its block table and summary (scene values at the centre sample and time)."""
    radar = raw.radar
    prf = radar.prf_hz
    n_samples = raw.echo.shape[1]
    Rg, T, w = bb.range_m, bb.time_s, bb.weight
    r_c = radar.first_range_m + 0.5 * (n_samples - 1) * C / (2.0 * radar.range_sampling_rate_hz)
    t_c = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
    fdc_c = float(fit.fdc_poly(r_c, t_c))
    gdiag = GeometryDiagnostics()
    if geo is not None:
        other = geo.fdc("closed" if options.fdc_model == "vector" else "vector", False, Rg, T)
        gdiag = GeometryDiagnostics(
            float(np.max(np.abs(other - ambs.fdc_orbit_hz))),
            float(np.sqrt(np.average((ambs.fdc_hz - ambs.fdc_orbit_hz) ** 2, weights=np.where(w > 0, w, 0) + 1e-300))))
    res = ambs.result
    summary = DopplerSummary(
        prf_hz=prf, fdc_baseband_hz=bb.scene_fbb_hz, quality=bb.scene_quality,
        ambiguity=int(np.rint((fdc_c - bb.scene_fbb_hz) / prf)), ambiguity_source=ambs.source,
        ambiguity_confidence=ambs.confidence, ambiguity_margin_prf=float(res.margin),
        ambiguity_resolved=ambs.resolved, fdc_hz=fdc_c, fr_hz_per_s=float(rate.fr_poly(r_c, t_c)),
        scene_range_m=float(r_c), scene_time_s=t_c, fdc_method=options.estimator,
        fdc_model=options.fdc_model if geo is not None else None, fr_method=rate.method, n_blocks=int(bb.fbb_hz.size),
        n_az_blocks=int(bb.shape[0]), n_rg_blocks=int(bb.shape[1]), n_valid_blocks=int(bb.valid.sum()),
        n_outlier_blocks=int(fit.outlier.sum()), data_only=ambs.data_only, fr_info=rate.diagnostics,
        geometry=gdiag, fit=dataclasses.replace(fit.diagnostics, fr_grid_fit_max_rel=rate.grid_fit_max_rel),
        gain_steps=None if gain_steps is None else tuple((int(m), float(d)) for m, d in gain_steps.as_list()),
        estimator_info=bb.info)
    blocks = {
        "range_m": Rg.ravel(), "azimuth_time_s": T.ravel(), "fdc_baseband_hz": bb.fbb_hz.ravel(),
        "quality": bb.quality.ravel(), "weight": w.ravel(), "valid": bb.valid.ravel(),
        "ambiguity": res.block_ambiguity.ravel(), "margin_prf": res.block_margin.ravel(), "fdc_hz": ambs.fdc_hz.ravel(),
        "fdc_fit_hz": fit.fdc_poly(Rg, T).ravel(), "fdc_orbit_hz": ambs.fdc_orbit_hz.ravel(),
        "fr_hz_per_s": rate.fr_hz_per_s.ravel(), "fr_seed_hz_per_s": rate.fr_seed_hz_per_s.ravel(),
        "look_seed_rad": rate.look_seed_rad.ravel(), "range_seed_m": rate.range_seed_m.ravel(),
        "outlier": fit.outlier.ravel(),
    }
    return PolyDoppler(fit.fdc_poly, rate.fr_poly, prf, radar.wavelength_m, blocks, summary, parameters)


# --- the whole pipeline ----------------------------------------------------------------------------

def run(raw: RawProduct, options: DopplerOptions, terrain: Terrain, gain_steps: GainSteps | None,
        parameters: dict, progress: Progress | None = None, first_pass_allowed: bool = True) -> PolyDoppler:
    """Stages 1-5 and the assembly on a prepared product (``inputs.prepare``). The estimator's
    first-pass hook runs this same function with another estimator (and no further first pass)."""
    def step(i: int) -> None:
        if progress is not None:
            progress(STAGES[i], i + 1, len(STAGES))

    def first_pass(name: str) -> PolyDoppler:
        if not first_pass_allowed:
            raise ConfigError(f"Doppler centroid estimator {options.estimator!r} asked for a first pass inside a "
                              "first pass")
        sub = dataclasses.replace(options, estimator=name)
        return run(raw, sub, terrain, None, parameters, None, first_pass_allowed=False)

    prf = raw.radar.prf_hz
    bb = baseband(ESTIMATORS.get(options.estimator), EstimationInput(raw, options, first_pass))
    step(0)
    fu = unwrap(bb, prf)
    step(1)
    geo = scene_geometry(raw, options, terrain, bb)
    ambs = resolve_ambiguity(raw, options, bb, fu, geo)
    step(2)
    fit = fit_centroid(raw, options, bb, ambs, geo)
    step(3)
    rate = doppler_rate(raw, options, bb, fit, geo)
    step(4)
    return assemble(raw, options, bb, ambs, fit, rate, geo, gain_steps, parameters)
