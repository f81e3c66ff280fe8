"""Workflow ``info``: describe any input without writing anything.

- a sarcli product (HDF5 with ``product_type``): provenance, attributes and datasets of every product,
  and for raw products their radar, time span and orbit, for SLCs their shape, spacings, algorithm and
  time/range span, for GB-SAR scans their polarizations, stops, sweep and status;
- a GeoTIFF: size, bands (type, unit, description, tags), CRS, bounds, resolution, nodata, ground
  control points, overviews, the dataset tags (sarcli's provenance);
- a raw input that a sensor reader recognises (a CEOS scene folder, a MATLAB block, ...): it is read
  and summarized like a raw product (nothing is written);
- anything else: one line saying what it is not.

The JSON keys of each kind are pinned by tests (``docs/ingest.md`` lists them).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError, MissingFileError, ProductError
from sarcli.workflows import base

_log = logging.getLogger(__name__)

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
TIFF_SIGNATURES = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")  # classic and BigTIFF, both byte orders


@dataclass(frozen=True)
class Config:
    """sources: a product, a GeoTIFF, or a raw input (one or more paths, as for ``ingest``); format and
    options: the sensor reader and its options, for raw inputs (default: found by sniffing)."""

    sources: tuple[Path, ...]
    format: str | None = None
    options: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.sources:
            raise ConfigError("give the file (or the raw input's files) to describe")


@dataclass
class Report(base.Report):
    """summary: the description (keys by kind, module docstring); for a raw input holding several data
    sets, ``{"file", "product_type": "raw input", "format", "products": [...]}``."""

    summary: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.summary)

    def lines(self) -> list[str]:
        s = self.summary
        if s.get("product_type") == "geotiff":
            return _geotiff_lines(s)
        if s.get("product_type") == "nisar_rslc" and "frequencies" in s:
            layers = "; ".join(f"{k}: {', '.join(v)}" for k, v in s["frequencies"].items())
            return [f"{s['file']}: NISAR RSLC ({s['band']}-band, mission {s['mission_id']}), image {s['shape'][0]} x "
                    f"{s['shape'][1]}; layers {layers}"]
        if "products" in s:
            out = [f"{s['file']}: raw input ({s['format']}), {len(s['products'])} data sets"]
            for p in s["products"]:
                out += ["  " + ln for ln in _product_lines(p)]
            return out
        return _product_lines(s)


def _head(path: Path, n: int = 8) -> bytes:
    with open(path, "rb") as f:
        return f.read(n)


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Describe the sources (module docstring)."""
    with base.using(provenance):
        sources = tuple(Path(s) for s in config.sources)
        for s in sources:
            if not s.exists():
                raise MissingFileError(f"{s}: no such file")
        one = sources[0]
        if len(sources) == 1 and config.format is None and one.is_file():
            head = _head(one)
            if head.startswith(TIFF_SIGNATURES):
                _log.info("%s: a TIFF file, described with rasterio", one)
                return Report(describe_geotiff(one))
            if head.startswith(HDF5_SIGNATURE) and _is_product(one):
                _log.info("%s: a sarcli product", one)
                return Report(summarize(one))
            if head.startswith(HDF5_SIGNATURE) and _is_rslc(one):
                _log.info("%s: a NISAR RSLC (not written by sarcli)", one)
                return Report(describe_rslc(one))
        _log.info("%s: not a product or a GeoTIFF; asking the sensor readers", " ".join(map(str, sources)))
        return Report(describe_raw_input(sources, config.format, config.options))


# ---------------------------------------------------------------------------------------------------------
# sarcli products


def _is_product(path: Path) -> bool:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return "product_type" in f.attrs
    except OSError:  # not HDF5 at all
        return False
    except Exception:  # an HDF5 file the library chokes on: open_product gives the one-line reason
        return True


def _is_rslc(path: Path) -> bool:
    from sarcli.io.nisar.rslc import sniff_rslc

    return sniff_rslc(path)


