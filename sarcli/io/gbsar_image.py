"""The focused GB-SAR image product (``product_type = "gbsar_image"``), schema version 1.

Layout (SI units)::

    /                 provenance, epoch_utc, polarizations, algorithm, center_frequency_hz,
                      frequency_step_hz, n_freq, rail_height_m (mean antenna height), rail_centre_m,
                      rail_length_m, scan_time_s (mean stop time after epoch), report (JSON),
                      phase_convention = "-4*pi*R0/lambda"
    /image            complex64 (n_pol, n_range, n_azimuth): slant-plane image
    /range            float64 (n_range,) m, R0 = distance from the rail line (image plane through the rail)
    /azimuth          float64 (n_azimuth,) m, x along the rail (scan frame)
    /algorithm_map    uint8 (n_range, n_azimuth): 0 not covered, 1 DF, 2 RD, 3 BP
    /site             attributes of the scan's site (rail centre geodetic position, heading, look side)
"""

from __future__ import annotations

import json
import os

import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import atomic_h5, attr_json, attr_number, attr_str, dataset, group, open_product, read_array
from sarcli.io.scan import read_attr_group
from sarcli.model.gbsar import GbsarImage, Site

PRODUCT_TYPE = "gbsar_image"
SCHEMA_VERSION = "1"


_SCALARS = ("algorithm", "center_frequency_hz", "frequency_step_hz", "n_freq", "rail_height_m", "rail_centre_m",
            "rail_length_m", "epoch_utc", "scan_time_s")


def write_gbsar_image(path: str | os.PathLike, img: GbsarImage, parameters: dict | None = None,
                      inputs: tuple = ()) -> None:
    if img.image.ndim != 3 or img.image.shape[1:] != (img.range_m.size, img.azimuth_m.size):
        raise ProductError(f"{path}: image shape {img.image.shape} does not match its axes")
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        for k in _SCALARS:
            f.attrs[k] = getattr(img, k)
        f.attrs["polarizations"] = ",".join(img.polarizations)
        f.attrs["report"] = json.dumps(img.report, sort_keys=True, default=float)
        f.attrs["phase_convention"] = "-4*pi*R0/lambda"
        dataset(f, "image", np.asarray(img.image, np.complex64), units="1", chunks=True, compression="gzip")
        dataset(f, "range", np.asarray(img.range_m, np.float64), units="m")
        dataset(f, "azimuth", np.asarray(img.azimuth_m, np.float64), units="m")
        dataset(f, "algorithm_map", np.asarray(img.algorithm_map, np.uint8), units="1", compression="gzip")
        g = group(f, "site")
        for k, v in vars(img.site).items():
            g.attrs[k] = v


def read_gbsar_image(path: str | os.PathLike) -> GbsarImage:
    """Read and validate (:meth:`GbsarImage.validate`) an image product; ProductError (one line) otherwise."""
    with open_product(path, PRODUCT_TYPE) as f:
        if attr_str(f, "schema_version") != SCHEMA_VERSION:
            raise ProductError(f"{path}: unsupported gbsar_image schema version")
        missing = [k for k in _SCALARS if k not in f.attrs]
        if missing:
            raise ProductError(f"{path}: malformed gbsar_image, missing attribute(s) {', '.join(missing)}")
        vals = {k: (attr_str(f, k) if k in ("algorithm", "epoch_utc") else attr_number(f, k, integer=k == "n_freq"))
                for k in _SCALARS}
        img = GbsarImage(
            image=read_array(f, "image", "c", ndim=3, finite=False),
            range_m=read_array(f, "range", "f", ndim=1, finite=False),
            azimuth_m=read_array(f, "azimuth", "f", ndim=1, finite=False),
            algorithm_map=read_array(f, "algorithm_map", "iu", ndim=2),
            polarizations=tuple(p for p in (attr_str(f, "polarizations") or "").split(",") if p),
            site=read_attr_group(f, "site", Site), report=attr_json(f, "report", {}), **vals)
    img.validate(str(path))
    return img
