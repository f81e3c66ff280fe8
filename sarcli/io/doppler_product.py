"""The Doppler product ``doppler.h5`` (``product_type = "doppler"``), schema version 1.

Layout (SI units)::

    /                 provenance (sarcli.io.h5common; ``parameters`` = the workflow configuration:
                      raw, output, plot, options (every estimation knob), height (m)),
                      prf_hz, wavelength_m, summary_json (the scene summary printed by --json,
                      :class:`sarcli.model.doppler_summary.DopplerSummary`), fdc_method, ambiguity_source,
                      ambiguity_confidence, ambiguity_resolved (int 0/1: whether a source decided the
                      PRF ambiguity; 0 = the centroid's ambiguity is a guess), fr_method, n_az_blocks,
                      n_rg_blocks
    /block            int64 (n_blocks,) block index, the dimension of every /blocks dataset
    /blocks           one 1-D dataset per column, one row per (azimuth block, range block), row-major
                      (azimuth outer): range_m, azimuth_time_s, fdc_baseband_hz, quality, weight, valid,
                      ambiguity, margin_prf, fdc_hz (absolute, per block), fdc_fit_hz, fdc_orbit_hz,
                      fr_hz_per_s, fr_seed_hz_per_s, look_seed_rad, range_seed_m, outlier
    /fdc_poly         coef (dx+1, dy+1) Hz; attributes x0, xs (m), y0, ys (s):
                      fdc(R, t) = sum coef[i, j] ((R - x0)/xs)^i ((t - y0)/ys)^j   (absolute centroid)
    /fr_poly          the same for the Doppler rate (Hz/s); an attribute x_power = p (default 0) multiplies
                      it by R^p (map-drift: p = -1, one coefficient -2 Vr^2/lam, fr = -2 Vr^2/(lam R))

``read_doppler(path)`` returns the :class:`sarcli.model.doppler.PolyDoppler` (its summary from
``summary_json``; older products are read as ``DopplerSummary.from_dict`` describes).
"""

from __future__ import annotations

import dataclasses
import json
import os

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
    provenance,
    read_array,
    to_jsonable,
    units_from_name,
)
from sarcli.model.constants import C_LIGHT
from sarcli.model.doppler import PolyDoppler
from sarcli.model.doppler_summary import DopplerSummary
from sarcli.model.poly import Poly2D
from sarcli.model.raw import CARRIER_HZ, PRF_HZ

PRODUCT_TYPE = "doppler"
SCHEMA_VERSION = "1"

DESCRIPTIONS = {
    "range_m": "slant range of the block centre", "azimuth_time_s": "raw time of the block centre, s after the "
    "raw product's epoch_utc", "fdc_baseband_hz": "centroid estimate in the baseband (-PRF/2, PRF/2]",
    "quality": "block quality |C|/E (magnitude of the lag-1 correlation over the energy)",
    "weight": "fit weight (inverse phase variance)", "valid": "1 if the block's estimate is usable",
    "ambiguity": "PRF ambiguity number of the block", "margin_prf": "distance of the estimate from the ambiguity "
    "decision boundary, in PRFs", "fdc_hz": "absolute centroid of the block", "fdc_fit_hz": "the fitted model at the "
    "block", "fdc_orbit_hz": "the orbit + attitude (geometry) centroid at the block", "fr_hz_per_s": "Doppler rate "
    "of the block", "fr_seed_hz_per_s": "geometric Doppler rate the estimate started from", "look_seed_rad":
    "look angle of the geometric seed", "range_seed_m": "slant range of the geometric seed", "outlier": "1 if the "
    "fit rejected the block"}
UNITS = {"range_m": "m", "azimuth_time_s": "s", "fdc_baseband_hz": "Hz", "quality": "1", "weight": "rad-2",
         "valid": "1", "ambiguity": "1", "margin_prf": "1", "fdc_hz": "Hz", "fdc_fit_hz": "Hz",
         "fdc_orbit_hz": "Hz", "fr_hz_per_s": "Hz/s", "fr_seed_hz_per_s": "Hz/s", "look_seed_rad": "rad",
         "range_seed_m": "m", "outlier": "1"}


def _write_poly(f, name: str, p: Poly2D, units: str) -> None:
    g = group(f, name)
    g.attrs["description"] = f"2-D polynomial of the {'Doppler centroid' if units == 'Hz' else 'Doppler rate'} " \
        "in range and azimuth time (x0, xs in m; y0, ys in s)"
    dataset(g, "coef", np.asarray(p.coef, np.float64), units=units,
            description="sum coef[i,j] ((range - x0)/xs)^i ((time - y0)/ys)^j")
    for k in ("x0", "xs", "y0", "ys"):
        g.attrs[k] = float(getattr(p, k))
    g.attrs["x_power"] = int(p.x_power)


