"""The stripmap raw-echo product (``product_type = "raw"``), schema version 1.

Layout (all SI; see ``docs/products.md``)::

    /                      provenance attributes (sarcli.io.h5common), epoch_utc, look_side,
                           n_channels, source ("simulated" | "ceos" | "matlab" | ...)
    /echo                  complex64 (n_lines, n_samples), chunked; azimuth along axis 0.
                           Channel 0. Values as delivered (4-bit levels for RS-1; AGC NOT undone).
    /echo_channels         optional complex64 (n_channels-1, n_lines, n_samples): further receive
                           channels (two-channel ATI); attribute receiver_offsets_m per channel
    /azimuth_time          float64 (n_lines,) s after epoch_utc (time of pulse transmission)
    /radar                 group, attributes: carrier_frequency_hz, wavelength_m, prf_hz (nominal),
                           range_sampling_rate_hz, chirp_rate_hz_per_s (signed: phase = +pi*K*t^2),
                           pulse_length_s, window_start_s (two-way time of the first sample),
                           first_range_m (slant range of the first sample), quantization_bits
                           (0 = not quantized), receiver_offsets_m (along-track, per channel),
                           platform_velocity_mps (optional, nominal |v| for flat geometry)
      prf_per_line         optional float64 (n_lines,) Hz, when the PRF varies
      agc_db               optional float32 (n_lines,) receiver attenuation per line, dB
      replica              optional complex64 (n_replica,) chirp replica at the range sampling rate
    /orbit                 optional group, attribute frame ("ECI" | "ECEF" | "LOCAL"):
      time                 float64 (n,) s after epoch_utc
      position             float64 (n, 3) m
      velocity             float64 (n, 3) m/s
    /attitude              optional group: time (s), pitch, roll, yaw (rad, float64)
    /auxiliary             optional group: named arrays a reader keeps beside the echo, never focused
                           (RawProduct.auxiliary; e.g. Sentinel-1 noise/calibration packets under s1/,
                           NISAR calibration lines (calType != 0) under calibration/: echo (n_cal,
                           n_channels, n_samples), line (their zeroed slots in /echo), cal_type,
                           azimuth_time)
    /truth                 optional group, simulated products only: scene_toml (attr), targets
                           (compound table), and any truth arrays (e.g. doppler_centroid_hz)

Frames: "ECI" inertial of date (X to the equinox, Z spin axis; GMST rotation to ECEF, see
``orbit.frames``), "ECEF" WGS-84 Earth-fixed, "LOCAL" a flat-Earth Cartesian frame for airborne
scenes (x cross-track ground range, y along-track, z up; targets on z = 0).
Phase convention: a scatterer at one-way range R contributes exp(-j*4*pi*R/lam).
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any

import h5py
import numpy as np

from sarcli.errors import ProductError
from sarcli.io.h5common import (
    PROVENANCE_ATTRS,
    atomic_h5,
    attr_number,
    attr_str,
    dataset,
    group,
    open_product,
    read_array,
    read_mapping,
    require,
    write_mapping,
)
from sarcli.model import checks as ck
from sarcli.model.raw import QUANTIZATION_BITS, Attitude, Orbit, Radar, RawProduct

PRODUCT_TYPE = "raw"
SCHEMA_VERSION = "1"


def write_raw(path: str | os.PathLike, p: RawProduct, parameters: dict | None = None,
              inputs: tuple = (), compression: str | None = None) -> None:
    """Validate (:meth:`RawProduct.validate`) and write ``p`` atomically to ``path``.

    NaN or inf samples are written as given (a tool may store them on purpose); :func:`read_raw`
    refuses them."""
    p.validate(str(path), finite_samples=False)
    n_lines, n_samples = p.echo.shape
    chunks = (min(n_lines, 256), min(n_samples, 2048))
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        f.attrs["epoch_utc"] = p.epoch_utc
        f.attrs["look_side"] = p.look_side
        f.attrs["source"] = p.source
        f.attrs["n_channels"] = p.n_channels
        for k, v in sorted(p.extra_attrs.items()):
            f.attrs[k] = v
        dataset(f, "echo", np.asarray(p.echo, dtype=np.complex64), units="1",
                description="raw echo samples, channel 0, (azimuth line, range sample)",
                chunks=chunks, compression=compression)
        if p.echo_channels is not None:
            dataset(f, "echo_channels", np.asarray(p.echo_channels, dtype=np.complex64), units="1",
                    description="further receive channels", chunks=(1, *chunks), compression=compression)
        dataset(f, "azimuth_time", np.asarray(p.azimuth_time, dtype=np.float64), units="s",
                description="pulse transmit time after epoch_utc")
        g = write_radar(f, p.radar)
        if p.prf_per_line is not None:
            dataset(g, "prf_per_line", np.asarray(p.prf_per_line, np.float64), units="Hz")
        if p.agc_db is not None:
            dataset(g, "agc_db", np.asarray(p.agc_db, np.float32), units="dB",
                    description="receiver attenuation per line; multiply by 10**(agc_db/20) to undo")
        if p.replica is not None:
            dataset(g, "replica", np.asarray(p.replica, np.complex64), units="1")
        write_platform(f, p.orbit, p.attitude)
        for name, arr in sorted(p.auxiliary.items()):
            f.create_dataset(f"auxiliary/{name}", data=arr)
        if p.truth is not None:
            write_mapping(f, "truth", p.truth)


def write_radar(f: h5py.Group, radar: Radar) -> h5py.Group:
    """The /radar group's attributes (shared by the raw and SLC products)."""
    g = group(f, "radar")
    for fld in dataclasses.fields(Radar):
        v = getattr(radar, fld.name)
        if v is not None:
            g.attrs[fld.name] = np.asarray(v, dtype=np.float64) if fld.name == "receiver_offsets_m" else v
    return g


