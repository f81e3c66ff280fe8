"""Focus workflow: raw product -> SLC product (HDF5), amplitude GeoTIFFs and a quicklook (file to file).

What is generic to every focuser (:mod:`sarcli.focus.base`) lives here: the input/output guard, the
terrain (``--height`` / ``--dem``), the Doppler model (a Doppler product, published ``fdc``/``fr``,
or estimated from the data when the focuser needs one), streaming the echo from HDF5 block by block
(or handing the echo in memory to a focuser that does not stream), writing the SLC atomically,
image statistics, GeoTIFFs and the quicklook, and the report.

One pass over the image: every focused block goes to a :class:`sarcli.focus.sink.BlockSink` that
writes it, keeps its per-line statistics sums and the multilooked intensities of the GeoTIFFs and
the quicklook; the inputs are hashed on a thread meanwhile. With ``workers`` or ``scheduler`` the
blocks are Dask tasks (:mod:`sarcli.parallel.focus`): the same image, bit for bit.

Refused before any work, in one line: an output that is an input (same file, symbolic or hard
link), options out of range, a raw product marked not focusable (``focusable = False`` with its
``not_focusable_reason``, e.g. TOPS bursts), a Doppler model whose ambiguity is unresolved
(``ambiguity_resolved`` False) unless ``accept_unresolved_ambiguity`` or published ``fdc``/``fr``.
"""

from __future__ import annotations

import dataclasses
import inspect
import logging
import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, ProductError
from sarcli.memory import peak_rss_bytes
from sarcli.workflows.base import Progress, Provenance, Report, no_progress, refuse_overwriting_inputs, using