def describe_rslc(path: Path) -> dict[str, Any]:
    """A NISAR RSLC as ISCE3 (or another NISAR tool) writes it: band, layers, image shape, mission."""
    from sarcli.io.nisar.rslc import rslc_contents

    c = rslc_contents(path)
    return {"file": str(path), "product_type": "nisar_rslc", "band": c.band,
            "frequencies": {f"frequency{k}": v for k, v in c.frequencies.items()}, "shape": list(c.shape),
            "mission_id": c.mission_id, "written_by_sarcli": c.written_by_sarcli}


def _text(v: Any) -> Any:
    """An attribute value for the summary: text decoded (invalid UTF-8 replaced), arrays as lists."""
    if isinstance(v, bytes):
        return v.decode(errors="replace")
    if hasattr(v, "dtype") and v.dtype.kind == "S":
        return v.astype(str).tolist()
    if hasattr(v, "tolist"):
        return v.tolist()
    return v


def _attrs(obj) -> dict[str, Any]:
    """Every attribute of an HDF5 object, names and text decoded (a name that is not UTF-8 is shown
    with replacement characters; the product readers have refused anything worse)."""
    names = [k.decode(errors="replace") if isinstance(k, bytes) else str(k) for k in obj.attrs]
    return {k: _text(v) for k, v in sorted(zip(names, obj.attrs.values(), strict=True))}


def _datasets(f) -> list[dict[str, Any]]:
    import h5py

    from sarcli.io.h5common import is_pure_dimension

    found: list[dict[str, Any]] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and not is_pure_dimension(obj):
            units = _text(obj.attrs.get("units", None))
            found.append({"path": "/" + name, "shape": list(obj.shape), "dtype": str(obj.dtype),
                          "units": units if isinstance(units, str) else None})
    f.visititems(visit)
    return found


def _utc(epoch: str | None, seconds: float) -> str | None:
    from orbit.timeutil import add_seconds

    if not epoch:
        return None
    try:
        return add_seconds(epoch, seconds)
    except (ValueError, OverflowError):
        return None


def _span(t, epoch: str | None) -> dict[str, Any]:
    """UTC start/stop and length of a vector of times (s after ``epoch``); {} when empty or not finite."""
    import numpy as np

    t = np.asarray(t)
    if t.size == 0 or t.dtype.kind not in "iuf" or not np.all(np.isfinite(t)):
        return {}
    return {"start_utc": _utc(epoch, float(t.min())), "stop_utc": _utc(epoch, float(t.max())),
            "span_s": float(t.max() - t.min())}


def _slc_summary(path: Path) -> dict[str, Any]:
    """Shape, pixel spacings, algorithm, zero-Doppler time span and slant-range span of an SLC."""
    from sarcli.io.slc import read_slc

    s = read_slc(path, load_image=False)
    span = _span(s.azimuth_time, s.epoch_utc)
    n_lines, n_samples = s.azimuth_time.size, s.slant_range.size
    return {"main_dataset": "/image", "shape": [n_lines, n_samples], "n_lines": n_lines, "n_samples": n_samples,
            "algorithm": s.algorithm, "range_spacing_m": s.range_spacing_m, "azimuth_spacing_m": s.azimuth_spacing_m,
            "prf_hz": s.prf_hz, "first_full_line": s.first_full_line, "last_full_line": s.last_full_line,
            "azimuth_start_utc": span.get("start_utc"), "azimuth_stop_utc": span.get("stop_utc"),
            "azimuth_span_s": span.get("span_s"), "first_range_m": float(s.slant_range[0]),
            "last_range_m": float(s.slant_range[-1])}


