"""The focused GB-SAR image product (``product_type = "gbsar_image"``), schema versions 1 and 2.

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

Schema 2 (written only for what schema 1 cannot say; a rail image in air stays schema 1, in the
layout it always had) adds root attributes ``permittivity`` (relative permittivity of the medium, waves
at c/sqrt(eps); ranges are geometric metres in it) and ``grid_z_m``: a grid image (``gbsar focus
--grid``) lies in the horizontal plane z = grid_z_m of the scan frame, /range then holds y (rows)
and /azimuth x (columns), and ``phase_convention`` is "reflectivity" (a scatterer focuses to its
complex amplitude). An older reader refuses schema 2 instead of taking it for a slant-plane image.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
from collections.abc import Iterator

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
    require,
)
from sarcli.io.scan import read_attr_group
from sarcli.model.gbsar import GbsarImage, Site

PRODUCT_TYPE = "gbsar_image"
SCHEMA_VERSION = "1"
SCHEMA_VERSION_GRID = "2"  # with permittivity and/or grid_z_m


_SCALARS = ("algorithm", "center_frequency_hz", "frequency_step_hz", "n_freq", "rail_height_m", "rail_centre_m",
            "rail_length_m", "epoch_utc", "scan_time_s")


def write_gbsar_image(path: str | os.PathLike, img: GbsarImage, parameters: dict | None = None,
                      inputs: tuple = ()) -> None:
    if img.image.ndim != 3 or img.image.shape[1:] != (img.range_m.size, img.azimuth_m.size):
        raise ProductError(f"{path}: image shape {img.image.shape} does not match its axes")
    plain = img.permittivity == 1.0 and img.grid_z_m is None
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION if plain else SCHEMA_VERSION_GRID, parameters, inputs) as f:
        for k in _SCALARS:
            f.attrs[k] = getattr(img, k)
        f.attrs["polarizations"] = ",".join(img.polarizations)
        f.attrs["report"] = json.dumps(img.report, sort_keys=True, default=float)
        f.attrs["phase_convention"] = "-4*pi*R0/lambda" if img.grid_z_m is None else "reflectivity"
        if not plain:
            f.attrs["permittivity"] = float(img.permittivity)
            if img.grid_z_m is not None:
                f.attrs["grid_z_m"] = float(img.grid_z_m)
        pol = coordinate(f, "polarization", np.array([p.encode() for p in img.polarizations]), "1",
                         "transmit-receive polarization")
        grid = img.grid_z_m is not None
        rg = coordinate(f, "range", np.asarray(img.range_m, np.float64), "m",
                        "y across the scan frame (grid image rows)" if grid else "R0, distance from the rail line")
        az = coordinate(f, "azimuth", np.asarray(img.azimuth_m, np.float64), "m",
                        "x along the scan frame (grid image columns)" if grid else "x along the rail")
        dataset(f, "image", np.asarray(img.image, np.complex64), units="1", chunks=True, compression="gzip",
                description="focused complex image (polarization, range, azimuth)", dims=(pol, rg, az))
        dataset(f, "algorithm_map", np.asarray(img.algorithm_map, np.uint8), units="1", compression="gzip",
                description="algorithm that focused each pixel: 0 not covered, 1 DF, 2 RD, 3 BP", dims=(rg, az))
        g = group(f, "site")
        for k, v in vars(img.site).items():
            g.attrs[k] = v


@contextlib.contextmanager
def open_gbsar_image(path: str | os.PathLike) -> Iterator[GbsarImage]:
    """The image product with its pixels left on disk: ``image`` is the HDF5 dataset (n_pol, n_range,
    n_azimuth), read by slicing (e.g. a block of rows), valid inside the ``with`` block only. Everything
    but the pixels is validated (:meth:`GbsarImage.validate`)."""
    with open_product(path, PRODUCT_TYPE) as f:
        version = attr_str(f, "schema_version")
        if version not in (SCHEMA_VERSION, SCHEMA_VERSION_GRID):
            raise ProductError(f"{path}: unsupported gbsar_image schema version {version}")
        missing = [k for k in _SCALARS if k not in f.attrs]
        if missing:
            raise ProductError(f"{path}: malformed gbsar_image, missing attribute(s) {', '.join(missing)}")
        vals = {k: (attr_str(f, k) if k in ("algorithm", "epoch_utc") else attr_number(f, k, integer=k == "n_freq"))
                for k in _SCALARS}
        img = GbsarImage(
            image=require(f, "image", path, shape_rank=3, dtype_kind="c"),
            range_m=read_array(f, "range", "f", ndim=1, finite=False),
            azimuth_m=read_array(f, "azimuth", "f", ndim=1, finite=False),
            algorithm_map=read_array(f, "algorithm_map", "iu", ndim=2),
            polarizations=tuple(p for p in (attr_str(f, "polarizations") or "").split(",") if p),
            site=read_attr_group(f, "site", Site), report=attr_json(f, "report", {}),
            permittivity=attr_number(f, "permittivity", 1.0),
            grid_z_m=attr_number(f, "grid_z_m") if "grid_z_m" in f.attrs else None, **vals)
        img.validate(str(path), pixels=False)
        yield img


def read_gbsar_image(path: str | os.PathLike) -> GbsarImage:
    """Read and validate (:meth:`GbsarImage.validate`) an image product; ProductError (one line) otherwise."""
    with open_gbsar_image(path) as lazy:
        img = dataclasses.replace(lazy, image=lazy.image[()])
    img.validate(str(path))
    return img