def read_radar(g: h5py.Group, path: str | os.PathLike) -> Radar:
    """Inverse of :func:`write_radar`: every attribute type-checked (a string, array or NaN where a number
    belongs is refused in one line); a missing required attribute is refused in one line. Plausibility
    is :meth:`Radar.validate`'s job."""
    kw: dict[str, Any] = {}
    for fld in dataclasses.fields(Radar):
        if fld.name not in g.attrs:
            if fld.default is dataclasses.MISSING:
                raise ProductError(f"{path}: malformed product, radar attribute '{fld.name}' missing")
            continue
        if fld.name == "receiver_offsets_m":
            v = g.attrs[fld.name]
            a = ck.array(f"{path}: radar", fld.name, np.atleast_1d(v), "f", ndim=1, min_size=1)
            kw[fld.name] = tuple(float(x) for x in a)
        elif fld.name == "quantization_bits":
            kw[fld.name] = attr_number(g, fld.name, lo=QUANTIZATION_BITS[0], hi=QUANTIZATION_BITS[1], integer=True)
        else:
            kw[fld.name] = attr_number(g, fld.name)
    return Radar(**kw)


def write_platform(f: h5py.Group, orbit: Orbit | None, attitude: Attitude | None) -> None:
    """/orbit and /attitude groups (shared by the raw and SLC products)."""
    if orbit is not None:
        og = group(f, "orbit")
        og.attrs["frame"] = orbit.frame
        dataset(og, "time", np.asarray(orbit.time, np.float64), units="s")
        dataset(og, "position", np.asarray(orbit.position, np.float64), units="m")
        dataset(og, "velocity", np.asarray(orbit.velocity, np.float64), units="m/s")
    if attitude is not None:
        ag = group(f, "attitude")
        dataset(ag, "time", np.asarray(attitude.time, np.float64), units="s")
        for name in ("pitch", "roll", "yaw"):
            dataset(ag, name, np.asarray(getattr(attitude, name), np.float64), units="rad")


def read_platform(f: h5py.Group, path: str | os.PathLike) -> tuple[Orbit | None, Attitude | None]:
    """Inverse of :func:`write_platform` (missing groups -> None); arrays type-checked, the models'
    ``validate`` checks the rest."""
    orbit = attitude = None
    if "orbit" in f:
        og = _subgroup(f, "orbit", path)
        orbit = Orbit(read_array(og, "time", "f", ndim=1, finite=False),
                      read_array(og, "position", "f", ndim=2, finite=False),
                      read_array(og, "velocity", "f", ndim=2, finite=False), attr_str(og, "frame", "ECI"))
    if "attitude" in f:
        ag = _subgroup(f, "attitude", path)
        attitude = Attitude(*(read_array(ag, k, "f", ndim=1, finite=False) for k in ("time", "pitch", "roll", "yaw")))
    return orbit, attitude


def _subgroup(f: h5py.Group, name: str, path: str | os.PathLike) -> h5py.Group:
    g = f[name]
    if not isinstance(g, h5py.Group):
        raise ProductError(f"{path}: malformed product, '{name}' is not a group")
    return g


def _extra_attrs(f: h5py.File, standard: set[str], path: str | os.PathLike) -> dict[str, Any]:
    """The root attributes a reader does not interpret (sensor metadata), carried to derived products:
    text checked as UTF-8 (it is written again), numbers and numeric arrays as they are."""
    out: dict[str, Any] = {}
    for k in f.attrs:
        if k in standard:
            continue
        v = f.attrs[k]
        if isinstance(v, str | bytes | np.bytes_):
            v = attr_str(f, k)
        elif isinstance(v, np.ndarray) and v.dtype.kind in "OSU":
            v = np.array([ck.text(f"{path}", k, x) for x in v.ravel()], dtype=object).reshape(v.shape)
        out[k] = v
    return out


