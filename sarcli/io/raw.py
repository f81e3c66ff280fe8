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
    dataset,
    group,
    open_product,
    read_mapping,
    require,
    write_mapping,
)
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


def write_raw(path: str | os.PathLike, p: RawProduct, parameters: dict | None = None,
              inputs: tuple = (), compression: str | None = None) -> None:
    """Validate and write ``p`` atomically to ``path``."""
    _validate(p)
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
        standard = set(PROVENANCE_ATTRS) | {"epoch_utc", "look_side", "source", "n_channels"}
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