if TYPE_CHECKING:
    from sarcli.model.raw import RawProduct

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Config:
    """``sarcli focus`` as data (TOML table ``[focus]``).

    raw, output: the raw product and the SLC to write; doppler: a Doppler product, or fdc (Hz) and
    fr (Hz/s) at mid-swath, or neither (estimated from the data); algorithm: a focuser name
    (:data:`sarcli.focus.FOCUSERS`); options: the focuser's options (its ``Options`` fields);
    height_m / dem / dem_geoid: the terrain (:func:`sarcli.io.dem.load_terrain`); geotiff (map
    projected, ``crs`` default UTM, ``pixel_spacing_m``), geotiff_slant, quicklook: optional products
    with looks_az x looks_rg looks, the GeoTIFFs' tiles compressed by ``geotiff_compression``
    (``sarcli.io.images.COMPRESSIONS``); channel: receive channel (0 = /echo);
    accept_unresolved_ambiguity: use a Doppler model whose PRF ambiguity is not resolved;
    algorithm ``auto``: the cheapest registered focuser whose predicted errors on this geometry meet
    ``quality`` (``"irw=0.02,pslr=1,phase=0.1"``, :class:`sarcli.focus.select.Quality`; default those),
    chosen by :func:`sarcli.focus.select.choose_for` once the Doppler model is known, before focusing;
    device: cpu | cuda, the focuser's ``device`` option (None: the focuser's default, cpu);
    workers / threads_per_worker / scheduler: focus the blocks in parallel on a local Dask cluster of
    that many processes, or on the scheduler at that address (:mod:`sarcli.parallel.cluster`); they
    do not change the image and are not stored in the product.
    """

    raw: Path
    output: Path
    doppler: Path | None = None
    fdc: float | None = None
    fr: float | None = None
    algorithm: str = "rd"
    options: dict[str, Any] = field(default_factory=dict)
    height_m: float = 0.0
    dem: Path | None = None
    dem_geoid: Literal["egm96", "egm2008"] | None = None
    geotiff: Path | None = None
    geotiff_slant: Path | None = None
    geotiff_compression: Literal["deflate", "zstd", "none"] = "deflate"
    quicklook: Path | None = None
    crs: str | None = None
    pixel_spacing_m: float | None = None
    looks_az: int = 1
    looks_rg: int = 1
    channel: int = 0
    accept_unresolved_ambiguity: bool = False
    device: Literal["cpu", "cuda"] | None = None
    workers: int | None = None
    threads_per_worker: int = 1
    scheduler: str | None = None
    radiometry: Literal["beta0", "sigma0", "gamma0"] | None = None
    noise_subtraction: bool = False
    quality: str | None = None

    def __post_init__(self) -> None:
        self.cluster()  # checked when the configuration is made
        if self.radiometry is not None and self.radiometry not in ("beta0", "sigma0", "gamma0"):
            raise ConfigError(f"--radiometry must be beta0, sigma0 or gamma0, got {self.radiometry!r}")
        if self.quality is not None:
            if self.algorithm != "auto":
                raise ConfigError("--quality states what --algorithm auto must meet: give --algorithm auto")
            from sarcli.focus.select import Quality

            Quality.parse(self.quality)
        if self.looks_az < 1 or self.looks_rg < 1:
            raise ConfigError(f"--looks-az and --looks-rg must be at least 1, got {self.looks_az} and {self.looks_rg}")
        if self.pixel_spacing_m is not None and not (math.isfinite(self.pixel_spacing_m) and self.pixel_spacing_m > 0):
            raise ConfigError(f"--pixel-spacing must be a positive number of metres, got {self.pixel_spacing_m}")
        if self.doppler is not None and (self.fdc is not None or self.fr is not None):
            raise ConfigError("give either --doppler or --fdc/--fr, not both")
        if (self.fdc is None) != (self.fr is None):
            raise ConfigError("--fdc and --fr go together (centroid Hz and Doppler rate Hz/s)")
        for name in ("fdc", "fr", "height_m"):
            v = getattr(self, name)
            if v is not None and not math.isfinite(v):
                raise ConfigError(f"--{name.replace('_m', '')} must be a finite number, got {v}")
        if self.channel < 0:
            raise ConfigError(f"--channel must be >= 0, got {self.channel}")
        if self.device == "cuda" and (self.workers or self.scheduler):
            raise ConfigError("--device cuda focuses on the GPU in this process: drop --workers/--scheduler")
        from sarcli.io.images import compression_options

        compression_options(self.geotiff_compression)  # one line naming the choices if unknown
        if self.crs is not None:
            from pyproj import CRS
            from pyproj.exceptions import CRSError

            try:
                CRS.from_user_input(self.crs)
            except CRSError:
                raise ConfigError(f"--crs {self.crs!r} is not a known coordinate reference system "
                                  "(e.g. EPSG:32610)") from None

    @property
    def outputs(self) -> tuple[Path | None, ...]:
        return (self.output, self.geotiff, self.geotiff_slant, self.quicklook)

    def cluster(self):
        """Where the blocks run: None (this process) or a :class:`sarcli.parallel.cluster.ClusterSpec`."""
        if self.workers is None and self.scheduler is None:
            return None
        from sarcli.parallel.cluster import cluster_spec

        return cluster_spec(self.scheduler, self.workers, self.threads_per_worker, use_env=False)

    def stored(self) -> dict[str, Any]:
        """The configuration recorded in the product (``parameters["config"]``): everything but where it ran."""
        from sarcli.parallel.cluster import EXECUTION_FIELDS

        return {k: v for k, v in to_mapping(self).items() if k not in EXECUTION_FIELDS}


