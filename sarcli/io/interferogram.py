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

import numpy as np

from sarcli.io.h5common import atomic_h5, attr_str, coordinate, dataset, group, open_product, require

IFG_TYPE, PS_TYPE, SCHEMA_VERSION = "gbsar_interferogram", "gbsar_ps", "1"
IFG_SCHEMA_VERSION = "2"


_IFG_DESCRIPTIONS = {
    "phase": "raw interferometric phase arg(B conj(A))", "coherence": "boxcar sample coherence",
    "model_phase": "flat-surface model phase of the mode", "residual_phase": "phase minus the model, wrapped",
    "unwrapped_phase": "residual phase unwrapped spatially (SNAPHU), NaN outside its connected components",
    "connected_component": "SNAPHU connected component of each pixel (0: none)"}


def _axes(f, range_m: np.ndarray, azimuth_m: np.ndarray):
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
        dims = _axes(f, range_m, azimuth_m)
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


def read_interferogram(path: str | os.PathLike) -> dict:
    """All datasets and attributes of an interferogram product as a dict of arrays / values."""
    with open_product(path, IFG_TYPE) as f:
        out = {k: require(f, k, path)[()] for k in ("phase", "coherence", "model_phase", "residual_phase", "value",
                                                     "range", "azimuth")}
        out.update({k: attr_str(f, k) if isinstance(f.attrs[k], str | bytes) else f.attrs[k] for k in f.attrs})
    out["rate"] = json.loads(out["rate"])
    return out


def write_ps(path: str | os.PathLike, coherence: np.ndarray, time_s: np.ndarray, rows: np.ndarray, cols: np.ndarray,
             range_m: np.ndarray, azimuth_m: np.ndarray, phase: np.ndarray, displacement_mm: np.ndarray, attrs: dict,
             parameters: dict | None = None, inputs: tuple = ()) -> None:
    with atomic_h5(path, PS_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        for k, v in attrs.items():
            f.attrs[k] = v
        rg, az = _axes(f, range_m, azimuth_m)
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
    with open_product(path, PS_TYPE) as f:
        out = {k: require(f, k, path)[()] for k in ("coherence", "time_s", "range", "azimuth")}
        out.update({f"ps_{k}": f["ps"][k][()] for k in f["ps"]})
    return out
