"""The single-look complex image product (``product_type = "slc"``), schema version 1.

Layout (SI units)::

    /                      provenance attributes (sarcli.io.h5common), epoch_utc, look_side, source,
                           algorithm, azimuth_spacing_m, range_spacing_m, prf_hz,
                           first_full_line / last_full_line (lines with the whole processed aperture)
    /image                 complex64 (n_lines, n_samples), chunked; azimuth along axis 0. Phase
                           convention: a scatterer at closest range R0 has phase arg(sigma) - 4 pi R0/lam
                           at its peak; the azimuth spectrum is centred on the Doppler centroid.
    /azimuth_time          float64 (n_lines,) ZERO-DOPPLER time of each line, s after epoch_utc
    /slant_range           float64 (n_samples,) closest-approach slant range of each column, m
    /doppler               the Doppler actually used, per processing block: block_time (n_blocks,) s
                           (raw time at which the model was evaluated), range_m (n_samples,),
                           fdc_hz, fr_hz_per_s, velocity_mps (n_blocks, n_samples)
    /radar                 the raw product's radar attributes
    /orbit, /attitude      copied from the raw product when present (geolocation)
    /truth                 copied from a simulated raw product (``sarcli quality`` compares with it)
    /timings               attributes: seconds per processing stage
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterator

import h5py
import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import (
    atomic_h5,
    attr_str,
    dataset,
    group,
    open_product,
    read_mapping,
    require,
    to_jsonable,
    write_mapping,
)
from sarcli.io.raw import read_platform, read_radar, write_platform, write_radar
from sarcli.model.slc import SLC, DopplerUsed

PRODUCT_TYPE = "slc"
SCHEMA_VERSION = "1"


def _write_meta(f: h5py.File, s: SLC) -> None:
    f.attrs["parameters"] = json.dumps(to_jsonable(dict(s.parameters)), sort_keys=True)
    f.attrs["epoch_utc"] = s.epoch_utc
    f.attrs["look_side"] = s.look_side
    f.attrs["source"] = s.source
    f.attrs["algorithm"] = s.algorithm
    f.attrs["azimuth_spacing_m"] = float(s.azimuth_spacing_m)
    f.attrs["range_spacing_m"] = s.range_spacing_m
    f.attrs["prf_hz"] = s.prf_hz
    f.attrs["first_full_line"] = int(s.first_full_line)
    f.attrs["last_full_line"] = int(s.last_full_line)
    dataset(f, "azimuth_time", np.asarray(s.azimuth_time, np.float64), units="s",
            description="zero-Doppler time after epoch_utc")
    dataset(f, "slant_range", np.asarray(s.slant_range, np.float64), units="m",
            description="closest-approach slant range")
    g = group(f, "doppler")
    d = s.doppler
    dataset(g, "block_time", np.asarray(d.block_time, np.float64), units="s")
    dataset(g, "range_m", np.asarray(d.range_m, np.float64), units="m")
    dataset(g, "fdc_hz", np.asarray(d.fdc_hz, np.float64), units="Hz")
    dataset(g, "fr_hz_per_s", np.asarray(d.fr_hz_per_s, np.float64), units="Hz/s")
    dataset(g, "velocity_mps", np.asarray(d.velocity_mps, np.float64), units="m/s")
    write_radar(f, s.radar)
    write_platform(f, s.orbit, s.attitude)
    if s.truth is not None:
        write_mapping(f, "truth", s.truth)
    tg = group(f, "timings")
    for k, v in sorted(s.timings.items()):
        tg.attrs[k] = float(v)


#: bytes of one ``/image`` chunk at most (HDF5's default chunk cache is 1 MiB: a chunk that a block
#: boundary splits stays in the cache until the next block completes it)
CHUNK_BYTES = 1 << 20


def image_chunks(shape: tuple[int, int]) -> tuple[int, int]:
    """HDF5 chunks of ``/image``: whole lines (no padding of the line to a multiple of a chunk width: a
    6354-sample line in 2048-wide chunks stored 29 % of padding), as many as fit in :data:`CHUNK_BYTES`."""
    n, m = (max(1, int(v)) for v in shape)
    return min(n, max(1, CHUNK_BYTES // (8 * m))), m


@contextlib.contextmanager
def slc_writer(path: str | os.PathLike, meta: SLC, shape: tuple[int, int], inputs: tuple = (),
               compression: str | None = None) -> Iterator[h5py.Dataset]:
    """Create the product atomically and yield the empty ``/image`` dataset to fill block by block
    (rows in any order).

    ``meta`` carries everything but the image (its ``image`` may be empty); metadata that is only
    known after processing (axes, Doppler, timings, parameters) can be set on ``meta`` inside the
    block (:meth:`SLC.update_from`): it is written when the block exits. The inputs are hashed
    meanwhile (:func:`sarcli.io.h5common.atomic_h5`).
    """
    chunks = image_chunks(shape)
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, meta.parameters, inputs) as f:
        ds = f.create_dataset("image", shape=shape, dtype=np.complex64, chunks=chunks, track_times=False,
                              **({"compression": compression} if compression else {}))
        ds.attrs["units"] = "1"
        ds.attrs["description"] = "focused single-look complex image (zero-Doppler line, slant-range column)"
        yield ds
        _write_meta(f, meta)


def write_slc(path: str | os.PathLike, s: SLC, inputs: tuple = ()) -> None:
    """Write an in-memory SLC atomically."""
    if s.image.shape != (s.azimuth_time.size, s.slant_range.size):
        raise ProductError(f"SLC image shape {s.image.shape} does not match its axes")
    with slc_writer(path, s, s.image.shape, inputs) as ds:
        ds[...] = np.asarray(s.image, np.complex64)


def read_slc(path: str | os.PathLike, load_image: bool = True) -> SLC:
    """Read an SLC product; a malformed file raises :class:`ProductError` (one line)."""
    with open_product(path, PRODUCT_TYPE) as f:
        sv = attr_str(f, "schema_version")
        if sv != SCHEMA_VERSION:
            raise ProductError(f"{path}: slc schema version {sv} is not supported (expected {SCHEMA_VERSION})")
        img = require(f, "image", path, shape_rank=2, dtype_kind="c")
        t = require(f, "azimuth_time", path, shape_rank=1, dtype_kind="f")[()]
        r = require(f, "slant_range", path, shape_rank=1, dtype_kind="f")[()]
        if img.shape != (t.size, r.size):
            raise ProductError(f"{path}: malformed product, image {img.shape} vs axes ({t.size}, {r.size})")
        if "radar" not in f or "doppler" not in f:
            raise ProductError(f"{path}: malformed product, missing 'radar' or 'doppler'")
        radar = read_radar(f["radar"], path)
        dg = f["doppler"]
        dop = DopplerUsed(*(require(dg, k, path)[()] for k in
                            ("block_time", "range_m", "fdc_hz", "fr_hz_per_s", "velocity_mps")))
        orbit, attitude = read_platform(f, path)
        truth = read_mapping(f["truth"]) if "truth" in f else None
        timings = dict(f["timings"].attrs) if "timings" in f else {}
        params = json.loads(attr_str(f, "parameters") or "{}")
        return SLC(
            image=img[()] if load_image else np.zeros((t.size, 0), np.complex64),
            azimuth_time=t, slant_range=r, epoch_utc=attr_str(f, "epoch_utc") or "", radar=radar,
            doppler=dop, look_side=attr_str(f, "look_side", "right"), source=attr_str(f, "source", "unknown"),
            algorithm=attr_str(f, "algorithm", "rd"),
            azimuth_spacing_m=float(f.attrs.get("azimuth_spacing_m", np.nan)),
            first_full_line=int(f.attrs.get("first_full_line", 0)),
            last_full_line=int(f.attrs.get("last_full_line", t.size - 1)),
            parameters=params, timings={k: float(v) for k, v in timings.items()},
            orbit=orbit, attitude=attitude, truth=truth,
        )
