"""``sarcli info``: summarize any sarcli product (raw, SLC and scan in detail, every type generically)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import typer

from sarcli.cli.common import emit_json
from sarcli.cli.common import report as say


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

    found: list[dict[str, Any]] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            found.append({"path": "/" + name, "shape": list(obj.shape), "dtype": str(obj.dtype),
                          "units": obj.attrs.get("units", None)})
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


def _time_span(f, name: str, epoch: str | None) -> dict[str, Any]:
    t = f[name][()]
    if t.size == 0:
        return {}
    return {"start_utc": _utc(epoch, float(t.min())), "stop_utc": _utc(epoch, float(t.max())),
            "span_s": float(t.max() - t.min())}


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
    """A JSON-ready summary of any sarcli product (keys documented in the README, section Ingest)."""
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
            if d["units"] == "s" and len(d["shape"]) == 1 and "time" in d["path"].rsplit("/", 1)[-1]}
        if prov["product_type"] == "raw" and "echo" in f:
            summary["main_dataset"] = "/echo"
            _raw_summary(f, summary)
        elif prov["product_type"] == "slc" and "image" in f:
            _slc_summary(f, summary)
        elif prov["product_type"] == "gbsar_scan" and "s21" in f:
            _scan_summary(f, summary)
    return summary


def _human(s: dict[str, Any]) -> None:
    say(f"{s['file']}: {s['product_type']} product (schema {s['schema_version']}), "
        f"shape {' x '.join(str(n) for n in s['shape'])} ({s['main_dataset']}), source {s.get('source')}")
    p = s["provenance"]
    say(f"  created {p.get('created_utc')} by sarcli {p.get('software_version')}: {p.get('command_line')}")
    for inp in p.get("inputs") or []:
        say(f"  input {inp.get('path')} sha256 {str(inp.get('sha256'))[:16]}...")
    if s["product_type"] == "raw":
        say(f"  azimuth {s['azimuth_start_utc']} .. {s['azimuth_stop_utc']} ({s['azimuth_span_s']:.3f} s), "
            f"PRF {s['prf_hz']:.3f} Hz")
        say(f"  range {s['first_range_m']:.2f} .. {s['last_range_m']:.2f} m, fs {s['range_sampling_rate_hz'] / 1e6:.6f}"
            f" MHz, wavelength {s['wavelength_m']:.6f} m, chirp {s['chirp_rate_hz_per_s']:.6g} Hz/s, "
            f"pulse {s['pulse_length_s'] * 1e6:.3f} us, {_bits(s['quantization_bits'])}")
        if s["n_state_vectors"]:
            say(f"  orbit: {s['n_state_vectors']} state vectors ({s['orbit_frame']}), "
                f"{s['orbit_start_utc']} .. {s['orbit_stop_utc']}")
        else:
            say("  orbit: none")
        return
    if s["product_type"] == "slc" and "n_lines" in s:
        say(f"  {s['n_lines']} lines x {s['n_samples']} samples, algorithm {s['algorithm']}, "
            f"spacing range {_fmt(s['range_spacing_m'], '.3f')} m x azimuth {_fmt(s['azimuth_spacing_m'], '.3f')} m, "
            + _full_lines(s['first_full_line'], s['last_full_line']))
        if s["azimuth_start_utc"]:
            say(f"  zero-Doppler time {s['azimuth_start_utc']} .. {s['azimuth_stop_utc']} "
                f"({s['azimuth_span_s']:.3f} s), slant range {_fmt(s['first_range_m'], '.2f')} .. "
                f"{_fmt(s['last_range_m'], '.2f')} m")
    elif s["product_type"] == "gbsar_scan" and "n_frequencies" in s:
        say(f"  status {s['status']}: {s['n_stops_complete']} of {s['n_stops_planned']} stops, polarizations "
            f"{', '.join(s['polarizations']) or 'none'}, rail {_fmt(s['rail_start_m'], '.3f')} .. "
            f"{_fmt(s['rail_stop_m'], '.3f')} m")
        if s["n_frequencies"]:
            say(f"  sweep {s['frequency_start_hz'] / 1e9:.6g} .. {s['frequency_stop_hz'] / 1e9:.6g} GHz, "
                f"{s['n_frequencies']} points" + (f", step {s['frequency_step_hz'] / 1e6:.6g} MHz"
                                                  if s["frequency_step_hz"] else ""))
    for name, span in s["time_spans"].items():
        if span:
            say(f"  {name}: {span['start_utc']} .. {span['stop_utc']} ({span['span_s']:.3f} s)")
    for d in s["datasets"]:
        say(f"  {d['path']}: {d['dtype']} {d['shape']}" + (f" [{d['units']}]" if d["units"] else ""))


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


def info(
    path: Path = typer.Argument(..., help="Any sarcli product (HDF5)."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object on stdout."),
) -> None:
    """Summarize a product: type, shape, time span, radar parameters, orbit, provenance.

    Raw products get their radar and orbit summary, SLCs their shape, pixel spacings, algorithm and
    time/range span, GB-SAR scans their polarizations, stops, sweep and status; every product also a
    generic summary of its provenance, attributes and datasets.

    Examples:

      sarcli info raw.h5

      sarcli info raw.h5 --json
    """
    s = summarize(path)
    if as_json:
        emit_json(s)
    else:
        _human(s)


def register(app: typer.Typer) -> None:
    app.command("info")(info)
