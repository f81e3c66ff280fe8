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
    cf_time_units,
    coordinate,
    dataset,
    group,
    open_product,
    read_array,
    read_mapping,
    require,
    units_from_name,
    write_mapping,
)
from sarcli.model import checks as ck
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import QUANTIZATION_BITS, Attitude, Orbit, Radar, RawProduct

PRODUCT_TYPE = "raw"
SCHEMA_VERSION = "1"


#: HDF5 compression of the echo: ``auto`` (shuffle + gzip level 1 where it pays, :func:`echo_compression`),
#: ``gzip`` (shuffle + gzip level 1), ``lzf`` (shuffle + lzf), ``none``
COMPRESSIONS = ("auto", "gzip", "lzf", "none")
#: bytes of one echo chunk: whole lines (the readers read line blocks across the full swath)
CHUNK_BYTES = 1 << 20
#: deflate level of ``gzip``: level 1 (measured: within 2 % of level 4's size at half its write time)
GZIP_LEVEL = 1


def echo_chunks(shape: tuple[int, ...]) -> tuple[int, ...]:
    """Chunks of an echo array (..., n_lines, n_samples): whole lines, about :data:`CHUNK_BYTES` each
    (complex64), since every reader reads blocks of lines across the whole swath."""
    n_lines, n_samples = shape[-2:]
    lines = int(min(max(n_lines, 1), max(1, CHUNK_BYTES // (8 * max(n_samples, 1)))))
    return (1,) * (len(shape) - 2) + (lines, max(n_samples, 1))


def echo_compression(echo: np.ndarray, compression: str | None = "auto") -> str | None:
    """The h5py filter of the echo (``gzip`` or ``lzf``, always after the byte shuffle) or None.

    ``auto`` compresses when it pays: the first chunk of lines, byte-shuffled as HDF5 does it and
    deflated at level 1 with zlib, shrinks below 80 % (quantized echoes: RS-1's 4-bit levels, BAQ,
    a simulation with the quantization effect, zero padding); a float echo of noise does not, and is
    stored as it is (bench/bench_products.py measures sizes and costs)."""
    import zlib

    mode = "auto" if compression is None else compression
    if mode not in COMPRESSIONS:
        raise ProductError(f"unknown echo compression {compression!r} (use {', '.join(COMPRESSIONS)})")
    if mode == "none":
        return None
    if mode != "auto":
        return mode
    e = np.asarray(echo)
    rows = e.reshape(-1, e.shape[-1])[: echo_chunks(e.shape)[-2]]
    raw = np.ascontiguousarray(rows, dtype=np.complex64).view(np.uint8).reshape(-1, 8).T.tobytes()
    return "gzip" if raw and len(zlib.compress(raw, 1)) < 0.8 * len(raw) else None


def write_raw(path: str | os.PathLike, p: RawProduct, parameters: dict | None = None,
              inputs: tuple = (), compression: str | None = "auto") -> None:
    """Validate (:meth:`RawProduct.validate`) and write ``p`` atomically to ``path`` (``compression``: one
    of :data:`COMPRESSIONS`, None = ``auto``).

    NaN or inf samples are written as given (a tool may store them on purpose); :func:`read_raw`
    refuses them."""
    p.validate(str(path), finite_samples=False)
    n_lines, n_samples = p.echo.shape
    filt = echo_compression(p.echo, compression)
    tunits = cf_time_units(p.epoch_utc)
    with atomic_h5(path, PRODUCT_TYPE, SCHEMA_VERSION, parameters, inputs) as f:
        f.attrs["epoch_utc"] = p.epoch_utc
        f.attrs["look_side"] = p.look_side
        f.attrs["source"] = p.source
        f.attrs["n_channels"] = p.n_channels
        for k, v in sorted(p.extra_attrs.items()):
            f.attrs[k] = v
        t = coordinate(f, "azimuth_time", np.asarray(p.azimuth_time, dtype=np.float64), tunits,
                       "pulse transmit time of each echo line")
        fs, tau0 = p.radar.range_sampling_rate_hz, p.radar.window_start_s
        r = coordinate(f, "slant_range", C_LIGHT / 2.0 * (tau0 + np.arange(n_samples) / fs), "m",
                       "one-way range c*tau/2 of each echo sample's two-way delay tau (window_start_s + k/fs)")
        dataset(f, "echo", np.asarray(p.echo, dtype=np.complex64), units="1",
                       description="raw echo samples, channel 0, (azimuth line, range sample), as delivered",
                       chunks=echo_chunks(p.echo.shape), compression=filt, level=GZIP_LEVEL, dims=(t, r))
        if p.echo_channels is not None:
            ch = coordinate(f, "channel", np.arange(1, p.n_channels, dtype=np.int32), "1",
                            "receive channel index (0 is /echo)")
            dataset(f, "echo_channels", np.asarray(p.echo_channels, dtype=np.complex64), units="1",
                    description="further receive channels (channel, azimuth line, range sample)",
                    chunks=echo_chunks(p.echo_channels.shape), compression=filt, level=GZIP_LEVEL,
                    dims=(ch, t, r))
        g = write_radar(f, p.radar)
        if p.prf_per_line is not None:
            dataset(g, "prf_per_line", np.asarray(p.prf_per_line, np.float64), units="Hz",
                    description="pulse repetition frequency of each line", dims=(t,))
        if p.agc_db is not None:
            dataset(g, "agc_db", np.asarray(p.agc_db, np.float32), units="dB",
                    description="receiver attenuation per line; multiply by 10**(agc_db/20) to undo", dims=(t,))
        if p.replica is not None:
            rt = coordinate(g, "replica_time", np.arange(p.replica.size) / fs, "s",
                            "time of each replica sample from the replica's first sample")
            dataset(g, "replica", np.asarray(p.replica, np.complex64), units="1",
                    description="chirp replica at the range sampling rate", dims=(rt,))
        write_platform(f, p.orbit, p.attitude, p.epoch_utc)
        for name, arr in sorted(p.auxiliary.items()):
            dataset(f, f"auxiliary/{name}", arr, units=units_from_name(name.rsplit("/", 1)[-1]) or "1",
                    description=f"auxiliary array kept by the {p.source} reader (not focused)")
        if p.truth is not None:
            write_mapping(f, "truth", p.truth, p.epoch_utc)


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


def write_platform(f: h5py.Group, orbit: Orbit | None, attitude: Attitude | None, epoch_utc: str) -> None:
    """/orbit and /attitude groups (shared by the raw and SLC products), and for an Earth orbit (ECI or
    ECEF) /orbit_ecef: the same state vectors in WGS-84 ECEF (GMST rotation, ``orbit.frames``), laid
    out as ISCE3 loads an orbit group (``time`` with ``seconds since`` units, ``position``,
    ``velocity``, ``orbitType``, ``interpMethod``)."""
    from orbit.errors import OrbitError
    from orbit.statevectors import StateVectors

    tunits = cf_time_units(epoch_utc)
    if orbit is not None:
        og = group(f, "orbit")
        og.attrs["frame"] = orbit.frame
        og.attrs["description"] = f"platform state vectors as delivered, {orbit.frame} frame"
        t = coordinate(og, "time", np.asarray(orbit.time, np.float64), tunits, "time of each state vector")
        xyz = coordinate(og, "xyz", np.array([b"x", b"y", b"z"]), "1", "Cartesian component")
        dataset(og, "position", np.asarray(orbit.position, np.float64), units="m",
                description=f"platform position ({orbit.frame})", dims=(t, xyz))
        dataset(og, "velocity", np.asarray(orbit.velocity, np.float64), units="m/s",
                description=f"platform velocity ({orbit.frame})", dims=(t, xyz))
        if orbit.frame in ("ECI", "ECEF"):
            try:
                sv = StateVectors.from_record(orbit, epoch_utc).to_ecef()
            except OrbitError as e:
                raise ProductError(f"orbit: {e}") from None
            eg = group(f, "orbit_ecef")
            eg.attrs["frame"] = "ECEF"
            eg.attrs["description"] = ("the state vectors of /orbit in WGS-84 ECEF (ISCE3/NISAR orbit layout); "
                                       f"{'rotated from ECI of date by GMST' if orbit.frame == 'ECI' else 'a copy'}")
            et = coordinate(eg, "time", sv.time, tunits, "time of each state vector")
            exyz = coordinate(eg, "xyz", np.array([b"x", b"y", b"z"]), "1", "Cartesian component")
            dataset(eg, "position", sv.position, units="m", description="platform position (ECEF, WGS-84)",
                    dims=(et, exyz))
            dataset(eg, "velocity", sv.velocity, units="m/s", description="platform velocity (ECEF, WGS-84)",
                    dims=(et, exyz))
            dataset(eg, "orbitType", np.bytes_("Custom"), units="1", description="orbit product type (ISCE3)")
            dataset(eg, "interpMethod", np.bytes_("Hermite"), units="1", description="interpolation method (ISCE3)")
    if attitude is not None:
        ag = group(f, "attitude")
        ag.attrs["description"] = "platform attitude: total flight-frame pitch, roll, yaw (orbit.pointing)"
        t = coordinate(ag, "time", np.asarray(attitude.time, np.float64), tunits, "time of each attitude record")
        for name in ("pitch", "roll", "yaw"):
            dataset(ag, name, np.asarray(getattr(attitude, name), np.float64), units="rad",
                    description=f"{name} angle", dims=(t,))


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
        p.extra_attrs = _extra_attrs(f, set(PROVENANCE_ATTRS) | {"Conventions", "epoch_utc", "look_side", "source",
                                                                    "n_channels"},
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