@dataclass
class FocusReport(Report):
    """What ``sarcli focus --json`` prints."""

    input: str
    products: dict[str, str]
    algorithm: str
    doppler_source: str
    shape: list[int]
    doppler_used: dict[str, float]
    image_statistics: dict[str, Any]
    timings_s: dict[str, float]
    peak_rss_bytes: int
    warnings: list[str]
    parameters: dict[str, Any]
    selection: dict[str, Any] | None = None

    def lines(self) -> list[str]:
        du = self.doppler_used
        out = [f"focused {self.input} -> {self.products['slc']} ({self.shape[0]} x {self.shape[1]}, "
               f"{self.algorithm}) in {self.timings_s['total_s']:.2f} s; Doppler {self.doppler_source}; used at the "
               f"closest range {du['range_m_mid']:.0f} m, mid-swath (the model read at its beam-centre range R0 / "
               f"cos(squint), median over the blocks): fdc {du['fdc_hz_mid']:.1f} Hz, "
               f"fr {du['fr_hz_per_s_mid']:.2f} Hz/s; peak RSS {self.peak_rss_bytes / 2**20:.0f} MiB"]
        out += [f"wrote {v}" for k, v in self.products.items() if k not in ("slc", "crs")]
        if self.selection is not None:
            p = self.selection["predicted"]
            knobs = ", ".join(f"{k}={v}" for k, v in (self.selection["knobs"] or {}).items())
            out.insert(0, f"auto chose {self.algorithm}{f' ({knobs})' if knobs else ''} (predicted: IRW "
                          f"{p['irw']:.2%}, PSLR {p['pslr_db']:.2f} dB, phase {p['phase_rad']:.3f} rad; "
                          f"{len(self.selection['alternatives'])} alternative(s) in --json)")
        return out


def _check_outputs(config: Config) -> None:
    for p in config.outputs:
        if p is not None and not Path(p).resolve().parent.is_dir():
            raise ConfigError(f"output folder {Path(p).resolve().parent} does not exist: create it first")