def _scan_summary(path: Path) -> dict[str, Any]:
    """Polarizations, stops (complete of planned), frequency sweep, rail extent and status of a scan."""
    from sarcli.io.scan import read_scan

    s = read_scan(path)
    f, x = s.frequency, s.rail_position
    return {"main_dataset": "/s21", "polarizations": list(s.polarizations), "status": s.status,
            "n_stops_complete": s.n_stops, "n_stops_planned": s.n_planned, "n_frequencies": int(f.size),
            "frequency_start_hz": float(f[0]), "frequency_stop_hz": float(f[-1]),
            "frequency_step_hz": float((f[-1] - f[0]) / (f.size - 1)) if f.size > 1 else None,
            "rail_start_m": float(x.min()) if x.size else None, "rail_stop_m": float(x.max()) if x.size else None}


def _validated(path: Path, product_type: str) -> dict[str, Any]:
    """Read the product with its own reader, which validates it (a bad file is one ProductError line),
    and return the type-specific part of the summary (from the validated model, not the file's layout)."""
    if product_type == "raw":
        from sarcli.io.raw import raw_shape, read_raw

        out = raw_model_summary(read_raw(path, load_echo=False), raw_shape(path)[1])
        for key in ("product_type", "attributes"):  # the file's own root attributes are listed already
            out.pop(key)
        return {**out, "main_dataset": "/echo"}
    if product_type == "slc":
        return _slc_summary(path)
    if product_type == "gbsar_scan":
        return _scan_summary(path)
    if product_type == "gbsar_image":
        from sarcli.io.gbsar_image import open_gbsar_image

        with open_gbsar_image(path) as img:
            return {"polarizations": list(img.polarizations), "algorithm": img.algorithm}
    if product_type == "doppler":
        from sarcli.io.doppler_product import read_doppler

        m = read_doppler(path)
        return {"fdc_hz": m.summary.fdc_hz if m.summary else None,
                "ambiguity_resolved": m.ambiguity_resolved}
    readers = {"interferogram": "sarcli.io.interferogram:read_interferogram", "ps": "sarcli.io.interferogram:read_ps",
               "ati": "sarcli.io.ati_product:read_ati"}
    if product_type in readers:
        import importlib

        module, _, name = readers[product_type].partition(":")
        getattr(importlib.import_module(module), name)(path)
    return {}


def summarize(path: Path) -> dict[str, Any]:
    """A JSON-ready summary of any sarcli product (keys in ``docs/ingest.md``), validated by its reader."""
    from sarcli.io.h5common import PROVENANCE_ATTRS, open_product, provenance

    with open_product(path) as f:
        prov = provenance(f)
        attrs = {k: v for k, v in _attrs(f).items() if k not in PROVENANCE_ATTRS}
        datasets = _datasets(f)
        main = max(datasets, key=lambda d: (len(d["shape"]) > 0, math.prod(d["shape"])), default=None)
        epoch = attrs.get("epoch_utc") if isinstance(attrs.get("epoch_utc"), str) else None
        spans = {d["path"]: _span(f[d["path"]][()], epoch) for d in datasets
                 if (d["units"] == "s" or str(d["units"]).startswith("seconds since")) and len(d["shape"]) == 1
                 and "time" in d["path"].rsplit("/", 1)[-1]}
    summary: dict[str, Any] = {
        "file": str(path), "product_type": prov["product_type"], "schema_version": prov["schema_version"],
        "shape": main["shape"] if main else [], "main_dataset": main["path"] if main else None,
        "epoch_utc": epoch, "source": attrs.get("source"), "provenance": prov, "attributes": attrs,
        "datasets": datasets, "time_spans": spans,
    }
    summary.update(_validated(path, str(prov["product_type"])))
    return summary


# ---------------------------------------------------------------------------------------------------------
# raw inputs a sensor reader recognises


