"""GB-SAR interferometry products.

``gbsar_interferogram`` (schema 2; schema 1 had no unwrapping: its ``value`` came from the WRAPPED residual)::

    /                 provenance, mode, pol, value_name, value_unit, rate (JSON), rail heights, frequencies
    /phase            float32 (n_range, n_azimuth) rad, raw phase of B * conj(A)
    /coherence        float32, boxcar sample coherence (window in the attributes)
    /model_phase      float32 rad, flat-surface model phase of the mode
    /residual_phase   float32 rad, wrapped phase after removing the model (NaN where undefined)
    /unwrapped_phase  float32 rad, residual unwrapped spatially (root attr ``unwrap_method``: SNAPHU),
                      NaN outside its connected components
    /connected_component  int32, SNAPHU's connected component of each pixel (0: none)
    /value            float32, converted unwrapped residual: LOS displacement (mm) | height (m) | range
                      offset (m), NaN where the coherence is below the ``min_coherence`` attribute
    phase, coherence, residual_phase and value are NaN outside the common support of the two images
    (outside the beam footprint or not covered by the focusing algorithm).
    /range, /azimuth  float64 axes (m), as the input images

``gbsar_ps`` (schema 1), temporal coherence and persistent scatterers::

    /coherence        float32 (n_range, n_azimuth) temporal coherence |sum z_i| / sum |z_i|, NaN outside
                      the common support of the images (as in the interferogram)
    /time_s           float64 (n_scans,) mean scan time after the reference scan's epoch
    /ps/row, /ps/col  int64 (n_ps,) pixel indices; /ps/range, /ps/azimuth (m); /ps/coherence
    /ps/phase         float32 (n_ps, n_scans) rad relative to the first scan
    /ps/displacement_mm  float32 (n_ps, n_scans) LOS displacement (+ = away from the radar)
"""

from __future__ import annotations

import json
import os
from typing import Any

import h5py
import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import (
    atomic_h5,
    attr_json,
    attr_number,
    attr_str,
    coordinate,
    dataset,
    group,
    open_product,
    read_array,
)
from sarcli.model import checks as ck

IFG_TYPE, PS_TYPE, SCHEMA_VERSION = "gbsar_interferogram", "gbsar_ps", "1"
IFG_SCHEMA_VERSION = "2"


_IFG_DESCRIPTIONS = {
    "phase": "raw interferometric phase arg(B conj(A))", "coherence": "boxcar sample coherence",
    "model_phase": "flat-surface model phase of the mode", "residual_phase": "phase minus the model, wrapped",
    "unwrapped_phase": "residual phase unwrapped spatially (SNAPHU), NaN outside its connected components",
    "connected_component": "SNAPHU connected component of each pixel (0: none)"}


def _write_axes(f, range_m: np.ndarray, azimuth_m: np.ndarray):
    return (coordinate(f, "range", np.asarray(range_m, np.float64), "m", "R0, distance from the rail line"),
            coordinate(f, "azimuth", np.asarray(azimuth_m, np.float64), "m", "x along the rail"))


def write_interferogram(path: str | os.PathLike, ifg, range_m: np.ndarray, azimuth_m: np.ndarray, attrs: dict,
                        parameters: dict | None = None, inputs: tuple = ()) -> None:
    with atomic_h5(path, IFG_TYPE, IFG_SCHEMA_VERSION, parameters, inputs) as f:
        for k, v in attrs.items():
            f.attrs[k] = v
        f.attrs["value_name"] = ifg.value_name
        f.attrs["value_unit"] = ifg.value_unit
        f.attrs["rate"] = json.dumps(ifg.rate, default=float)
        f.attrs["unwrap_method"] = ifg.unwrap_method
        dims = _write_axes(f, range_m, azimuth_m)
        for name, arr, unit in (("phase", ifg.phase, "rad"), ("coherence", ifg.coherence, "1"),
                                ("model_phase", ifg.model_phase, "rad"), ("residual_phase", ifg.residual, "rad"),
                                ("unwrapped_phase", ifg.unwrapped, "rad")):
            dataset(f, name, np.asarray(arr, np.float32), units=unit, compression="gzip",
                    description=_IFG_DESCRIPTIONS[name], dims=dims)
        dataset(f, "connected_component", np.asarray(ifg.component, np.int32), units="1", compression="gzip",
                description=_IFG_DESCRIPTIONS["connected_component"], dims=dims)
        dataset(f, "value", np.asarray(ifg.value, np.float32), units=ifg.value_unit, compression="gzip",
                description=f"{ifg.value_name.replace('_', ' ')} from the unwrapped residual, NaN below min_coherence",
                dims=dims)


def _root_attrs(f: h5py.File) -> dict[str, Any]:
    """Root attributes: text checked as UTF-8, numeric scalars as finite numbers, numeric arrays as they are."""
    out: dict[str, Any] = {}
    for k in f.attrs:
        v = f.attrs[k]
        if isinstance(v, str | bytes | np.bytes_):
            out[k] = attr_str(f, k)
        elif isinstance(v, np.ndarray) and v.ndim > 0:
            out[k] = ck.array(f"{f.filename}", k, v, "fiu", finite=False)
        else:
            out[k] = attr_number(f, k)
    return out


