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

from sarcli.errors import ConfigError, ProductError
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
                raise ProductError(f"{s}: no such file")
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
    except OSError:
        return False


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


def _attrs(obj) -> dict[str, Any]:
    out = {}
    for k in sorted(obj.attrs):
        v = obj.attrs[k]
        if isinstance(v, bytes):
            v = v.decode(errors="replace")
        elif hasattr(v, "dtype") and v.dtype.kind == "S":
            v = v.astype(str)
        out[k] = v
    return out


def _datasets(f) -> list[dict[str, Any]]:
    import h5py

    from sarcli.io.h5common import is_pure_dimension

    found: list[dict[str, Any]] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and not is_pure_dimension(obj):
            units = obj.attrs.get("units", None)
            if isinstance(units, bytes):
                units = units.decode(errors="replace")
            found.append({"path": "/" + name, "shape": list(obj.shape), "dtype": str(obj.dtype),
                          "units": None if units is None else str(units)})
    f.visititems(visit)
    return found


def _utc(epoch: str | None, seconds: float) -> str | None:
    from orbit.timeutil import add_seconds

    if not epoch:
        return None
    try:
        return add_seconds(epoch, seconds)
    except ValueError:
        return None


def _span(t, epoch: str | None) -> dict[str, Any]:
    """UTC start/stop and length of a vector of times (s after ``epoch``); {} when empty."""
    if t.size == 0:
        return {}
    return {"start_utc": _utc(epoch, float(t.min())), "stop_utc": _utc(epoch, float(t.max())),
            "span_s": float(t.max() - t.min())}


def _time_span(f, name: str, epoch: str | None) -> dict[str, Any]:
    return _span(f[name][()], epoch)


def _raw_summary(f, summary: dict[str, Any]) -> None:
    from sarcli.model.constants import C_LIGHT

    radar = _attrs(f["radar"]) if "radar" in f else {}
    epoch = summary.get("epoch_utc")
    n_lines, n_samples = f["echo"].shape
    span = _time_span(f, "azimuth_time", epoch) if "azimuth_time" in f else {}
    fs = radar.get("range_sampling_rate_hz")
    r0 = radar.get("first_range_m")
    summary.update({
        "shape": [n_lines, n_samples], "n_lines": n_lines, "n_samples": n_samples,
        "prf_hz": radar.get("prf_hz"), "range_sampling_rate_hz": fs,
        "wavelength_m": radar.get("wavelength_m"), "carrier_frequency_hz": radar.get("carrier_frequency_hz"),
        "chirp_rate_hz_per_s": radar.get("chirp_rate_hz_per_s"), "pulse_length_s": radar.get("pulse_length_s"),
        "first_range_m": r0,
        "last_range_m": (r0 + (n_samples - 1) * C_LIGHT / (2 * fs)) if (r0 and fs) else None,
        "quantization_bits": radar.get("quantization_bits"),
        "azimuth_start_utc": span.get("start_utc"), "azimuth_stop_utc": span.get("stop_utc"),
        "azimuth_span_s": span.get("span_s"),
        "n_channels": summary.get("attributes", {}).get("n_channels", 1),
        "has_replica": "replica" in f.get("radar", {}), "has_agc": "agc_db" in f.get("radar", {}),
        "has_attitude": "attitude" in f, "has_truth": "truth" in f,
        "radar": radar,
    })
    if "orbit" in f:
        o = f["orbit"]
        frame = o.attrs.get("frame", None)
        ospan = _time_span(o, "time", epoch)
        summary.update({"n_state_vectors": int(o["time"].shape[0]),
                        "orbit_frame": frame.decode() if isinstance(frame, bytes) else frame,
                        "orbit_start_utc": ospan.get("start_utc"), "orbit_stop_utc": ospan.get("stop_utc"),
                        "orbit_span_s": ospan.get("span_s")})
    else:
        summary.update({"n_state_vectors": 0, "orbit_frame": None, "orbit_start_utc": None,
                        "orbit_stop_utc": None, "orbit_span_s": None})


def _slc_summary(f, summary: dict[str, Any]) -> None:
    """Shape, pixel spacings, algorithm, zero-Doppler time span and slant-range span of an SLC."""
    a = summary["attributes"]
    n_lines, n_samples = f["image"].shape
    rng = f["slant_range"][()] if "slant_range" in f else None
    span = _time_span(f, "azimuth_time", summary.get("epoch_utc")) if "azimuth_time" in f else {}
    summary.update({
        "main_dataset": "/image", "shape": [n_lines, n_samples], "n_lines": n_lines, "n_samples": n_samples,
        "algorithm": a.get("algorithm"), "range_spacing_m": _num(a.get("range_spacing_m")),
        "azimuth_spacing_m": _num(a.get("azimuth_spacing_m")), "prf_hz": _num(a.get("prf_hz")),
        "first_full_line": _int(a.get("first_full_line")), "last_full_line": _int(a.get("last_full_line")),
        "azimuth_start_utc": span.get("start_utc"), "azimuth_stop_utc": span.get("stop_utc"),
        "azimuth_span_s": span.get("span_s"),
        "first_range_m": float(rng[0]) if rng is not None and rng.size else None,
        "last_range_m": float(rng[-1]) if rng is not None and rng.size else None,
    })


