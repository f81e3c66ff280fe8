"""GB-SAR interferometry products.

``gbsar_interferogram`` (schema 1)::

    /                 provenance, mode, pol, value_name, value_unit, rate (JSON), rail heights, frequencies
    /phase            float32 (n_range, n_azimuth) rad, raw phase of B * conj(A)
    /coherence        float32, boxcar sample coherence (window in the attributes)
    /model_phase      float32 rad, flat-surface model phase of the mode
    /residual_phase   float32 rad, wrapped phase after removing the model (NaN where undefined)
    /value            float32, converted residual: LOS displacement (mm) | height (m) | range offset (m),
                      NaN where the coherence is below the ``min_coherence`` attribute
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

from sarcli.io.h5common import atomic_h5, attr_str, dataset, group, open_product, require

IFG_TYPE, PS_TYPE, SCHEMA_VERSION = "gbsar_interferogram", "gbsar_ps", "1"


def write_interferogram(path: str | os.PathLike, ifg, range_m: np.ndarray, azimuth_m: np.ndarray, attrs: dict,
                        parameters: dict | None = None, inputs: tuple = ()) -> None:
    with atomic_h5(path, IFG_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        for k, v in attrs.items():
            f.attrs[k] = v
        f.attrs["value_name"] = ifg.value_name
        f.attrs["value_unit"] = ifg.value_unit
        f.attrs["rate"] = json.dumps(ifg.rate, default=float)
        for name, arr, unit in (("phase", ifg.phase, "rad"), ("coherence", ifg.coherence, "1"),
                                ("model_phase", ifg.model_phase, "rad"), ("residual_phase", ifg.residual, "rad"),
                                ("value", ifg.value, ifg.value_unit)):
            dataset(f, name, np.asarray(arr, np.float32), units=unit, compression="gzip")
        dataset(f, "range", np.asarray(range_m, np.float64), units="m")
        dataset(f, "azimuth", np.asarray(azimuth_m, np.float64), units="m")


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
        dataset(f, "coherence", np.asarray(coherence, np.float32), units="1", compression="gzip")
        dataset(f, "time_s", np.asarray(time_s, np.float64), units="s")
        dataset(f, "range", np.asarray(range_m, np.float64), units="m")
        dataset(f, "azimuth", np.asarray(azimuth_m, np.float64), units="m")
        g = group(f, "ps")
        dataset(g, "row", np.asarray(rows, np.int64))
        dataset(g, "col", np.asarray(cols, np.int64))
        dataset(g, "range", np.asarray(range_m[rows], np.float64), units="m")
        dataset(g, "azimuth", np.asarray(azimuth_m[cols], np.float64), units="m")
        dataset(g, "coherence", np.asarray(coherence[rows, cols], np.float32), units="1")
        dataset(g, "phase", np.asarray(phase, np.float32), units="rad")
        dataset(g, "displacement_mm", np.asarray(displacement_mm, np.float32), units="mm")


def read_ps(path: str | os.PathLike) -> dict:
    with open_product(path, PS_TYPE) as f:
        out = {k: require(f, k, path)[()] for k in ("coherence", "time_s", "range", "azimuth")}
        out.update({f"ps_{k}": f["ps"][k][()] for k in f["ps"]})
    return out