def _doppler_model(config: Config, raw, shape: tuple[int, int], terrain, load_echo):
    """(model, how): from the Doppler product, from (fdc, fr), or estimated from the data."""
    if config.doppler is not None:
        from sarcli.io.doppler_product import read_doppler
        from sarcli.model.plausible import doppler_model

        model = read_doppler(config.doppler)
        doppler_model(str(config.doppler), model, raw, shape)  # against the geometry, before use
        return model, f"read from {config.doppler}"
    if config.fdc is not None and config.fr is not None:  # Config gives both or neither
        from sarcli.model.constants import C_LIGHT
        from sarcli.model.doppler import GeometricDoppler

        r_mid = raw.radar.first_range_m + (shape[1] // 2) * C_LIGHT / (2 * raw.radar.range_sampling_rate_hz)
        return (GeometricDoppler.from_centroid_and_rate(config.fdc, config.fr, r_mid, raw.radar.wavelength_m),
                f"given as fdc/fr (--fdc/--fr: their values at the beam-centre range {r_mid:.0f} m, mid-swath)")
    from sarcli.doppler.api import estimate_doppler

    log.info("no Doppler product given: estimating the centroid and rate from the data")
    full = load_echo()
    if "terrain" in inspect.signature(estimate_doppler).parameters:
        return estimate_doppler(full, terrain=terrain), "estimated from the data"
    return estimate_doppler(full), "estimated from the data"


def _refuse_unresolved(model, config: Config) -> None:
    if getattr(model, "ambiguity_resolved", True) is False and not config.accept_unresolved_ambiguity:
        raise ProductError("the Doppler centroid's PRF ambiguity is unresolved (the model may be whole PRFs off): "
                           "give the centroid with --fdc/--fr, resolve it in 'sarcli doppler' (an orbit, "
                           "--ambiguity), or accept it with --accept-unresolved-ambiguity")
    from sarcli.model.doppler_summary import low_confidence_note

    note = (None if config.accept_unresolved_ambiguity or config.doppler is None  # an estimate here has warned
            else low_confidence_note(getattr(model, "summary", None)))
    if note:
        log.warning(note)


def run(config: Config, provenance: Provenance | None = None, progress: Progress | None = None) -> FocusReport:
    """Focus ``config.raw`` into ``config.output`` (and the optional images); see the module docstring."""
    from sarcli.io.h5common import start_probing

    start_probing()  # the inputs' metadata probe starts while the focusers are imported
    from sarcli.focus import FOCUSERS
    from sarcli.focus.base import make_plan, options_for, run_blocks
    from sarcli.gpu.device import options_with_device
    from sarcli.io.atomic import all_or_nothing

    progress = progress or no_progress
    with using(provenance):
        t_start = time.perf_counter()
        refuse_overwriting_inputs((config.raw, config.doppler, config.dem), config.outputs)
        _check_outputs(config)
        auto = config.algorithm == "auto"
        focuser: Any = None if auto else FOCUSERS.get(config.algorithm)  # auto: chosen below
        options = None if auto else options_for(focuser, options_with_device(focuser.Options, config.options,
                                                                              config.device))
        from sarcli.io.dem import load_terrain
        from sarcli.io.raw import raw_shape, read_raw

        raw = read_raw(config.raw, load_echo=False)
        _refuse_unfocusable(raw, config.raw)
        if not 0 <= config.channel < raw.n_channels:
            raise ConfigError(f"{config.raw}: product has {raw.n_channels} channel(s), channel {config.channel} "
                              "requested")
        if (config.geotiff or config.geotiff_slant) and (raw.orbit is None or raw.orbit.frame == "LOCAL"):
            raise ConfigError(f"{config.raw}: GeoTIFF needs an Earth orbit (ECI/ECEF state vectors); this product "
                              f"has {'none' if raw.orbit is None else 'a LOCAL (flat) frame'}: drop "
                              "--geotiff/--geotiff-slant")
        terrain = load_terrain(config.height_m, config.dem, config.dem_geoid)
        shape = raw_shape(config.raw)
        load_echo = _Echo(config.raw)

        t0 = time.perf_counter()
        model, how = (None, "not used") if not (auto or focuser.needs_doppler) else _doppler_model(
            config, raw, shape, terrain, load_echo)
        if model is not None and config.fdc is None:
            _refuse_unresolved(model, config)
        t_doppler = time.perf_counter() - t0
        selection, notes = None, []
        if auto:  # before any focusing: a refusal costs nothing but the Doppler model
            focuser, options, selection, notes = _auto(config, raw, shape, model)
        with all_or_nothing():  # the SLC, GeoTIFFs and quicklook appear together or not at all
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                t0 = time.perf_counter()
                slc, sink = _focus_to_file(config, focuser, options, raw, shape, model, terrain, load_echo,
                                           make_plan, run_blocks, progress)
                t_focus = time.perf_counter() - t0
            msgs = notes + [str(w.message) for w in caught]
            for m in msgs:
                log.warning(m)
            t0 = time.perf_counter()
            stats = sink.statistics(slc.first_full_line, slc.last_full_line)
            products = _products(config, slc, sink, terrain, how)
            t_products = time.perf_counter() - t0
        d = slc.doppler
        import numpy as np

        mid = d.fdc_hz.shape[1] // 2
        timings = {"doppler_s": t_doppler, "focus_s": t_focus,
                   **{(k if k.endswith("_s") else f"{k}_s"): float(v) for k, v in slc.timings.items()},
                   "statistics_and_products_s": t_products}
        timings["total_s"] = time.perf_counter() - t_start
        return FocusReport(
            input=str(config.raw), products=products, algorithm=focuser.name if auto else config.algorithm,
            doppler_source=how,
            shape=[int(shape[0]), int(shape[1])],
            doppler_used={"range_m_mid": float(d.range_m[mid]),
                          "fdc_hz_min": float(np.min(d.fdc_hz)), "fdc_hz_max": float(np.max(d.fdc_hz)),
                          "fdc_hz_mid": float(np.median(d.fdc_hz[:, mid])),
                          "fr_hz_per_s_min": float(np.min(d.fr_hz_per_s)),
                          "fr_hz_per_s_max": float(np.max(d.fr_hz_per_s)),
                          "fr_hz_per_s_mid": float(np.median(d.fr_hz_per_s[:, mid])),
                          "effective_velocity_mps_mid": float(np.median(d.velocity_mps[:, mid]))},
            image_statistics=stats, timings_s=timings,
            peak_rss_bytes=peak_rss_bytes(), warnings=msgs,
            parameters=slc.parameters, selection=selection)


def _auto(config: Config, raw, shape, model):
    """(focuser, options, the selection's report, warnings) of ``--algorithm auto``
    (:mod:`sarcli.focus.select`). The user's options go to the chosen focuser where its Options have
    them (the others are named in a warning); the chosen knobs are added. Nothing meeting the quality:
    one line, before focusing."""
    from dataclasses import fields as dc_fields

    from sarcli.errors import SarcliError
    from sarcli.focus import FOCUSERS
    from sarcli.focus.base import options_for
    from sarcli.focus.select import Quality, choose_for

    sel = choose_for(raw, shape, model, config.options, Quality.parse(config.quality))
    if sel.algorithm is None:
        raise SarcliError(sel.refusal())
    focuser = FOCUSERS.get(sel.algorithm)
    known = {f.name for f in dc_fields(focuser.Options)}
    dropped = sorted(set(config.options) - known)
    notes = [f"auto chose {sel.algorithm}, which has no option {', '.join(dropped)}: not used"] if dropped else []
    from sarcli.gpu.device import options_with_device

    kept = {**{k: v for k, v in config.options.items() if k in known}, **sel.knobs}
    options = options_for(focuser, options_with_device(focuser.Options, kept, config.device))
    return focuser, options, sel.to_dict(), notes


def _refuse_unfocusable(raw, path: Path) -> None:
    extra = raw.extra_attrs or {}
    flag = extra.get("focusable", True)
    if flag is False or (hasattr(flag, "dtype") and not bool(flag)):
        reason = extra.get("not_focusable_reason") or "the reader marked it not focusable"
        raise ProductError(f"{path}: this raw product cannot be focused as stripmap: {reason}")


def _focus_to_file(config: Config, focuser, options, raw, shape, model, terrain, load_echo, make_plan, run_blocks,
                   progress: Progress):
    """Plan, stream the blocks into the SLC product (and the sink), write its metadata; returns
    (the SLC metadata, the sink)."""
    from sarcli.focus.quicklook import quicklook_looks
    from sarcli.focus.sink import BlockSink
    from sarcli.io.h5common import open_product
    from sarcli.io.slc import slc_writer
    from sarcli.model import checks as ck
    from sarcli.model.slc import SLC

    ch = config.channel
    if focuser.streams:
        plan_raw = raw
    else:
        full = load_echo()
        plan_raw = dataclasses.replace(full, echo=full.channel(ch), echo_channels=None)
        shape = plan_raw.echo.shape
    plan = make_plan(focuser, plan_raw, shape, model, options, terrain)
    meta = SLC.placeholder(raw, plan.output_shape)
    inputs = tuple(p for p in (config.raw, config.doppler, config.dem) if p is not None)
    looks = []
    if config.geotiff or config.geotiff_slant:
        looks.append((config.looks_az, config.looks_rg))
    if config.quicklook:
        looks.append(quicklook_looks(plan.output_shape, config.looks_az, config.looks_rg)[:2])
    cluster = config.cluster()
    if cluster is not None and not focuser.streams:
        log.info("focuser %s does not stream its echo: focusing in this process", focuser.name)
        cluster = None
    with slc_writer(config.output, meta, plan.output_shape, inputs=inputs) as out:
        def write(first, block):
            out[first:first + block.shape[0]] = block

        sink = BlockSink(write, plan.output_shape, tuple(looks), str(Path(config.output).resolve().parent))

        def on_block(done, total):
            progress("focusing", done, total)

        if cluster is not None:
            from sarcli.parallel.cluster import connect
            from sarcli.parallel.focus import focus_blocks

            with connect(cluster) as client:
                slc = focus_blocks(client, focuser, plan, config.raw, ch, sink, on_block)
        elif focuser.streams and load_echo.raw is None:
            with open_product(config.raw, "raw") as f:
                ds = f["echo"] if ch == 0 else f["echo_channels"]

                def read(a, b):  # the samples of every block checked as they stream in (NaN, inf)
                    return ck.array(str(config.raw), "echo", ds[a:b] if ch == 0 else ds[ch - 1, a:b], "c")

                slc = run_blocks(focuser, plan, read, sink, on_block)
        else:
            echo = load_echo().channel(ch) if focuser.streams else plan_raw.echo
            slc = run_blocks(focuser, plan, lambda a, b: echo[a:b], sink, on_block)
        slc.parameters = {**slc.parameters, "terrain": terrain.describe(), "config": config.stored()}
        from sarcli.calibration.radiometry import annotate

        slc.calibration = annotate(slc, load_echo.raw or raw, shape[1])
        meta.update_from(slc)
    return slc, sink


class _Echo:
    """The raw product with its echo, read on first call (the estimator and non-streaming focusers need
    it in memory; once read, streaming focusers use it instead of reading the file again)."""

    def __init__(self, path: Path):
        self.path = path
        self.raw: RawProduct | None = None

    def __call__(self):
        if self.raw is None:
            from sarcli.io.raw import read_raw

            self.raw = read_raw(self.path)
        return self.raw


def _products(config: Config, slc, sink, terrain, how: str) -> dict[str, str]:
    """GeoTIFFs and quicklook from the multilooked intensities the sink accumulated (``slc``: metadata).
    The GeoTIFFs' provenance hashes the SLC just written (1.2 GB for a full scene, about 1 s): on a thread
    while the quicklook is drawn, so the GeoTIFFs find it done (``sha256_file`` keeps it)."""
    from sarcli.io.h5common import hashing

    products = {"slc": str(config.output)}
    tags = {"source_product": Path(config.output).name, "algorithm": slc.parameters.get("algorithm", config.algorithm),
            "doppler": how}
    geotiffs = config.geotiff or config.geotiff_slant
    with hashing([config.output] if geotiffs else []) as slc_hashed:
        if config.quicklook:
            from sarcli.focus.quicklook import quicklook_looks, write_slc_quicklook

            la, lr, _ = quicklook_looks((slc.azimuth_time.size, slc.slant_range.size), config.looks_az,
                                        config.looks_rg)
            write_slc_quicklook(config.quicklook, slc, config.looks_az, config.looks_rg,
                                intensity=sink.intensity(la, lr))
            products["quicklook"] = str(config.quicklook)
        slc_hashed()
    inten = None
    if geotiffs:
        inten = sink.intensity(config.looks_az, config.looks_rg)
        if config.radiometry:
            from sarcli.calibration.products import radiometric_intensity

            inten, tags = radiometric_intensity(slc, inten, config.looks_az, config.looks_rg, config.radiometry,
                                                terrain, config.noise_subtraction, tags)
    if config.geotiff_slant:
        from sarcli.focus.geocode import write_slant_geotiff

        write_slant_geotiff(config.geotiff_slant, slc, config.looks_az, config.looks_rg, tags, terrain,
                            inputs=(config.output,), intensity=inten,
                            compression=config.geotiff_compression, radiometry=config.radiometry)
        products["geotiff_slant"] = str(config.geotiff_slant)
    if config.geotiff:
        from sarcli.focus.geocode import write_map_geotiff

        used = write_map_geotiff(config.geotiff, slc, config.looks_az, config.looks_rg, config.crs,
                                 config.pixel_spacing_m, tags, terrain, inputs=(config.output,),
                                 intensity=inten, compression=config.geotiff_compression,
                                 radiometry=config.radiometry)
        products["geotiff"] = str(config.geotiff)
        products["crs"] = used
    return products
