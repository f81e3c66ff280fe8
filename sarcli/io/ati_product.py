"""The ATI moving-target product (``product_type = "ati"``), schema version 1.

Layout (SI units)::

    /                      provenance attributes (sarcli.io.h5common), epoch_utc, t_ref_s (reference time
                           of every mover estimate, s after epoch_utc), frame ("LOCAL"), look_side,
                           detection (JSON: CFAR knobs and summary), movers_json (JSON list, the
                           ``sarcli ati estimate --json`` records)
    /azimuth_time          float64 (n_lines,) zero-Doppler time of each image line, s after epoch_utc
    /slant_range           float64 (n_samples,) closest-approach slant range of each column, m
    /image_before          complex64 (n_lines, n_samples): channel-0 RD image (stationary-scene focusing)
    /image_after           optional complex64: movers compensated and relocated (``sarcli ati compensate``)
    /ati_phase             float32 (n_lines, n_samples): arg(Z1 * conj(Z0)) of the co-registered pair, rad
    /movers                compound table, one row per mover: id, vx_mps, vy_mps, x0_m, y0_m, r0_m and their
                           *_sigma (1-sigma), x_local_m, y_local_m (LOCAL frame at t_ref), confidence,
                           ati_phase_rad, ati_ambiguous, vy_degenerate
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
    attr_value,
    cf_time_units,
    coordinate,
    dataset,
    open_product,
    read_array,
    to_jsonable,
    units_from_name,
)
from sarcli.model import checks as ck
from sarcli.model.raw import LOOK_SIDES

PRODUCT_TYPE = "ati"
SCHEMA_VERSION = "1"
MOVER_FIELDS = ("vx_mps", "vy_mps", "x0_m", "y0_m", "r0_m", "vx_mps_sigma", "vy_mps_sigma", "x0_m_sigma",
                "y0_m_sigma", "r0_m_sigma", "x_local_m", "y_local_m", "confidence", "ati_phase_rad")


def _table(movers: list[dict]) -> np.ndarray:
    dt = [("id", "i4")] + [(k, "f8") for k in MOVER_FIELDS] + [("ati_ambiguous", "i1"), ("vy_degenerate", "i1")]
    tab = np.zeros(len(movers), dt)
    for i, m in enumerate(movers):
        tab[i]["id"] = m.get("id", i)
        for k in MOVER_FIELDS:
            v = m.get(k)
            tab[i][k] = np.nan if v is None else float(v)
        tab[i]["ati_ambiguous"] = int(bool(m.get("ati_ambiguous", False)))
        tab[i]["vy_degenerate"] = int(bool(m.get("vy_degenerate", False)))
    return tab


def write_ati(path: str | os.PathLike, *, epoch_utc: str, t_ref_s: float, look_side: str,
              azimuth_time: np.ndarray, slant_range: np.ndarray, image_before: np.ndarray,
              ati_phase: np.ndarray, movers: list[dict], detection: dict[str, Any],
              image_after: np.ndarray | None = None, parameters: dict | None = None, inputs: tuple = ()) -> None:
    """Write the product atomically (see the module docstring)."""
    n, m = image_before.shape
    chunks = (min(n, 256), min(m, 1024))
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        f.attrs["epoch_utc"] = epoch_utc
        f.attrs["t_ref_s"] = float(t_ref_s)
        f.attrs["frame"] = "LOCAL"
        f.attrs["look_side"] = look_side
        f.attrs["detection"] = json.dumps(to_jsonable(detection), sort_keys=True)
        f.attrs["movers_json"] = json.dumps(to_jsonable(movers), sort_keys=True)
        t = coordinate(f, "azimuth_time", np.asarray(azimuth_time, np.float64), cf_time_units(epoch_utc),
                       "zero-Doppler time of each image line")
        r = coordinate(f, "slant_range", np.asarray(slant_range, np.float64), "m", "closest-approach slant range")
        dataset(f, "image_before", np.asarray(image_before, np.complex64), units="1", chunks=chunks,
                description="channel-0 RD image, stationary-scene focusing", dims=(t, r))
        if image_after is not None:
            dataset(f, "image_after", np.asarray(image_after, np.complex64), units="1", chunks=chunks,
                    description="movers compensated and relocated", dims=(t, r))
        dataset(f, "ati_phase", np.asarray(ati_phase, np.float32), units="rad", chunks=chunks,
                description="arg(Z1 conj(Z0)), co-registered, channel 1 ahead", dims=(t, r))
        tab = _table(movers)
        ds = dataset(f, "movers", tab, units="1", description="one row per mover, SI units, 1-sigma uncertainties: "
                     "units of each field in field_units")
        ds.attrs["field_units"] = json.dumps({n: units_from_name(n.removesuffix("_sigma")) or "1"
                                              for n in tab.dtype.names})


def read_ati(path: str | os.PathLike) -> dict[str, Any]:
    """The product as a dict (arrays loaded); a malformed file raises ProductError (one line). Checked:
    an ISO-8601 epoch, a finite t_ref_s, a look side, JSON detection (object) and movers (list), finite
    increasing axes, finite complex images and ATI phase on their grid, the movers table with its fields."""
    with open_product(path, PRODUCT_TYPE) as f:
        where = str(path)
        t = read_array(f, "azimuth_time", "f", ndim=1, min_size=1)
        r = read_array(f, "slant_range", "f", ndim=1, min_size=1)
        ck.increasing(where, "azimuth_time", t)
        ck.increasing(where, "slant_range", r)
        grid = (t.size, r.size)
        out: dict[str, Any] = {
            "epoch_utc": ck.utc(where, "epoch_utc", attr_value(f, "epoch_utc")),
            "t_ref_s": attr_number(f, "t_ref_s", unit="s"),
            "look_side": ck.text(where, "look_side", attr_value(f, "look_side"), LOOK_SIDES),
            "detection": attr_json(f, "detection", {}, kind=dict),
            "movers": attr_json(f, "movers_json", [], kind=list),
            "azimuth_time": t, "slant_range": r,
            "image_before": read_array(f, "image_before", "c", shape=grid),
            "ati_phase": read_array(f, "ati_phase", "f", shape=grid),
            "image_after": read_array(f, "image_after", "c", shape=grid, required=False),
        }
        if "movers" not in f or not isinstance(f["movers"], h5py.Dataset):
            raise ProductError(f"{path}: malformed product, missing 'movers'")
        tab = f["movers"][()]
        names = tab.dtype.names or ()
        missing = [k for k in ("id", *MOVER_FIELDS) if k not in names]
        if tab.ndim != 1 or missing:
            raise ProductError(f"{path}: malformed movers table (missing field(s) {', '.join(missing) or '-'})")
        out["movers_table"] = tab
        return out