def raw_model_summary(raw: Any, n_samples: int | None = None) -> dict[str, Any]:
    """The raw-product keys of :func:`summarize` computed from a :class:`RawProduct` (``n_samples``: the
    line length when the echo was not loaded)."""
    import dataclasses

    from sarcli.model.constants import C_LIGHT

    r = raw.radar
    n_lines = raw.shape[0]
    n_samples = raw.shape[1] if n_samples is None else n_samples
    span = _span(raw.azimuth_time, raw.epoch_utc)
    o = raw.orbit
    ospan = _span(o.time, raw.epoch_utc) if o is not None else {}
    return {
        "product_type": "raw input", "source": raw.source, "epoch_utc": raw.epoch_utc,
        "shape": [n_lines, n_samples], "n_lines": n_lines, "n_samples": n_samples,
        "prf_hz": r.prf_hz, "range_sampling_rate_hz": r.range_sampling_rate_hz, "wavelength_m": r.wavelength_m,
        "carrier_frequency_hz": r.carrier_frequency_hz, "chirp_rate_hz_per_s": r.chirp_rate_hz_per_s,
        "pulse_length_s": r.pulse_length_s, "first_range_m": r.first_range_m,
        "last_range_m": r.first_range_m + (n_samples - 1) * C_LIGHT / (2 * r.range_sampling_rate_hz),
        "quantization_bits": r.quantization_bits,
        "azimuth_start_utc": span.get("start_utc"), "azimuth_stop_utc": span.get("stop_utc"),
        "azimuth_span_s": span.get("span_s"), "n_channels": raw.n_channels,
        "has_replica": raw.replica is not None, "has_agc": raw.agc_db is not None,
        "has_attitude": raw.attitude is not None, "has_truth": raw.truth is not None,
        "n_state_vectors": 0 if o is None else int(o.time.size), "orbit_frame": None if o is None else o.frame,
        "orbit_start_utc": ospan.get("start_utc"), "orbit_stop_utc": ospan.get("stop_utc"),
        "orbit_span_s": ospan.get("span_s"), "look_side": raw.look_side,
        "radar": dataclasses.asdict(r), "attributes": dict(raw.extra_attrs),
    }


def describe_raw_input(sources: tuple[Path, ...], fmt: str | None, options: dict[str, Any]) -> dict[str, Any]:
    """Read the sources with their reader (nothing written) and summarize what it found."""
    from sarcli.io.readers import find_reader
    from sarcli.workflows.ingest import reader_options

    shown = " ".join(map(str, sources))
    try:
        reader = find_reader(sources, fmt)
    except ProductError as e:
        if len(sources) == 1 and "no reader recognises" in str(e):
            raise ProductError(f"{shown}: not a sarcli product, a GeoTIFF, or a raw input a reader recognises "
                               f"(formats: {_formats()})") from None
        raise
    ingested = reader.read(sources, reader_options(reader, options))
    base_keys = {"file": shown, "format": reader.name, "inputs": [str(p) for p in ingested.inputs],
                 "notes": list(ingested.notes)}
    products = []
    for name, raw in ingested.products.items():
        products.append({**base_keys, **({"name": name} if name else {}), **raw_model_summary(raw),
                         **ingested.summaries.get(name, {})})
    if len(products) == 1:
        return products[0]
    return {**base_keys, "product_type": "raw input", "products": products}


def _formats() -> str:
    from sarcli.io.readers import READERS

    return ", ".join(READERS.names())


# ---------------------------------------------------------------------------------------------------------
# GeoTIFF