def _read_poly(f, name: str, path) -> Poly2D:
    """A polynomial group: finite 2-D coefficients, finite offsets, positive finite scales (they divide),
    an integer range power."""
    if name not in f or not isinstance(f[name], h5py.Group):
        raise ProductError(f"{path}: malformed doppler product, missing group '{name}'")
    g = f[name]
    coef = read_array(g, "coef", "f", ndim=2, min_size=1)
    x0, y0 = (attr_number(g, k) for k in ("x0", "y0"))
    xs, ys = (attr_number(g, k, lo=0.0) for k in ("xs", "ys"))
    if xs == 0.0 or ys == 0.0:
        raise ProductError(f"{path}: malformed doppler product, '{name}' has a zero scale")
    return Poly2D(coef, x0, xs, y0, ys, attr_number(g, "x_power", 0, lo=-4, hi=4, integer=True))


def write_doppler(path: str | os.PathLike, model: PolyDoppler, inputs: tuple = (),
                  parameters: dict | None = None) -> None:
    """Write ``model`` atomically to ``path``; ``parameters`` (default ``model.parameters``) is what the
    product records about how it was made (the workflow passes its configuration)."""
    s = model.summary
    if s is None:
        raise ProductError(f"{path}: a Doppler model without a summary cannot be written as a doppler product")
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, model.parameters if parameters is None else parameters,
                   inputs) as f:
        f.attrs["prf_hz"] = float(model.prf_hz)
        f.attrs["wavelength_m"] = float(model.wavelength_m)
        f.attrs["n_az_blocks"] = int(s.n_az_blocks)
        f.attrs["n_rg_blocks"] = int(s.n_rg_blocks)
        f.attrs["summary_json"] = json.dumps(to_jsonable(s.to_dict()), sort_keys=True)
        for k in ("fdc_method", "ambiguity_source", "fr_method"):
            f.attrs[k] = str(getattr(s, k))
        f.attrs["ambiguity_confidence"] = float(s.ambiguity_confidence)
        f.attrs["ambiguity_resolved"] = np.int8(s.ambiguity_resolved)
        g = group(f, "blocks")
        g.attrs["description"] = ("one value per (azimuth block, range block), row-major (azimuth outer): the "
                                  "block estimates and the fit")
        n = len(next(iter(model.blocks.values()))) if model.blocks else 0
        b = coordinate(f, "block", np.arange(n, dtype=np.int64), "1",
                       f"block index = azimuth block * {int(s.n_rg_blocks)} + range block")
        for k in sorted(model.blocks):
            v = np.asarray(model.blocks[k])
            v = v.astype(np.int8) if v.dtype == bool else v
            dataset(g, k, v, units=UNITS.get(k, units_from_name(k) or "1"),
                    description=DESCRIPTIONS.get(k, k.replace("_", " ")), dims=(b,) if v.ndim == 1 else ())
        _write_poly(f, "fdc_poly", model.fdc_poly, "Hz")
        _write_poly(f, "fr_poly", model.fr_poly, "Hz/s")


def read_doppler(path: str | os.PathLike) -> PolyDoppler:
    """Read a ``doppler.h5`` into a :class:`PolyDoppler`; a malformed file raises ProductError (one line)."""
    with open_product(path, PRODUCT_TYPE) as f:
        sv = attr_str(f, "schema_version")
        if sv != SCHEMA_VERSION:
            raise ProductError(f"{path}: doppler schema version {sv} is not supported (expected {SCHEMA_VERSION})")
        prf = attr_number(f, "prf_hz", lo=PRF_HZ[0], hi=PRF_HZ[1], unit="Hz")
        lam = attr_number(f, "wavelength_m", lo=C_LIGHT / CARRIER_HZ[1], hi=C_LIGHT / CARRIER_HZ[0], unit="m")
        blocks = {}
        if "blocks" in f:
            g = f["blocks"]
            if not isinstance(g, h5py.Group):
                raise ProductError(f"{path}: malformed doppler product, 'blocks' is not a group")
            for k in g:
                v = read_array(g, k, "fiub", ndim=1, finite=False)
                blocks[k] = v.astype(bool) if k in ("valid", "outlier") else v
            if len({v.size for v in blocks.values()}) > 1:
                raise ProductError(f"{path}: malformed doppler product, the block columns differ in length")
        summary = DopplerSummary.from_dict(attr_json(f, "summary_json", {}), f"{path}: summary_json")
        if "ambiguity_resolved" in f.attrs:  # 0/1; where it and the summary differ, not resolved
            v = f.attrs["ambiguity_resolved"]
            flag = bool(v) if isinstance(v, bool | np.bool_) else attr_number(f, "ambiguity_resolved", lo=0, hi=1,
                                                                                integer=True)
            if summary.ambiguity_resolved and not flag:
                summary = dataclasses.replace(summary, ambiguity_resolved=False)
        params = provenance(f).get("parameters") or {}
        return PolyDoppler(_read_poly(f, "fdc_poly", path), _read_poly(f, "fr_poly", path), prf, lam, blocks,
                            summary, params if isinstance(params, dict) else {})
