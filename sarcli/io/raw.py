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
    attr_str,
    cf_time_units,
    coordinate,
    dataset,
    group,
    open_product,
    read_mapping,
    require,
    units_from_name,
    write_mapping,
)
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import Attitude, Orbit, Radar, RawProduct

PRODUCT_TYPE = "raw"
SCHEMA_VERSION = "1"
ORBIT_FRAMES = ("ECI", "ECEF", "LOCAL")


def _validate(p: RawProduct, where: str = "raw product") -> None:
    e = p.echo
    if e.ndim != 2 or e.shape[0] < 1 or e.shape[1] < 1:
        raise ProductError(f"{where}: echo must be a non-empty 2-D array, got shape {e.shape}")
    n_lines = e.shape[0]
    if p.azimuth_time.shape != (n_lines,):
        raise ProductError(f"{where}: azimuth_time has {p.azimuth_time.shape}, expected ({n_lines},)")
    if n_lines > 1 and not np.all(np.diff(p.azimuth_time) > 0):
        raise ProductError(f"{where}: azimuth times are not strictly increasing")
    r = p.radar
    for name in ("carrier_frequency_hz", "wavelength_m", "prf_hz", "range_sampling_rate_hz",
                 "pulse_length_s", "first_range_m"):
        v = getattr(r, name)
        if not (np.isfinite(v) and v > 0):
            raise ProductError(f"{where}: radar.{name} must be positive and finite, got {v}")
    if not np.isfinite(r.chirp_rate_hz_per_s) or r.chirp_rate_hz_per_s == 0:
        raise ProductError(f"{where}: radar.chirp_rate_hz_per_s must be non-zero and finite")
    if p.look_side not in ("right", "left"):
        raise ProductError(f"{where}: look_side must be 'right' or 'left', got {p.look_side!r}")
    for name in ("prf_per_line", "agc_db"):
        a = getattr(p, name)
        if a is not None and a.shape != (n_lines,):
            raise ProductError(f"{where}: {name} has shape {a.shape}, expected ({n_lines},)")
    if p.echo_channels is not None:
        if p.echo_channels.ndim != 3 or p.echo_channels.shape[1:] != e.shape:
            raise ProductError(f"{where}: echo_channels shape {p.echo_channels.shape} does not match echo")
        if len(r.receiver_offsets_m) != p.n_channels:
            raise ProductError(f"{where}: receiver_offsets_m needs {p.n_channels} values")
    if p.orbit is not None:
        o = p.orbit
        if o.frame not in ORBIT_FRAMES:
            raise ProductError(f"{where}: orbit frame {o.frame!r} is not one of {ORBIT_FRAMES}")
        n = o.time.shape[0]
        if o.time.ndim != 1 or o.position.shape != (n, 3) or o.velocity.shape != (n, 3):
            raise ProductError(f"{where}: orbit arrays must be (n,), (n,3), (n,3)")
        if not (np.all(np.isfinite(o.time)) and np.all(np.isfinite(o.position))
                and np.all(np.isfinite(o.velocity))):
            raise ProductError(f"{where}: orbit state vectors contain NaN or inf")


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
    """Validate and write ``p`` atomically to ``path`` (``compression``: one of :data:`COMPRESSIONS`,
    None = ``auto``)."""
    _validate(p)
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
    """Inverse of :func:`write_radar`; a missing required attribute is refused in one line."""
    kw: dict[str, Any] = {}
    for fld in dataclasses.fields(Radar):
        if fld.name in g.attrs:
            v = g.attrs[fld.name]
            if fld.name == "receiver_offsets_m":
                v = tuple(float(x) for x in np.atleast_1d(v))
            elif fld.name == "quantization_bits":
                v = int(v)
            else:
                v = float(v)
            kw[fld.name] = v
        elif fld.default is dataclasses.MISSING:
            raise ProductError(f"{path}: malformed product, radar attribute '{fld.name}' missing")
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
    """Inverse of :func:`write_platform` (missing groups -> None)."""
    orbit = attitude = None
    if "orbit" in f:
        og = f["orbit"]
        orbit = Orbit(require(og, "time", path)[()], require(og, "position", path)[()],
                      require(og, "velocity", path)[()], attr_str(og, "frame", "ECI"))
    if "attitude" in f:
        ag = f["attitude"]
        attitude = Attitude(*(require(ag, k, path)[()] for k in ("time", "pitch", "roll", "yaw")))
    return orbit, attitude


def read_raw(path: str | os.PathLike, load_echo: bool = True) -> RawProduct:
    """Read and validate a raw product; a malformed file raises :class:`ProductError` (one line).

    With ``load_echo=False`` the echo comes back as an empty (n_lines, 0) array and the metadata
    only; use :func:`read_raw_echo_block` to stream lines in bounded memory.
    """
    with open_product(path, PRODUCT_TYPE) as f:
        sv = attr_str(f, "schema_version")
        if sv != SCHEMA_VERSION:
            raise ProductError(f"{path}: raw schema version {sv} is not supported (expected {SCHEMA_VERSION})")
        echo_ds = require(f, "echo", path, shape_rank=2, dtype_kind="c")
        t = require(f, "azimuth_time", path, shape_rank=1, dtype_kind="f")[()]
        if "radar" not in f:
            raise ProductError(f"{path}: malformed product, missing 'radar'")
        g = f["radar"]
        radar = read_radar(g, path)
        echo = echo_ds[()] if load_echo else np.zeros((echo_ds.shape[0], 0), np.complex64)
        echo_channels = f["echo_channels"][()] if ("echo_channels" in f and load_echo) else None
        orbit, attitude = read_platform(f, path)
        truth = read_mapping(f["truth"]) if "truth" in f else None
        p = RawProduct(
            echo=echo, azimuth_time=t, epoch_utc=attr_str(f, "epoch_utc") or "", radar=radar,
            look_side=attr_str(f, "look_side", "right"), source=attr_str(f, "source", "unknown"),
            echo_channels=echo_channels,
            prf_per_line=g["prf_per_line"][()] if "prf_per_line" in g else None,
            agc_db=g["agc_db"][()] if "agc_db" in g else None,
            replica=g["replica"][()] if "replica" in g else None,
            orbit=orbit, attitude=attitude, truth=truth,
        )
        if "auxiliary" in f:
            f["auxiliary"].visititems(
                lambda name, obj: p.auxiliary.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        standard = set(PROVENANCE_ATTRS) | {"Conventions", "epoch_utc", "look_side", "source", "n_channels"}
        p.extra_attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()
                         if k not in standard}
        if not p.epoch_utc:
            raise ProductError(f"{path}: malformed product, epoch_utc missing")
        if load_echo:
            _validate(p, str(path))
        if load_echo and not np.all(np.isfinite(p.echo.view(np.float32))):
            raise ProductError(f"{path}: echo contains NaN or inf samples")
        return p


def read_raw_echo_block(path: str | os.PathLike, start: int, stop: int, channel: int = 0) -> np.ndarray:
    """Lines ``start:stop`` of one channel's echo, for block processing in bounded memory."""
    with open_product(path, PRODUCT_TYPE) as f:
        if channel == 0:
            return require(f, "echo", path, shape_rank=2)[start:stop]
        return f["echo_channels"][channel - 1, start:stop]


def raw_shape(path: str | os.PathLike) -> tuple[int, int]:
    """(n_lines, n_samples) without reading the echo."""
    with open_product(path, PRODUCT_TYPE) as f:
        return tuple(require(f, "echo", path, shape_rank=2).shape)  # type: ignore[return-value]