def describe_geotiff(path: Path) -> dict[str, Any]:
    """Size, bands, CRS, bounds, resolution, nodata, GCPs, overviews and tags of a GeoTIFF (rasterio)."""
    import warnings

    import rasterio
    from rasterio.errors import NotGeoreferencedWarning, RasterioIOError

    try:
        ds = rasterio.open(path)
    except RasterioIOError as e:
        raise ProductError(f"{path}: not a readable GeoTIFF ({' '.join(str(e).split())})") from None
    with ds, warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)  # reported: crs and transform are null
        crs = ds.crs
        gcps, gcp_crs = ds.gcps
        bands = []
        for i in range(1, ds.count + 1):
            bands.append({"band": i, "dtype": ds.dtypes[i - 1], "unit": ds.units[i - 1] or None,
                          "description": ds.descriptions[i - 1], "nodata": ds.nodatavals[i - 1],
                          "scale": ds.scales[i - 1], "offset": ds.offsets[i - 1],
                          "overviews": ds.overviews(i), "tags": ds.tags(i)})
        has_transform = not ds.transform.is_identity
        b = ds.bounds
        out: dict[str, Any] = {
            "file": str(path), "product_type": "geotiff", "driver": ds.driver, "width": ds.width,
            "height": ds.height, "count": ds.count, "shape": [ds.height, ds.width],
            "crs": crs.to_string() if crs else None, "crs_epsg": crs.to_epsg() if crs else None,
            "crs_wkt": crs.to_wkt() if crs else None,
            "transform": list(ds.transform)[:6] if has_transform else None,
            "bounds": {"left": b.left, "bottom": b.bottom, "right": b.right, "top": b.top} if has_transform else None,
            "resolution": list(ds.res) if has_transform else None,
            "nodata": ds.nodata, "bands": bands, "tags": ds.tags(),
            "n_gcps": len(gcps), "gcp_crs": gcp_crs.to_string() if gcp_crs else None,
            "gcp_bounds": _gcp_bounds(gcps), "compression": ds.compression.value if ds.compression else None,
            "tiled": bool(ds.profile.get("tiled", False)), "block_shapes": [list(s) for s in ds.block_shapes],
        }
    return out


def _gcp_bounds(gcps) -> dict[str, float] | None:
    if not gcps:
        return None
    xs, ys = [g.x for g in gcps], [g.y for g in gcps]
    return {"left": min(xs), "bottom": min(ys), "right": max(xs), "top": max(ys)}


# ---------------------------------------------------------------------------------------------------------
# lines for people


def _product_lines(s: dict[str, Any]) -> list[str]:
    out: list[str] = []
    if s["product_type"] == "raw input":
        out.append(f"{s['file']}: raw input ({s['format']}{', ' + s['name'] if s.get('name') else ''}), "
                   f"shape {' x '.join(str(n) for n in s['shape'])}, source {s.get('source')}")
        out += [f"  note: {n}" for n in s["notes"]]
        return out + _raw_lines(s)
    out.append(f"{s['file']}: {s['product_type']} product (schema {s['schema_version']}), "
               f"shape {' x '.join(str(n) for n in s['shape'])} ({s['main_dataset']}), source {s.get('source')}")
    p = s["provenance"]
    out.append(f"  created {p.get('created_utc')} by sarcli {p.get('software_version')}: {p.get('command_line')}")
    for inp in p.get("inputs") or []:
        out.append(f"  input {inp.get('path')} sha256 {str(inp.get('sha256'))[:16]}...")
    if s["product_type"] == "raw":
        return out + _raw_lines(s)
    if s["product_type"] == "slc" and "n_lines" in s:
        out.append(f"  {s['n_lines']} lines x {s['n_samples']} samples, algorithm {s['algorithm']}, "
                   f"spacing range {_fmt(s['range_spacing_m'], '.3f')} m x azimuth "
                   f"{_fmt(s['azimuth_spacing_m'], '.3f')} m, "
                   + _full_lines(s['first_full_line'], s['last_full_line']))
        if s["azimuth_start_utc"]:
            out.append(f"  zero-Doppler time {s['azimuth_start_utc']} .. {s['azimuth_stop_utc']} "
                       f"({s['azimuth_span_s']:.3f} s), slant range {_fmt(s['first_range_m'], '.2f')} .. "
                       f"{_fmt(s['last_range_m'], '.2f')} m")
    elif s["product_type"] == "gbsar_scan" and "n_frequencies" in s:
        out.append(f"  status {s['status']}: {s['n_stops_complete']} of {s['n_stops_planned']} stops, polarizations "
                   f"{', '.join(s['polarizations']) or 'none'}, rail {_fmt(s['rail_start_m'], '.3f')} .. "
                   f"{_fmt(s['rail_stop_m'], '.3f')} m")
        if s["n_frequencies"]:
            out.append(f"  sweep {s['frequency_start_hz'] / 1e9:.6g} .. {s['frequency_stop_hz'] / 1e9:.6g} GHz, "
                       f"{s['n_frequencies']} points" + (f", step {s['frequency_step_hz'] / 1e6:.6g} MHz"
                                                         if s["frequency_step_hz"] else ""))
    for name, span in s["time_spans"].items():
        if span:
            out.append(f"  {name}: {span['start_utc']} .. {span['stop_utc']} ({span['span_s']:.3f} s)")
    for d in s["datasets"]:
        out.append(f"  {d['path']}: {d['dtype']} {d['shape']}" + (f" [{d['units']}]" if d["units"] else ""))
    return out