def _scan_summary(f, summary: dict[str, Any]) -> None:
    """Polarizations, stops (complete of planned), frequency sweep, rail extent and status of a scan."""
    a = summary["attributes"]
    freq = f["frequency"][()] if "frequency" in f else None
    x = f["rail_position"][()] if "rail_position" in f else None
    pols = a.get("polarizations")
    summary.update({
        "main_dataset": "/s21", "polarizations": pols.split(",") if isinstance(pols, str) and pols else [],
        "status": a.get("status"), "n_stops_complete": _int(a.get("n_complete")),
        "n_stops_planned": _int(a.get("n_planned")),
        "n_frequencies": int(freq.size) if freq is not None else 0,
        "frequency_start_hz": float(freq.min()) if freq is not None and freq.size else None,
        "frequency_stop_hz": float(freq.max()) if freq is not None and freq.size else None,
        "frequency_step_hz": float((freq[-1] - freq[0]) / (freq.size - 1)) if freq is not None and freq.size > 1
        else None,
        "rail_start_m": float(x.min()) if x is not None and x.size else None,
        "rail_stop_m": float(x.max()) if x is not None and x.size else None,
    })


def _num(v) -> float | None:
    return None if v is None else float(v)


def _int(v) -> int | None:
    return None if v is None else int(v)


def summarize(path: Path) -> dict[str, Any]:
    """A JSON-ready summary of any sarcli product (keys in ``docs/ingest.md``)."""
    from sarcli.io.h5common import PROVENANCE_ATTRS, open_product, provenance

    with open_product(path) as f:
        prov = provenance(f)
        attrs = {k: v for k, v in _attrs(f).items() if k not in PROVENANCE_ATTRS}
        datasets = _datasets(f)
        main = max(datasets, key=lambda d: (len(d["shape"]) > 0, math.prod(d["shape"])),
                   default=None)
        summary: dict[str, Any] = {
            "file": str(path), "product_type": prov["product_type"], "schema_version": prov["schema_version"],
            "shape": main["shape"] if main else [], "main_dataset": main["path"] if main else None,
            "epoch_utc": attrs.get("epoch_utc"), "source": attrs.get("source"),
            "provenance": prov, "attributes": attrs, "datasets": datasets,
        }
        summary["time_spans"] = {
            d["path"]: _time_span(f, d["path"], summary["epoch_utc"]) for d in datasets
            if (d["units"] == "s" or str(d["units"]).startswith("seconds since")) and len(d["shape"]) == 1
            and "time" in d["path"].rsplit("/", 1)[-1]}
        if prov["product_type"] == "raw" and "echo" in f:
            summary["main_dataset"] = "/echo"
            _raw_summary(f, summary)
        elif prov["product_type"] == "slc" and "image" in f:
            _slc_summary(f, summary)
        elif prov["product_type"] == "gbsar_scan" and "s21" in f:
            _scan_summary(f, summary)
    return summary


# ---------------------------------------------------------------------------------------------------------
# raw inputs a sensor reader recognises


def raw_model_summary(raw: Any) -> dict[str, Any]:
    """The raw-product keys of :func:`summarize` computed from an in-memory :class:`RawProduct`."""
    import dataclasses

    r = raw.radar
    n_lines, n_samples = raw.shape
    span = _span(raw.azimuth_time, raw.epoch_utc)
    o = raw.orbit
    ospan = _span(o.time, raw.epoch_utc) if o is not None else {}
    return {
        "product_type": "raw input", "source": raw.source, "epoch_utc": raw.epoch_utc,
        "shape": [n_lines, n_samples], "n_lines": n_lines, "n_samples": n_samples,
        "prf_hz": r.prf_hz, "range_sampling_rate_hz": r.range_sampling_rate_hz, "wavelength_m": r.wavelength_m,
        "carrier_frequency_hz": r.carrier_frequency_hz, "chirp_rate_hz_per_s": r.chirp_rate_hz_per_s,
        "pulse_length_s": r.pulse_length_s, "first_range_m": r.first_range_m,
        "last_range_m": float(raw.slant_range()[-1]), "quantization_bits": r.quantization_bits,
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