def read_raw(path: str | os.PathLike, load_echo: bool = True) -> RawProduct:
    """Read and validate a raw product; a malformed or implausible file raises :class:`ProductError`
    (one line; :meth:`RawProduct.validate` lists the checks).

    With ``load_echo=False`` the echo comes back as an empty (n_lines, 0) array (further channels as
    (n_channels - 1, n_lines, 0)) and everything else is read and validated; use
    :func:`read_raw_echo_block` to stream lines in bounded memory.
    """
    with open_product(path, PRODUCT_TYPE) as f:
        sv = attr_str(f, "schema_version")
        if sv != SCHEMA_VERSION:
            raise ProductError(f"{path}: raw schema version {sv} is not supported (expected {SCHEMA_VERSION})")
        echo_ds = require(f, "echo", path, shape_rank=2, dtype_kind="c")
        n_lines, n_samples = echo_ds.shape
        t = read_array(f, "azimuth_time", "f", ndim=1, finite=False)
        if "radar" not in f:
            raise ProductError(f"{path}: malformed product, missing 'radar'")
        g = _subgroup(f, "radar", path)
        radar = read_radar(g, path)
        echo_channels = ch = None
        if "echo_channels" in f:
            ch = require(f, "echo_channels", path, shape_rank=3, dtype_kind="c")
            if ch.shape[1:] != (n_lines, n_samples):
                raise ProductError(f"{path}: echo_channels has shape {ch.shape}, echo {echo_ds.shape}")
            echo_channels = np.zeros((ch.shape[0], n_lines, 0), np.complex64)
        orbit, attitude = read_platform(f, path)
        if "truth" in f:
            truth = read_mapping(_subgroup(f, "truth", path))
        else:
            truth = None
        epoch = attr_str(f, "epoch_utc")
        if epoch is None:
            raise ProductError(f"{path}: malformed product, epoch_utc missing")
        p = RawProduct(
            echo=np.zeros((n_lines, 0), np.complex64), azimuth_time=t, epoch_utc=epoch, radar=radar,
            look_side=attr_str(f, "look_side", "right"), source=attr_str(f, "source", "unknown"),
            echo_channels=echo_channels,
            prf_per_line=read_array(g, "prf_per_line", "f", ndim=1, finite=False, required=False),
            agc_db=read_array(g, "agc_db", "f", ndim=1, finite=False, required=False),
            replica=read_array(g, "replica", "c", ndim=1, finite=False, required=False),
            orbit=orbit, attitude=attitude, truth=truth,
        )
        if "auxiliary" in f:
            _subgroup(f, "auxiliary", path).visititems(
                lambda name, obj: p.auxiliary.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        n_ch = attr_number(f, "n_channels", p.n_channels, lo=1, integer=True)
        if n_ch != p.n_channels:
            raise ProductError(f"{path}: n_channels says {n_ch}, the product holds {p.n_channels} channel(s)")
        p.extra_attrs = _extra_attrs(f, set(PROVENANCE_ATTRS) | {"epoch_utc", "look_side", "source", "n_channels"},
                                     path)
        p.validate(str(path), n_samples=n_samples)  # everything but the samples, before reading them
        if load_echo:
            p.echo = ck.array(str(path), "echo", echo_ds[()], "c")
            if ch is not None:
                p.echo_channels = ck.array(str(path), "echo_channels", ch[()], "c")
        return p


def read_raw_echo_block(path: str | os.PathLike, start: int, stop: int, channel: int = 0) -> np.ndarray:
    """Lines ``start:stop`` of one channel's echo, for block processing in bounded memory (NaN or inf
    samples are refused in one line)."""
    with open_product(path, PRODUCT_TYPE) as f:
        if channel == 0:
            block = require(f, "echo", path, shape_rank=2, dtype_kind="c")[start:stop]
        else:
            block = require(f, "echo_channels", path, shape_rank=3, dtype_kind="c")[channel - 1, start:stop]
        return ck.array(str(path), "echo" if channel == 0 else "echo_channels", block, "c")


def raw_shape(path: str | os.PathLike) -> tuple[int, int]:
    """(n_lines, n_samples) without reading the echo."""
    with open_product(path, PRODUCT_TYPE) as f:
        return tuple(require(f, "echo", path, shape_rank=2, dtype_kind="c").shape)  # type: ignore[return-value]