def _raw_lines(s: dict[str, Any]) -> list[str]:
    out = [f"  azimuth {s['azimuth_start_utc']} .. {s['azimuth_stop_utc']} ({s['azimuth_span_s']:.3f} s), "
           f"PRF {s['prf_hz']:.3f} Hz",
           f"  range {s['first_range_m']:.2f} .. {s['last_range_m']:.2f} m, fs {s['range_sampling_rate_hz'] / 1e6:.6f}"
           f" MHz, wavelength {s['wavelength_m']:.6f} m, chirp {s['chirp_rate_hz_per_s']:.6g} Hz/s, "
           f"pulse {s['pulse_length_s'] * 1e6:.3f} us, {_bits(s['quantization_bits'])}"]
    if s["n_state_vectors"]:
        out.append(f"  orbit: {s['n_state_vectors']} state vectors ({s['orbit_frame']}), "
                   f"{s['orbit_start_utc']} .. {s['orbit_stop_utc']}")
    else:
        out.append("  orbit: none")
    return out


def _geotiff_lines(s: dict[str, Any]) -> list[str]:
    out = [f"{s['file']}: GeoTIFF {s['width']} x {s['height']} pixels, {s['count']} band(s), "
           f"CRS {s['crs'] or 'none'}, nodata {s['nodata']}"]
    if s["bounds"]:
        b = s["bounds"]
        out.append(f"  bounds left {b['left']:.6f} bottom {b['bottom']:.6f} right {b['right']:.6f} top "
                   f"{b['top']:.6f}, pixel {s['resolution'][0]:.6g} x {s['resolution'][1]:.6g}")
    if s["n_gcps"]:
        g = s["gcp_bounds"]
        out.append(f"  {s['n_gcps']} ground control points ({s['gcp_crs']}), x {g['left']:.6f} .. {g['right']:.6f}, "
                   f"y {g['bottom']:.6f} .. {g['top']:.6f}")
    for band in s["bands"]:
        out.append(f"  band {band['band']}: {band['dtype']}, unit {band['unit'] or 'none'}, "
                   f"{band['description'] or 'no description'}, overviews {band['overviews'] or 'none'}")
    for k, v in sorted(s["tags"].items()):
        out.append(f"  tag {k}: {v}")
    return out


def _bits(bits) -> str:
    """Quantization of a raw echo: 0 (or absent) means floating-point samples."""
    return f"{int(bits)}-bit quantized" if bits else "not quantized"


def _full_lines(first: int | None, last: int | None) -> str:
    """The lines focused with the whole synthetic aperture (none when the scene is shorter than one)."""
    if first is None or last is None:
        return "fully focused lines unknown"
    return f"fully focused lines {first}..{last}" if last >= first else "no line has the full aperture"


def _fmt(v, spec: str) -> str:
    return "?" if v is None else format(v, spec)