def _axes(f: h5py.File, path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    r = read_array(f, "range", "f", ndim=1, min_size=1)
    x = read_array(f, "azimuth", "f", ndim=1, min_size=1)
    ck.increasing(str(path), "range", r)
    ck.increasing(str(path), "azimuth", x)
    return r, x


def read_interferogram(path: str | os.PathLike) -> dict:
    """All datasets and attributes of an interferogram product as a dict of arrays / values; checked:
    five float (n_range, n_azimuth) layers on finite increasing axes (NaN marks no support, as
    documented), coherence within [0, 1], typed attributes, ``rate`` a JSON object."""
    with open_product(path, IFG_TYPE) as f:
        r, x = _axes(f, path)
        out: dict[str, Any] = {"range": r, "azimuth": x}
        for k in ("phase", "coherence", "model_phase", "residual_phase", "value"):
            out[k] = read_array(f, k, "f", shape=(r.size, x.size), finite=False)
        _unit_interval(path, "coherence", out["coherence"])
        out.update(_root_attrs(f))
        out["rate"] = attr_json(f, "rate", kind=dict)
        for k in ("value_name", "value_unit"):
            out[k] = attr_str(f, k) or ""
    return out


def _unit_interval(path: str | os.PathLike, name: str, a: np.ndarray) -> None:
    fin = a[np.isfinite(a)]
    if fin.size and (fin.min() < -1e-6 or fin.max() > 1 + 1e-6):
        raise ProductError(f"{path}: {name} must lie within [0, 1]")


def write_ps(path: str | os.PathLike, coherence: np.ndarray, time_s: np.ndarray, rows: np.ndarray, cols: np.ndarray,
             range_m: np.ndarray, azimuth_m: np.ndarray, phase: np.ndarray, displacement_mm: np.ndarray, attrs: dict,
             parameters: dict | None = None, inputs: tuple = ()) -> None:
    with atomic_h5(path, PS_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        for k, v in attrs.items():
            f.attrs[k] = v
        rg, az = _write_axes(f, range_m, azimuth_m)
        dataset(f, "coherence", np.asarray(coherence, np.float32), units="1", compression="gzip",
                description="temporal coherence |sum z_i| / sum |z_i|", dims=(rg, az))
        ts = coordinate(f, "time_s", np.asarray(time_s, np.float64), "s", "mean scan time after the reference "
                        "scan's epoch")
        sc = coordinate(f, "scatterer", np.arange(len(rows), dtype=np.int64), "1", "persistent scatterer index")
        g = group(f, "ps")
        g.attrs["description"] = "persistent scatterers: one row per scatterer"
        for name, arr, unit, desc in (
                ("row", np.asarray(rows, np.int64), "1", "pixel row"), ("col", np.asarray(cols, np.int64), "1",
                                                                       "pixel column"),
                ("range", np.asarray(range_m[rows], np.float64), "m", "R0 of the scatterer"),
                ("azimuth", np.asarray(azimuth_m[cols], np.float64), "m", "x of the scatterer"),
                ("coherence", np.asarray(coherence[rows, cols], np.float32), "1", "temporal coherence")):
            dataset(g, name, arr, units=unit, description=desc, dims=(sc,))
        dataset(g, "phase", np.asarray(phase, np.float32), units="rad", description="phase relative to the first "
                "scan", dims=(sc, ts))
        dataset(g, "displacement_mm", np.asarray(displacement_mm, np.float32), units="mm",
                description="LOS displacement (+ away from the radar)", dims=(sc, ts))


def read_ps(path: str | os.PathLike) -> dict:
    """The temporal-coherence / persistent-scatterer product as a dict (``ps_<name>`` for /ps datasets);
    checked: coherence (n_range, n_azimuth) within [0, 1] where defined, finite increasing axes and
    times, PS pixel indices inside the grid, one phase and displacement per PS and scan."""
    with open_product(path, PS_TYPE) as f:
        r, x = _axes(f, path)
        out: dict[str, Any] = {"range": r, "azimuth": x}
        out["coherence"] = read_array(f, "coherence", "f", shape=(r.size, x.size), finite=False)
        _unit_interval(path, "coherence", out["coherence"])
        out["time_s"] = read_array(f, "time_s", "f", ndim=1, min_size=1)
        if "ps" not in f or not isinstance(f["ps"], h5py.Group):
            raise ProductError(f"{path}: malformed product, missing group 'ps'")
        g = f["ps"]
        rows = read_array(g, "row", "iu", ndim=1)
        n_ps, n_t = rows.size, out["time_s"].size
        cols = read_array(g, "col", "iu", shape=(n_ps,))
        if n_ps and (rows.min() < 0 or rows.max() >= r.size or cols.min() < 0 or cols.max() >= x.size):
            raise ProductError(f"{path}: ps/row or ps/col outside the {r.size} x {x.size} grid")
        out.update({"ps_row": rows, "ps_col": cols})
        for k in ("range", "azimuth", "coherence"):
            out[f"ps_{k}"] = read_array(g, k, "f", shape=(n_ps,))
        for k in ("phase", "displacement_mm"):
            out[f"ps_{k}"] = read_array(g, k, "f", shape=(n_ps, n_t))
    return out
