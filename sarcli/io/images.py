"""Images for people: Cloud-Optimized GeoTIFFs (rasterio, real CRS, nodata, units, provenance tags,
overviews averaged in power, a QGIS style beside them) and PNG quicklooks.

GeoTIFF layout (``write_geotiff``): GDAL's COG driver (tiled 256 x 256, deflate level 1 with the
floating-point predictor by default (:data:`COMPRESSIONS`: or zstd, or none), overviews after the
full-resolution image, the main IFD first), float32 bands,
nodata NaN. Overviews are computed here (:mod:`sarcli.io.overviews`), one level per factor 2 until the
picture fits one 256-pixel tile, with the reduction the band's quantity needs (``Band.overview``:
``power`` for amplitudes, ``power_db`` for dB, ``phase`` the circular mean, ``mean``), from the rows
as they are written: the full image goes to an uncompressed tiled GeoTIFF and its levels to one
GeoTIFF each, attached to a VRT of the full image as its overviews, and the COG driver copies the VRT
with ``OVERVIEWS=FORCE_USE_EXISTING`` (GDAL computes none itself).

Deflate level 1 rather than GDAL's default 6: on a map-projected amplitude + dB scene (2 x 166 Mpixel)
the file is 1.4 % larger and written 1.8x faster (bench_products); the predictor does most of the work.

Every GeoTIFF carries provenance tags (:func:`provenance_tags`: software, version, creation time,
command line, input files with their SHA-256, and the sensor, wavelength, look side and acquisition
times when the image has them), per band a description, a unit, scale 1 and offset 0, and a QGIS
style ``NAME.qml`` beside it (:class:`Style`; QGIS loads it with the layer) so the default stretch is
readable: dB bands as grey from a 2nd to a 99.5th percentile, phase on a cyclic colour ramp.

All files are written atomically (temporary file in the target folder, then rename).
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import tempfile
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sarcli import threads
from sarcli.errors import ConfigError, ProductError
from sarcli.io.atomic import atomic_path  # re-exported: plots and CSV writers import it from here

if TYPE_CHECKING:
    from sarcli.io.overviews import OverviewKind

#: the tile size of every GeoTIFF (pixels); overviews go down until the image fits one tile
BLOCK = 256

#: readable names of the ``source`` attribute of raw/SLC products
SENSORS = {"ceos": "RADARSAT-1 (CEOS raw)", "sentinel1-l0": "Sentinel-1 (level-0)", "nisar-l0b": "NISAR L0B",
           "matlab": "RADARSAT-1 (Cumming & Wong MATLAB block)", "simulated": "simulated (sarcli simulate)",
           "measured": "GB-SAR (sarcli gbsar scan)", "imported": "imported frequency sweeps"}


#: GDAL's block cache while a GeoTIFF is written, MB (its default, 5 % of the machine's memory, would hold
#: a large raster's blocks a second time)
GDAL_CACHE_MB = 64


@dataclass(frozen=True)
class Strips:
    """A raster too large to hold twice, given as ``shape`` and ``strips()``: an iterator of (first row,
    rows) covering the rows in order (rows in multiples of 256, the GeoTIFF's tile height, but the last)."""

    shape: tuple[int, int]
    strips: Any

    def __iter__(self) -> Iterator[tuple[int, np.ndarray]]:
        return iter(self.strips())


@dataclass(frozen=True)
class Band:
    """One float32 band: ``data`` (2-D array or :class:`Strips`), ``description``, ``unit``
    (UDUNITS-like: ``dB``, ``rad``, ``mm``, ``1``), the overview reduction (module docstring), and
    ``derive``, applied to the data (each strip of it) before writing: bands derived from one
    :class:`Strips` object compute it once (the amplitude and its dB of a map projection)."""

    data: np.ndarray | Strips
    description: str
    unit: str
    overview: OverviewKind = "mean"
    derive: Callable[[np.ndarray], np.ndarray] | None = None

    def values(self, data: np.ndarray) -> np.ndarray:
        """This band's float32 values of (a strip of) its data."""
        return np.asarray(data if self.derive is None else self.derive(data), np.float32)


@dataclass(frozen=True)
class Style:
    """The QGIS style written beside the GeoTIFF: ``band`` (1-based) drawn from ``vmin`` to ``vmax``
    in grey (``cmap = "gray"``) or on a matplotlib colour map (``twilight`` for phase, ...)."""

    band: int
    vmin: float
    vmax: float
    cmap: str = "gray"
    label: str = ""


def _tiff_datetime(iso_utc: str) -> str:
    t = _dt.datetime.strptime(iso_utc, "%Y-%m-%dT%H:%M:%S.%fZ")
    return t.strftime("%Y:%m:%d %H:%M:%S")


def utc_after(epoch_utc: str, seconds: float) -> str:
    """ISO-8601 UTC of ``seconds`` after the ISO-8601 ``epoch_utc`` (microseconds)."""
    from sarcli.io.h5common import parse_utc

    t = parse_utc(epoch_utc) + _dt.timedelta(seconds=float(seconds))
    return t.strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def provenance_tags(inputs: Sequence[str | os.PathLike] = (), *, sensor: str | None = None,
                    wavelength_m: float | None = None, look_side: str | None = None,
                    acquisition: tuple[str, float, float] | None = None, **extra: Any) -> dict[str, str]:
    """The GeoTIFF metadata of an image: who made it and from what (``SOFTWARE``, ``SOFTWARE_VERSION``,
    ``CREATED_UTC`` (``SOURCE_DATE_EPOCH`` when set), ``COMMAND_LINE`` (the caller's, as products
    record it), ``INPUTS`` (JSON list of ``{path, sha256}``, the path as the caller gave it, folder
    included)), what was observed (``SENSOR``,
    ``WAVELENGTH_M``, ``LOOK_SIDE``, ``ACQUISITION_START_UTC``/``_STOP_UTC`` from ``acquisition`` =
    (epoch, first s, last s)), the TIFF's own ``TIFFTAG_SOFTWARE``/``TIFFTAG_DATETIME``, and ``extra``
    (upper-cased keys; dicts and lists as JSON)."""
    from sarcli import __version__
    from sarcli.io.h5common import created_utc, describe_inputs
    from sarcli.io.provenance import current

    created = created_utc()
    tags: dict[str, Any] = {
        "SOFTWARE": "sarcli", "SOFTWARE_VERSION": __version__, "CREATED_UTC": created,
        "COMMAND_LINE": current().command_line, "INPUTS": json.dumps(
            [{**d, "path": os.fspath(p)} for d, p in zip(describe_inputs(inputs), inputs, strict=True)]),
        "TIFFTAG_SOFTWARE": f"sarcli {__version__}", "TIFFTAG_DATETIME": _tiff_datetime(created),
    }
    if sensor is not None:
        tags["SENSOR"] = SENSORS.get(sensor, sensor)
    if wavelength_m is not None:
        tags["WAVELENGTH_M"] = repr(float(wavelength_m))
    if look_side is not None:
        tags["LOOK_SIDE"] = look_side
    if acquisition is not None:
        epoch, t0, t1 = acquisition
        tags["ACQUISITION_START_UTC"] = utc_after(epoch, t0)
        tags["ACQUISITION_STOP_UTC"] = utc_after(epoch, t1)
    for k, v in extra.items():
        if v is not None:
            tags[k.upper()] = json.dumps(v, sort_keys=True, default=float) if isinstance(v, dict | list | tuple) \
                else str(v)
    return {k: str(v) for k, v in tags.items()}


def _band_strips(bands: Sequence[Band], shape: tuple[int, int]) -> Iterator[tuple[int, list[np.ndarray]]]:
    """(first row, float32 values of every band) strip by strip: the :class:`Strips` sources iterated
    once each, in lockstep (their strips must cover the same rows); array bands cut to the same rows."""
    sources: dict[int, Strips] = {id(b.data): b.data for b in bands if isinstance(b.data, Strips)}
    if not sources:
        yield 0, [b.values(b.data) for b in bands]
        return
    iters = {k: iter(v) for k, v in sources.items()}
    row = 0
    while row < shape[0]:
        got = {k: next(it, None) for k, it in iters.items()}
        if any(g is None or g[0] != row for g in got.values()) or len({g[1].shape[0] for g in got.values()}) != 1:
            raise ProductError(f"GeoTIFF band strips do not cover the rows alike at row {row}")
        rows = next(iter(got.values()))[1].shape[0]
        yield row, [b.values(got[id(b.data)][1] if isinstance(b.data, Strips) else
                             np.asarray(b.data)[row:row + rows]) for b in bands]
        row += rows


def _attach_overviews(vrt: Path, files: Sequence[tuple[int, str]], n_bands: int) -> None:
    """Add ``<Overview>`` elements (one GeoTIFF per level) to every band of a GDAL VRT."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(vrt)
    for band in tree.getroot().iter("VRTRasterBand"):
        i = int(band.get("band"))
        if i > n_bands:
            continue
        for _, name in files:
            ov = ET.SubElement(band, "Overview")
            src = ET.SubElement(ov, "SourceFilename", relativeToVRT="1")
            src.text = name
            ET.SubElement(ov, "SourceBand").text = str(i)
    tree.write(vrt)


#: GeoTIFF tile compressions (GDAL COG creation options): level 1 with the floating-point predictor
#: for both codecs (docs/products.md: size and time of each on a full scene's map)
COMPRESSIONS: dict[str, dict[str, str]] = {
    "deflate": {"COMPRESS": "DEFLATE", "PREDICTOR": "YES", "LEVEL": "1"},
    "zstd": {"COMPRESS": "ZSTD", "PREDICTOR": "YES", "LEVEL": "1"},
    "none": {"COMPRESS": "NONE"},
}


def compression_options(name: str) -> dict[str, str]:
    """The COG creation options of the compression ``name`` (:data:`COMPRESSIONS`); ConfigError if unknown."""
    if name not in COMPRESSIONS:
        raise ConfigError(f"GeoTIFF compression must be one of {', '.join(COMPRESSIONS)}, got {name!r}")
    return COMPRESSIONS[name]


def write_geotiff(
    path: str | os.PathLike,
    bands: Band | Sequence[Band],
    crs: str | int,
    transform: Any | None = None,
    gcps: Sequence[tuple[float, float, float, float, float]] | None = None,
    tags: Mapping[str, Any] | None = None,
    style: Style | None = None,
    compression: str = "deflate",
) -> None:
    """Write a Cloud-Optimized GeoTIFF of float32 ``bands`` (nodata NaN) and its QGIS style (module
    docstring). ``compression``: one of :data:`COMPRESSIONS` (deflate, the widest support; zstd, about
    2x faster to compress at the same size, needs a reader with zstd: GDAL >= 2.3; none).

    Georeferencing is either an affine ``transform`` (rasterio.Affine) in ``crs``, or ground control
    points ``gcps`` given as (row, col, x, y, z) in ``crs`` (e.g. EPSG:4326 lon/lat for slant-range
    geometry images). ``crs`` is anything rasterio accepts ("EPSG:32610", 4326, a WKT string).
    ``tags``: :func:`provenance_tags` (and anything else to keep, upper-case keys by convention).
    Bands given as :class:`Strips` are written strip by strip and their overviews computed from the
    strips as they pass: a raster never held whole gives the same file as the array would.
    """
    import rasterio
    import rasterio.shutil
    from rasterio.control import GroundControlPoint
    from rasterio.crs import CRS
    from rasterio.errors import NotGeoreferencedWarning
    from rasterio.windows import Window

    from sarcli.io.overviews import Pyramid, overview_factors

    bands = [bands] if isinstance(bands, Band) else list(bands)
    if not bands:
        raise ProductError("a GeoTIFF needs at least one band")
    codec = compression_options(compression)
    shape = tuple(bands[0].data.shape) if isinstance(bands[0].data, Strips) else np.shape(bands[0].data)
    for b in bands:
        got = tuple(b.data.shape) if isinstance(b.data, Strips) else np.shape(b.data)
        if len(got) != 2 or got != shape:
            raise ProductError(f"GeoTIFF bands must be 2-D arrays of one shape, got {got}")
    if (transform is None) == (gcps is None):
        raise ProductError("a GeoTIFF needs either an affine transform or ground control points")
    crs_obj = CRS.from_epsg(crs) if isinstance(crs, int) else CRS.from_user_input(crs)
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ProductError(f"output folder {folder} does not exist")
    profile: dict[str, Any] = {"crs": crs_obj, "transform": transform} if transform is not None else {}
    if shape[0] >= BLOCK and shape[1] >= BLOCK:
        profile.update(tiled=True, blockxsize=BLOCK, blockysize=BLOCK)
    with tempfile.TemporaryDirectory(prefix=f".{path.name}.", dir=folder) as td, warnings.catch_warnings(), \
            rasterio.Env(GDAL_CACHEMAX=GDAL_CACHE_MB):
        # GCPs are attached after the file is opened (rasterio warns in between); overview levels have none
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        base = os.path.join(td, "full.tif")
        factors = overview_factors(shape, BLOCK)
        with rasterio.open(base, "w", driver="GTiff", count=len(bands), dtype="float32", nodata=np.nan,
                           height=shape[0], width=shape[1], INTERLEAVE="BAND", **profile) as dst, \
                Pyramid(td, shape, factors, [b.overview for b in bands], BLOCK) as pyramid:
            for row, values in _band_strips(bands, shape):
                for i, v in enumerate(values, start=1):
                    dst.write(v, i, window=Window(0, row, shape[1], v.shape[0]))
                pyramid.add(values)
            for i, b in enumerate(bands, start=1):
                dst.set_band_description(i, b.description)
                dst.set_band_unit(i, b.unit)
            dst.scales = (1.0,) * len(bands)
            dst.offsets = (0.0,) * len(bands)
            if gcps is not None:
                dst.gcps = ([GroundControlPoint(row=r, col=c, x=x, y=y, z=z) for r, c, x, y, z in gcps], crs_obj)
            if tags:
                dst.update_tags(**{str(k): str(v) for k, v in tags.items()})
            for i, b in enumerate(bands, start=1):
                dst.update_tags(i, OVERVIEW_RESAMPLING=b.overview)
        levels = list(zip(factors, pyramid.names, strict=True))
        vrt = Path(td) / "full.vrt"
        rasterio.shutil.copy(base, vrt, driver="VRT")
        _attach_overviews(vrt, levels, len(bands))
        with atomic_path(path, ".tif") as tmp:
            # tiles are compressed on the thread budget's threads, each on its own: the same bytes as one
            # thread
            rasterio.shutil.copy(str(vrt), tmp, driver="COG", **codec, BLOCKSIZE=str(BLOCK),
                                 OVERVIEWS="FORCE_USE_EXISTING" if levels else "NONE",
                                 BIGTIFF="IF_SAFER", NUM_THREADS=str(threads.budget()))
    if style is not None:
        write_qgis_style(path.with_suffix(".qml"), style, n_bands=len(bands))


def write_qgis_style(path: str | os.PathLike, style: Style, n_bands: int = 1) -> None:
    """A QGIS layer style (``.qml``; QGIS 3 loads ``NAME.qml`` beside ``NAME.tif`` with the layer):
    one band in grey or on a colour ramp, stretched from ``vmin`` to ``vmax``, NaN transparent."""
    import xml.etree.ElementTree as ET

    if not 1 <= style.band <= n_bands:
        raise ProductError(f"style band {style.band} is not one of the {n_bands} band(s)")
    if not (np.isfinite(style.vmin) and np.isfinite(style.vmax) and style.vmax > style.vmin):
        raise ProductError(f"style stretch {style.vmin}..{style.vmax} is empty")
    root = ET.Element("qgis", version="3.22.0", styleCategories="AllStyleCategories")
    pipe = ET.SubElement(root, "pipe")
    lo, hi = f"{style.vmin:.6g}", f"{style.vmax:.6g}"
    if style.cmap == "gray":
        r = ET.SubElement(pipe, "rasterrenderer", type="singlebandgray", grayBand=str(style.band),
                          gradient="BlackToWhite", opacity="1", alphaBand="-1")
        ET.SubElement(r, "rasterTransparency")
        ce = ET.SubElement(r, "contrastEnhancement")
        ET.SubElement(ce, "minValue").text = lo
        ET.SubElement(ce, "maxValue").text = hi
        ET.SubElement(ce, "algorithm").text = "StretchToMinimumMaximum"
    else:
        from matplotlib import colormaps

        cmap = colormaps[style.cmap]
        r = ET.SubElement(pipe, "rasterrenderer", type="singlebandpseudocolor", band=str(style.band),
                          classificationMin=lo, classificationMax=hi, opacity="1", alphaBand="-1")
        ET.SubElement(r, "rasterTransparency")
        shader = ET.SubElement(ET.SubElement(r, "rastershader"), "colorrampshader", colorRampType="INTERPOLATED",
                               classificationMode="1", clip="0", minimumValue=lo, maximumValue=hi)
        for x in np.linspace(0.0, 1.0, 17):
            v = style.vmin + x * (style.vmax - style.vmin)
            rgb = "#{:02x}{:02x}{:02x}".format(*(int(round(255 * c)) for c in cmap(float(x))[:3]))
            ET.SubElement(shader, "item", value=f"{v:.6g}", color=rgb, alpha="255", label=f"{v:.4g}")
    ET.SubElement(pipe, "brightnesscontrast", brightness="0", contrast="0")
    ET.SubElement(pipe, "rasterresampler", maxOversampling="2")
    ET.SubElement(root, "blendMode").text = "0"
    if style.label:
        ET.SubElement(root, "layerComment").text = style.label  # not read by QGIS: a note for people
    ET.indent(root)
    with atomic_path(path, ".qml") as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write("<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n")
            fh.write(ET.tostring(root, encoding="unicode"))
            fh.write("\n")


def db_stretch(db: np.ndarray, low_pct: float = 2.0, high_pct: float = 99.5) -> tuple[float, float]:
    """A readable grey stretch of a dB image: its ``low_pct`` and ``high_pct`` percentiles of the finite
    pixels, at least 10 dB apart ((-30, 0) dB for an image without finite pixels)."""
    v = np.asarray(db, np.float64)
    v = v[np.isfinite(v)]
    if not v.size:
        return -30.0, 0.0
    lo, hi = (float(x) for x in np.percentile(v, [low_pct, high_pct]))
    return min(lo, hi - 10.0), hi


def amplitude_db(image: np.ndarray, floor_db: float | None = -300.0) -> np.ndarray:
    """20*log10|image| (float32, computed in float64): zero amplitude gives ``floor_db``, or NaN (no
    signal) with ``floor_db=None``; NaN stays NaN."""
    from sarcli.io.decibels import magnitude_db

    a = np.asarray(image)
    if np.iscomplexobj(a):
        a = np.abs(a)
    elif a.dtype not in (np.float32, np.float64):
        a = a.astype(np.float64)
    flat = np.ascontiguousarray(a).reshape(-1)
    floor = -300.0 if floor_db is None else float(floor_db)
    return magnitude_db(flat, floor, floor_db is not None).reshape(a.shape)


def write_quicklook(
    path: str | os.PathLike,
    image: np.ndarray,
    title: str = "",
    dynamic_range_db: float = 40.0,
    cmap: str = "gray",
    is_db: bool = False,
    vmin: float | None = None,
    vmax: float | None = None,
    extent: Sequence[float] | None = None,
    xlabel: str = "",
    ylabel: str = "",
    colorbar_label: str = "",
    aspect: str | float = "auto",
    decorate: Callable[[Any], None] | None = None,
) -> None:
    """A PNG for people: amplitude in dB (or the values as given, e.g. phase with a cyclic cmap).
    ``decorate(ax)``: the caller's additions to the axes (tick formats, marks) before the layout."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if np.iscomplexobj(image) or not is_db and cmap == "gray":
        data = amplitude_db(image)
        finite = data[np.isfinite(data)]
        # white at the 99.9th percentile (scenes), but never more than 20 dB under the peak: on a point
        # scene the percentile sits in the sidelobes/quantization floor and would paint it as white as
        # the targets
        top = max(float(np.percentile(finite, 99.9)), float(finite.max()) - 20.0) if finite.size else 0.0
        vmax = top if vmax is None else vmax
        vmin = vmax - dynamic_range_db if vmin is None else vmin
        colorbar_label = colorbar_label or "amplitude (dB)"
    else:
        data = np.asarray(image, dtype=np.float32)
    fig, ax = plt.subplots(figsize=(8, 6), dpi=100)
    im = ax.imshow(data, cmap=cmap, vmin=vmin, vmax=vmax, extent=extent, aspect=aspect,
                   interpolation="nearest", origin="upper")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    fig.colorbar(im, ax=ax, label=colorbar_label)
    if decorate is not None:
        decorate(ax)
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


def phase_rgb(phase: np.ndarray, brightness: np.ndarray) -> np.ndarray:
    """RGBA (float, [0, 1]) of a phase picture: hue = phase (once round the colour wheel over 2 pi: cyan
    at 0, red at +-pi, as matplotlib's ``hsv`` map over [-pi, pi]), full saturation, value =
    ``brightness`` clipped to [0, 1]; NaN in either is transparent."""
    from matplotlib.colors import hsv_to_rgb

    ph = np.asarray(phase, np.float64)
    br = np.asarray(brightness, np.float64)
    ok = np.isfinite(ph) & np.isfinite(br)
    hsv = np.stack([np.mod(np.where(ok, ph, 0.0) + np.pi, 2 * np.pi) / (2 * np.pi), np.ones_like(ph),
                    np.clip(np.where(ok, br, 0.0), 0.0, 1.0)], axis=-1)
    return np.concatenate([hsv_to_rgb(hsv), ok[..., None].astype(np.float64)], axis=-1)


def write_phase_picture(path: str | os.PathLike, phase: np.ndarray, brightness: np.ndarray, title: str = "",
                        brightness_label: str = "coherence", extent: Sequence[float] | None = None,
                        xlabel: str = "", ylabel: str = "", aspect: str | float = "auto") -> None:
    """A PNG of a phase (rad) with hue = phase and brightness = ``brightness`` in [0, 1] (coherence, or
    a normalised amplitude): :func:`phase_rgb`, a cyclic hue bar for the phase, the brightness named."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    fig, ax = plt.subplots(figsize=(8, 6), dpi=100)
    ax.imshow(phase_rgb(phase, brightness), extent=extent, aspect=aspect, interpolation="nearest", origin="upper")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    sm = ScalarMappable(Normalize(-np.pi, np.pi), cmap="hsv")
    cb = fig.colorbar(sm, ax=ax, label=f"phase (rad); brightness: {brightness_label} (dark = 0)")
    cb.set_ticks([-np.pi, -np.pi / 2, 0, np.pi / 2, np.pi], labels=["-π", "-π/2", "0", "π/2", "π"])
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
