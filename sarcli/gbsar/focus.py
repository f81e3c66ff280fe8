"""Focus a GB-SAR scan onto a Cartesian slant-plane grid with DF, RD, BP or ``auto`` (DF far, near
algorithm nearer, split at the DF minimum range of eq. 12), or FFBP (:mod:`sarcli.gbsar.ffbp`: BP's
images by fast factorized backprojection, on BP's grids; code 3 in ``algorithm_map``, as BP).

Grid: rows are range R0 from the rail line on the range-compression bins ``n c/(2 N_Rfft df)`` up to
``max_range`` (default R_max), columns are azimuth x on the lattice ``x_0 + j*k*dx`` of the rail stops
(``k = pixel_x/dx`` an integer, so RD samples fall on pixels exactly), centred on the rail.
Every image has the phase convention ``-4 pi R0/lam`` at a scatterer (DF's ``-4 pi Rc/lam`` is
converted, see :mod:`sarcli.gbsar.deramp`). ``algorithm_map``: 0 not covered, 1 DF, 2 RD, 3 BP.
The stops are taken in increasing rail position (:func:`sarcli.gbsar.rail.ordered`: a scan measured
backwards focuses to the same image; a rail with unknown or repeated positions is refused).
Options: :class:`FocusOptions`, a frozen configuration (``sarcli.config.from_mapping`` builds it
from a table); windows are taper specs of :mod:`sarcli.gbsar.windows`.

Grid mode (``grid_m`` = x0, x1, dx, y0, y1, dy[, z]): backprojection onto the horizontal plane z
(default 0) of the scan frame, rows y, columns x (:func:`sarcli.gbsar.backprojection.backproject_grid`),
from every sweep's antenna phase centre (a rail's ``(x_i, 0, h_i)``, or the scan's 3-D
``antenna_position``) and its reference range; a scatterer focuses to its complex amplitude. Scans
with a 3-D track or reference ranges can only be focused this way. ``permittivity``: the waves travel
at c/sqrt(eps) (every algorithm; ranges are geometric metres in the medium).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from sarcli.errors import ConfigError, ProductError, SarcliError
from sarcli.focus.ffbp import FfbpKnobs
from sarcli.gbsar.backprojection import backproject, backproject_grid
from sarcli.gbsar.deramp import aperture_gain, focus_df, geometric_correction
from sarcli.gbsar.ffbp import ffbp_grid, ffbp_slant
from sarcli.gbsar.rail import ordered
from sarcli.gbsar.rangecomp import RangeProfiles, check_sweep, range_compress, wave_speed
from sarcli.gbsar.rangedoppler import focus_rd_pols, rd_n_xfft
from sarcli.gbsar.system import df_min_range, df_phase_error, next_pow2
from sarcli.gbsar.windows import parse_taper
from sarcli.gpu.device import check_device
from sarcli.model.gbsar import Scan

ALGORITHMS = ("auto", "df", "rd", "bp", "ffbp")
ALG_CODE = {"df": 1, "rd": 2, "bp": 3, "ffbp": 3}


@dataclass
class Grid:
    """Cartesian slant-plane grid: ``ranges`` R0 (n_r,) and ``azimuths`` x (n_x,), metres."""

    ranges: np.ndarray
    azimuths: np.ndarray


MIN_RANGE_BINS = 4  # an image shallower than this many range bins is a mistake, not a product
MAX_GRID_PIXELS = 100_000_000  # a grid larger than this (0.8 GB per polarization) is a typo, not an image


@dataclass(frozen=True)
class PlaneGrid:
    """Horizontal grid of the scan frame: columns ``xs``, rows ``ys`` (m), at height ``z`` (m)."""

    xs: np.ndarray
    ys: np.ndarray
    z: float

    @classmethod
    def from_spec(cls, spec: tuple[float, ...]) -> PlaneGrid:
        """``(x0, x1, dx, y0, y1, dy[, z])``: x0, x0 + dx, ... up to x1 (included when on the lattice),
        the same for y; z default 0. One-line :class:`ConfigError` for anything else."""
        if len(spec) not in (6, 7) or not all(math.isfinite(v) for v in spec):
            raise ConfigError(f"--grid needs six or seven finite numbers x0,x1,dx,y0,y1,dy[,z] (m), got "
                              f"{','.join(f'{v:g}' for v in spec) or 'nothing'}")
        x0, x1, dx, y0, y1, dy = spec[:6]
        sizes = []
        for name, a, b, d in (("x", x0, x1, dx), ("y", y0, y1, dy)):
            if not d > 0 or b < a:
                raise ConfigError(f"--grid: {name} runs from {a:g} to {b:g} m in steps of {d:g} m; the step must "
                                  f"be > 0 and the end >= the start")
            sizes.append(math.floor((b - a) / d + 1e-9) + 1)
        if sizes[0] * sizes[1] > MAX_GRID_PIXELS:  # before the axes are allocated (1 mm over 2000 km: 16 GB each)
            raise ConfigError(f"--grid has {sizes[1]:.4g} x {sizes[0]:.4g} pixels (more than {MAX_GRID_PIXELS:.0e}): "
                              "use larger steps or a smaller area")
        xs, ys = (a + d * np.arange(n) for (a, d), n in zip(((x0, dx), (y0, dy)), sizes, strict=True))
        return cls(xs=xs, ys=ys, z=float(spec[6]) if len(spec) == 7 else 0.0)


def _positive(name: str, flag: str, value: float | None, what: str) -> None:
    if value is not None and not (math.isfinite(value) and value > 0):
        raise ConfigError(f"{name} ({flag}) must be a positive {what}, got {value:g}")


@dataclass(frozen=True)
class FocusOptions:
    """How to focus (SI units; names as the ``sarcli gbsar focus`` options, whose flags the messages give).

    ``algorithm``: auto | df | rd | bp; ``near``: auto's algorithm below the eq. 12 range;
    ``range_window``/``azimuth_window``: taper specs over the frequencies / the stops (or, in BP, each
    pixel's aperture); ``max_range_m``/``min_range_m``: image rows; ``pixel_x_m`` (a multiple of the
    rail step), ``width_m``: image columns; ``criterion_rad``: the eq. 12 phase-error criterion;
    ``n_xfft``: azimuth FFT size of DF/RD; ``*_oversample``: range (and DF azimuth) FFT oversampling;
    ``beam_limited``: BP integrates each pixel's beam footprint only; ``rd_reference``: sinc | rect;
    ``grid_m``: (x0, x1, dx, y0, y1, dy[, z]) backprojects onto that horizontal grid instead (module
    docstring; ``auto`` means BP there, and the slant-grid options must stay unset);
    ``permittivity``: relative permittivity of the medium the waves travel in (>= 1); ``ffbp``: the
    knobs of ``algorithm`` ffbp (:class:`sarcli.focus.ffbp.FfbpKnobs`; aperture_split 64: a rail's footprint
    apertures are short, so most of them are backprojected stop by stop, as BP does);
    ``bp_precision``: single | double, the grid backprojection kernel (float32 phasor recurrence or float64);
    ``device``: cpu, or cuda: the backprojections (bp, auto's bp ranges, ``grid_m``) and ffbp on the GPU
    (:mod:`sarcli.gpu.bp_cuda`, :mod:`sarcli.gpu.ffbp_cuda`; DF and RD stay on the CPU).
    """

    algorithm: Literal["auto", "df", "rd", "bp", "ffbp"] = "auto"
    range_window: str = "hamming"
    azimuth_window: str = "hamming"
    max_range_m: float | None = None
    min_range_m: float = 0.0
    pixel_x_m: float | None = None
    width_m: float | None = None
    criterion_rad: float = math.pi / 4
    near: Literal["bp", "rd"] = "bp"
    n_xfft: int | None = None
    bp_oversample: int = 4
    rd_oversample: int = 2
    df_oversample: int = 2
    beam_limited: bool = True
    rd_reference: Literal["sinc", "rect"] = "sinc"
    grid_m: tuple[float, ...] = ()
    permittivity: float = 1.0
    ffbp: FfbpKnobs = FfbpKnobs(aperture_split=64)
    bp_precision: Literal["single", "double"] = "single"
    device: Literal["cpu", "cuda"] = "cpu"

    def __post_init__(self) -> None:
        object.__setattr__(self, "device", check_device(self.device))
        if self.algorithm not in ALGORITHMS:
            raise ConfigError(f"unknown algorithm '{self.algorithm}' (use {', '.join(ALGORITHMS)})")
        if self.near not in ("rd", "bp"):
            raise ConfigError(f"the near-range algorithm (--near) must be 'rd' or 'bp', not '{self.near}'")
        if self.rd_reference not in ("sinc", "rect"):
            raise ConfigError(f"unknown RD reference '{self.rd_reference}' (use sinc or rect)")
        parse_taper(self.range_window)
        parse_taper(self.azimuth_window)
        _positive("max_range_m", "--max-range", self.max_range_m, "range in metres")
        if not (math.isfinite(self.min_range_m) and self.min_range_m >= 0):
            raise ConfigError(f"min_range_m (--min-range) must be a finite range >= 0 m, got {self.min_range_m:g}")
        _positive("pixel_x_m", "--pixel-x", self.pixel_x_m, "azimuth pixel in metres")
        _positive("width_m", "--width", self.width_m, "azimuth extent in metres")
        if not (math.isfinite(self.criterion_rad) and 0 < self.criterion_rad <= math.pi):
            raise ConfigError(f"the DF phase-error criterion must be in (0, pi] rad, got {self.criterion_rad:g}")
        if self.n_xfft is not None and self.n_xfft < 1:
            raise ConfigError(f"n_xfft (--n-xfft) must be a positive FFT size, got {self.n_xfft}")
        for name in ("bp_oversample", "rd_oversample", "df_oversample"):
            if getattr(self, name) < 1:
                raise ConfigError(f"{name} must be >= 1, got {getattr(self, name)}")
        if not (math.isfinite(self.permittivity) and self.permittivity >= 1.0):
            raise ConfigError(f"--permittivity must be a relative permittivity >= 1, got {self.permittivity:g}")
        if self.bp_precision not in ("single", "double"):
            raise ConfigError(f"bp_precision must be 'single' or 'double', not '{self.bp_precision}'")
        if self.grid_m:
            self.plane_grid()
            if self.algorithm not in ("bp", "ffbp", "auto"):
                raise ConfigError(f"--grid is a backprojection grid: use --algorithm bp, not {self.algorithm} "
                                  "(or ffbp)")
            slant = [flag for flag, value in (("--max-range", self.max_range_m), ("--pixel-x", self.pixel_x_m),
                                              ("--width", self.width_m), ("--n-xfft", self.n_xfft))
                     if value is not None] + (["--min-range"] if self.min_range_m else [])
            if slant:
                raise ConfigError(f"{', '.join(slant)} shape the slant-plane grid; with --grid the grid says it all")

    def plane_grid(self) -> PlaneGrid:
        """The ``grid_m`` grid (module docstring)."""
        return PlaneGrid.from_spec(tuple(float(v) for v in self.grid_m))


def check_range_interval(scan: Scan, opts: FocusOptions) -> None:
    """Refuse a range interval that holds fewer than MIN_RANGE_BINS range bins, before any focusing.

    The bin is the range-compression sample spacing ``c / (2 N df)``, ``N = 2^ceil(log2 N_f)``
    (N_Rfft of Table 1); ranges stop at R_max = c / (4 df) (c/sqrt(eps) in a medium). Nothing to check
    on a ``grid_m`` grid (it is checked when the options are made).
    """
    if opts.grid_m:
        return
    df = check_sweep(scan.frequency)
    v = wave_speed(opts.permittivity)
    dr = v / (2 * next_pow2(scan.frequency.size) * df)
    r_max = v / (4 * df)
    lo, hi = opts.min_range_m, opts.max_range_m
    if lo > r_max - MIN_RANGE_BINS * dr:
        raise ConfigError(f"--min-range {lo:g} m leaves fewer than {MIN_RANGE_BINS} range bins below the "
                          f"unambiguous range R_max = {r_max:.4g} m of this sweep")
    top = r_max if hi is None else min(hi, r_max)
    if top - lo < MIN_RANGE_BINS * dr:
        raise ConfigError(f"the range interval {lo:g}-{top:g} m holds fewer than {MIN_RANGE_BINS} range bins "
                          f"of {dr:.3g} m (R_max {r_max:.4g} m): give --max-range at least "
                          f"{lo + MIN_RANGE_BINS * dr:.3g} m and --min-range below it")


@dataclass
class Focused:
    image: np.ndarray  # (n_pol, n_r, n_x) complex64
    grid: Grid
    algorithm_map: np.ndarray  # (n_r, n_x) uint8
    report: dict = field(default_factory=dict)


def default_grid(prof: RangeProfiles, antenna_length_m: float, opts: FocusOptions) -> Grid:
    """Rows: compression bins in [min_range, max_range]; columns: k*dx lattice over ``width``.

    Default width ``min(lam R/(2 dx), lam R/L_x + X)`` at the top range R (DF's azimuth width, or the
    beam footprint plus the rail); for backprojection ``lam R/L_x + X`` (the whole track plus the beam
    footprint: DF's FFT width is no limit of BP's); default pixel ``k dx`` with
    ``k = round(dR/(2 dx))`` (>= 1).
    """
    r = prof.ranges_m
    keep = (r >= opts.min_range_m) & (r <= (opts.max_range_m if opts.max_range_m is not None else np.inf))
    ranges = r[keep]
    if ranges.size < 1:
        raise SarcliError("the range interval selects no range bins")
    x = prof.positions_m
    dx = float(np.median(np.diff(x))) if x.size > 1 else prof.dr_m
    lam = prof.wavelength_m
    rail = float(x[-1] - x[0])
    rt = float(ranges[-1])
    footprint = lam * rt / antenna_length_m + rail
    width = (opts.width_m if opts.width_m is not None else footprint if opts.algorithm == "bp"
             else min(lam * rt / (2 * dx), footprint))
    k = max(1, int(round((opts.pixel_x_m if opts.pixel_x_m is not None else prof.dr_m / 2) / dx)))
    if opts.pixel_x_m is not None and not math.isclose(k * dx, opts.pixel_x_m, rel_tol=1e-6):
        raise SarcliError(f"--pixel-x must be a multiple of the rail step {dx:g} m")
    step = k * dx
    centre = 0.5 * (x[0] + x[-1])
    j0, j1 = math.ceil((centre - width / 2 - x[0]) / step), math.floor((centre + width / 2 - x[0]) / step)
    azimuths = x[0] + step * np.arange(j0, j1 + 1)
    if azimuths.size < 1:
        raise SarcliError(f"the image width {width:g} m holds no azimuth pixel of {step:g} m: give --width at "
                          f"least {step:g} m")
    return Grid(ranges=ranges, azimuths=azimuths)


def _bp(scan: Scan, pol: str, grid: Grid, rows: np.ndarray, opts: FocusOptions) -> np.ndarray:
    prof = range_compress(scan, pol, opts.range_window, opts.bp_oversample, permittivity=opts.permittivity)
    px, pr = np.meshgrid(grid.azimuths, grid.ranges[rows])
    return backproject(prof, px, pr, scan.antenna.length_azimuth_m if opts.beam_limited else None,
                       opts.azimuth_window, opts.device)


def _ffbp(scan: Scan, pol: str, grid: Grid, rows: np.ndarray, opts: FocusOptions) -> np.ndarray:
    prof = range_compress(scan, pol, opts.range_window, opts.bp_oversample, permittivity=opts.permittivity)
    px, pr = np.meshgrid(grid.azimuths, grid.ranges[rows])
    return ffbp_slant(prof, px, pr, scan.antenna.length_azimuth_m if opts.beam_limited else None,
                      opts.azimuth_window, opts.ffbp, device=opts.device)


def _df(scan: Scan, pol: str, grid: Grid, rows: np.ndarray, opts: FocusOptions) -> tuple[np.ndarray, np.ndarray, int]:
    """DF with range and azimuth FFTs ``df_oversample`` times Table 1's sizes (finer polar grid for the
    bilinear geometric correction; 1 = the paper's N_Rfft x N_xfft), on BP's amplitude normalization."""
    prof = range_compress(scan, pol, opts.range_window, opts.df_oversample, opts.max_range_m, opts.permittivity)
    n = opts.n_xfft or next_pow2(scan.rail_position.size) * opts.df_oversample
    pol_img = focus_df(prof, n, opts.azimuth_window)
    part, cov = geometric_correction(pol_img, grid.ranges[rows], grid.azimuths, prof.wavelength_m)
    part *= aperture_gain(prof, scan.antenna.length_azimuth_m, grid.ranges[rows], grid.azimuths, opts.azimuth_window)
    return part, cov, n


def _rd(scan: Scan, pols: tuple[str, ...], grid: Grid, rows: np.ndarray, opts: FocusOptions,
        antenna_length_m: float, n_xfft: int | None) -> tuple[list[tuple[np.ndarray, np.ndarray]], int]:
    """RD of every polarization at once (the filters are shared, :func:`focus_rd_pols`), sampled onto
    the grid's rows and azimuths: ``[(part, covered)]`` per polarization, and N_xfft."""
    profs = [range_compress(scan, pol, opts.range_window, opts.rd_oversample,
                            max_range_m=float(grid.ranges[rows][-1]) * 1.05 + 1.0, permittivity=opts.permittivity)
             for pol in pols]
    imgs = focus_rd_pols(profs, antenna_length_m, n_xfft, opts.azimuth_window,
                         max_range_m=float(grid.ranges[rows][-1]) + 1e-9, reference=opts.rd_reference)
    img = imgs[0]
    ri = np.rint(grid.ranges[rows] / img.ranges_m[1]).astype(np.int64) if img.ranges_m.size > 1 else \
        np.zeros(rows.size, np.int64)
    ci = np.rint((grid.azimuths - img.azimuth_first_m) / img.dx_m).astype(np.int64)
    ok_c = (ci >= 0) & (ci < img.n_xfft)
    parts = []
    for im in imgs:
        out = np.zeros((rows.size, grid.azimuths.size), np.complex64)
        out[:, ok_c] = im.data[np.clip(ri, 0, im.data.shape[0] - 1)][:, ci[ok_c]]
        parts.append((out, np.broadcast_to(ok_c, out.shape).copy()))
    return parts, img.n_xfft


def focus_scan(scan: Scan, opts: FocusOptions | None = None, grid: Grid | None = None,
               pols: tuple[str, ...] | None = None) -> Focused:
    """Focus every polarization of ``scan`` (or ``pols``) with ``opts.algorithm``; report the choices.

    The stops are focused in increasing rail position (:func:`sarcli.gbsar.rail.ordered`); the
    report's ``skipped_stops`` are indices of the input scan. With ``opts.grid_m``:
    :func:`focus_grid` (``grid`` unused)."""
    opts = opts or FocusOptions()
    if opts.grid_m:
        return focus_grid(scan, opts, pols)
    if not scan.is_rail:
        what = "3-D antenna positions" if scan.antenna_position is not None else "reference ranges"
        raise ConfigError(f"this scan has {what} (not a straight rail in absolute range): focus it on a grid "
                          "with --algorithm bp --grid x0,x1,dx,y0,y1,dy[,z]")
    scan, order = ordered(scan)
    pols = pols or scan.polarizations
    lx = scan.antenna.length_azimuth_m
    prof0 = range_compress(scan, pols[0], opts.range_window, 1, opts.max_range_m, opts.permittivity)
    if np.all(prof0.weights == 0):
        raise SarcliError("every rail stop is flagged or holds NaN: nothing to focus")
    grid = grid or default_grid(prof0, lx, opts)
    x = scan.rail_position
    rail = float(x[-1] - x[0])
    split = df_min_range(prof0.wavelength_m, rail, lx, opts.criterion_rad)
    alg = opts.algorithm
    uniform = x.size < 3 or np.allclose(np.diff(x), np.diff(x)[0], rtol=1e-6, atol=0)
    near, near_selection = opts.near, None
    if alg == "auto" and opts.near == "bp":  # ffbp instead where it is a GB-SAR algorithm and predicted good
        from dataclasses import asdict

        from sarcli.focus.select import gbsar_near

        own = getattr(opts, "ffbp", None)  # the GB-SAR ffbp's knobs, where it has them
        near, near_selection = gbsar_near(x.size, ALGORITHMS, opts.azimuth_window,
                                          knobs=asdict(own) if own is not None else None)
    if alg == "auto" and not uniform:
        alg_plan = {near if near == "ffbp" else "bp": np.arange(grid.ranges.size)}
    elif alg == "auto":
        near_rows = np.flatnonzero(grid.ranges < split)
        far_rows = np.flatnonzero(grid.ranges >= split)
        alg_plan = {k: v for k, v in ((near, near_rows), ("df", far_rows)) if v.size}
    else:
        alg_plan = {alg: np.arange(grid.ranges.size)}
    amap = np.zeros((grid.ranges.size, grid.azimuths.size), np.uint8)
    image = np.zeros((len(pols), grid.ranges.size, grid.azimuths.size), np.complex64)
    timings: dict[str, float] = {}
    n_xfft_used: dict[str, int] = {}
    for name, rows in alg_plan.items():
        t0 = time.perf_counter()
        if name == "rd":
            n = opts.n_xfft
            if n is None:  # cover the grid's width at its far rows (and the paper's rule)
                dx = float(np.median(np.diff(x)))
                width_n = (grid.azimuths[-1] - grid.azimuths[0]) / dx + 2 * x.size
                n = max(rd_n_xfft(prof0.wavelength_m, float(grid.ranges[rows][-1]), dx, x.size),
                        next_pow2(width_n))
            rd_parts, n_xfft_used["rd"] = _rd(scan, pols, grid, rows, opts, lx, n)
        for ip, pol in enumerate(pols):
            if name == "bp":
                part, cov = _bp(scan, pol, grid, rows, opts), np.ones((rows.size, grid.azimuths.size), bool)
            elif name == "ffbp":
                part, cov = _ffbp(scan, pol, grid, rows, opts), np.ones((rows.size, grid.azimuths.size), bool)
            elif name == "df":
                part, cov, n_xfft_used["df"] = _df(scan, pol, grid, rows, opts)
            else:
                part, cov = rd_parts[ip]
            image[ip, rows] = np.where(cov, part, 0)
            amap[rows] = np.where(cov, ALG_CODE[name], 0)
        timings[name] = time.perf_counter() - t0
    report = {
        "algorithm": opts.algorithm,
        "used": {k: [float(grid.ranges[v][0]), float(grid.ranges[v][-1])] for k, v in alg_plan.items()},
        "df_min_range_m": split, "criterion_rad": opts.criterion_rad,
        "near_algorithm": near if opts.algorithm == "auto" else None,
        "rail_uniform": bool(uniform), "skipped_stops": sorted(int(order[i]) for i in prof0.skipped),
        "rail_reordered": bool(np.any(order != np.arange(order.size))),
        # L_x of the beam footprint |x - x_i| <= lam R0/(2 L_x) that limits each pixel's aperture
        # (None: whole rail); interferometry masks pixels outside it (sarcli.gbsar.interferometry.support)
        "footprint_antenna_length_m": lx if opts.beam_limited else None,
        "n_xfft": n_xfft_used, "seconds": timings, "polarizations": list(pols),
        "range_window": opts.range_window, "azimuth_window": opts.azimuth_window,
    }
    if opts.permittivity != 1.0:
        report["permittivity"] = opts.permittivity
    if near_selection is not None:
        report["near_selection"] = near_selection
    if opts.algorithm == "auto" and not uniform:
        report["note"] = "non-uniform rail steps: DF/RD impossible, the whole image was backprojected"
    df_ranges = grid.ranges[alg_plan["df"]] if "df" in alg_plan else np.zeros(0)
    if df_ranges.size and df_ranges[0] < split:  # DF asked to image nearer than eq. 12 allows
        r_low = float(df_ranges[df_ranges > 0][0]) if np.any(df_ranges > 0) else split
        err = df_phase_error(prof0.wavelength_m, r_low, prof0.wavelength_m * r_low / (2 * lx), rail / 2)
        report["df_below_limit"] = {"from_m": float(df_ranges[0]), "limit_m": split,
                                    "eq11_phase_error_rad": float(err)}
    return Focused(image=image, grid=grid, algorithm_map=amap, report=report)


def _track(scan: Scan) -> np.ndarray:
    """The scan's antenna phase centres, refused in one line when focusing cannot use them."""
    a = scan.antenna_xyz()
    bad = ~np.all(np.isfinite(a), axis=1)
    if scan.reference_range is not None:
        bad |= ~np.isfinite(np.asarray(scan.reference_range, np.float64))
    if np.any(bad):
        idx = np.flatnonzero(bad)
        raise ProductError(f"the antenna position or reference range of sweep(s) {', '.join(map(str, idx[:5]))}"
                           f"{f' (and {idx.size - 5} more)' if idx.size > 5 else ''} is not finite: their geometry "
                           "is unknown, so the scan cannot be focused")
    if scan.n_stops < 2 or np.all(a == a[0]):
        raise ProductError(f"the scan's {scan.n_stops} sweep(s) were measured from one antenna position: there "
                           "is no synthetic aperture to focus")
    return a


def focus_grid(scan: Scan, opts: FocusOptions, pols: tuple[str, ...] | None = None) -> Focused:
    """Backproject every polarization onto the horizontal grid ``opts.grid_m`` (module docstring);
    ``Focused.grid`` holds y in ``ranges`` and x in ``azimuths``; ``algorithm_map`` is 3 where some
    sweep's profile covered the pixel. The report gives the grid, the share of pixels that every sweep
    covered (``full_aperture_fraction``: pixels outside lie beyond some sweep's unambiguous range
    window [-R_max, R_max) about its reference range) and the skipped sweeps."""
    plane = opts.plane_grid()
    ant = _track(scan)
    pols = pols or scan.polarizations
    image = np.zeros((len(pols), plane.ys.size, plane.xs.size), np.complex64)
    t0 = time.perf_counter()
    for ip, pol in enumerate(pols):
        prof = range_compress(scan, pol, opts.range_window, opts.bp_oversample, permittivity=opts.permittivity,
                              centred=True)
        if np.all(prof.weights == 0):
            raise SarcliError("every sweep is flagged or holds NaN: nothing to focus")
        if opts.algorithm == "ffbp":
            image[ip], frac = ffbp_grid(prof, ant, scan.reference_range, plane.xs, plane.ys, plane.z,
                                        opts.azimuth_window, opts.ffbp, device=opts.device)
        else:
            image[ip], frac = backproject_grid(prof, ant, scan.reference_range, plane.xs, plane.ys, plane.z,
                                               opts.azimuth_window, opts.bp_precision, opts.device)
    amap = np.where(frac > 0, ALG_CODE["bp"], 0).astype(np.uint8)
    used = "ffbp" if opts.algorithm == "ffbp" else "bp"
    report = {
        "algorithm": opts.algorithm, "used": {used: [float(plane.ys[0]), float(plane.ys[-1])]},
        "grid": {"x_m": [float(plane.xs[0]), float(plane.xs[-1])], "y_m": [float(plane.ys[0]), float(plane.ys[-1])],
                 "dx_m": float(opts.grid_m[2]), "dy_m": float(opts.grid_m[5]), "z_m": plane.z},
        "n_sweeps": scan.n_stops, "track": "rail" if scan.antenna_position is None else "3-D",
        "reference_range": scan.reference_range is not None,
        "unambiguous_range_m": [float(prof.first_range_m), float(-prof.first_range_m)],
        "full_aperture_fraction": float(np.mean(frac >= 1.0 - 1e-9)),
        "skipped_stops": list(prof.skipped), "seconds": {used: time.perf_counter() - t0},
        "polarizations": list(pols), "range_window": opts.range_window, "azimuth_window": opts.azimuth_window,
        "footprint_antenna_length_m": None, "permittivity": opts.permittivity, "bp_precision": opts.bp_precision,
    }
    return Focused(image=image, grid=Grid(ranges=plane.ys, azimuths=plane.xs), algorithm_map=amap, report=report)


def image_from_scan(scan: Scan, opts: FocusOptions | None = None, grid: Grid | None = None,
                    pols: tuple[str, ...] | None = None):
    """Focus ``scan`` and wrap the result as a :class:`sarcli.io.gbsar_image.GbsarImage` product."""
    from sarcli.model.gbsar import GbsarImage

    opts = opts or FocusOptions()
    f = focus_scan(scan, opts, grid, pols)  # checked the rail (or track): finite, >= 2 distinct positions
    fr, x = scan.frequency, np.sort(np.asarray(scan.rail_position, np.float64))
    return GbsarImage(image=f.image, range_m=f.grid.ranges, azimuth_m=f.grid.azimuths, algorithm_map=f.algorithm_map,
                      polarizations=tuple(f.report["polarizations"]), algorithm=opts.algorithm,
                      center_frequency_hz=float(0.5 * (fr[0] + fr[-1])),
                      frequency_step_hz=float((fr[-1] - fr[0]) / max(fr.size - 1, 1)), n_freq=int(fr.size),
                      rail_height_m=float(np.mean(scan.rail_height)), rail_centre_m=float(0.5 * (x[0] + x[-1])),
                      rail_length_m=float(x[-1] - x[0]), epoch_utc=scan.epoch_utc,
                      scan_time_s=float(np.mean(scan.stop_time)) if scan.stop_time is not None else 0.0,
                      site=scan.site, report=f.report, permittivity=opts.permittivity,
                      grid_z_m=opts.plane_grid().z if opts.grid_m else None)
