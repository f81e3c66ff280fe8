"""Cumming & Wong MATLAB raw blocks -> :class:`RawProduct`.

Input: a MAT-file (v5, ``scipy.io.loadmat``) holding one complex array (``data`` by default; azimuth
along axis 0), as written by the extraction scripts distributed with Cumming & Wong (2005), and the
run-parameter MAT-file of the same extraction (``f0`` Hz, ``Fr`` Hz, ``Kr`` Hz/s (magnitude), ``Tr`` s,
``PRF`` Hz, ``R0`` m and the speed of light ``c`` the scripts used, 2.9979e8 m/s).

Conventions applied:

- chirp rate: the parameter file stores |Kr|; the book's processing scripts use a down-chirp, so the
  product gets ``-|Kr|`` unless ``chirp_sign=+1`` is asked for;
- window start: tau_0 = 2 R0 / c_scripts (6.5956 ms for Vancouver); ``first_range_m`` is recomputed
  with the exact c (988 662.1 m instead of the scripts' 988 647.46 m), so that range and time agree
  with the rest of sarcli; the published R0 is kept as ``published_first_range_m``;
- azimuth time n / PRF after ``epoch_utc``. A block carries no time of day: the epoch defaults to
  the acquisition date of the Cumming & Wong Vancouver scene (2002-06-16T00:00:00Z) and the root
  attribute ``epoch_note`` says that the time of day is unknown; pass ``epoch_utc`` to override;
- no orbit (there are no state vectors in a block): the product has no ``/orbit`` group and
  ``orbit_note`` says so;
- no AGC correction is known or applied (no ``agc_db``); ``quantization_bits`` is 4 when every sample
  is an odd level in -15..15, else 0;
- for the Vancouver scene (recognised from the parameter file: ``DAT_01.001``, 19432 x 9288 lines x
  cells, PRF 1256.98 Hz) the values the book's scripts use are stored as root attributes prefixed
  ``published_`` (effective velocity 7062 m/s, azimuth FM rate 1733 Hz/s, Doppler centroid -6900 Hz
  "as given with the data"), with ``published_note``: they are published inputs, not measured here.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io

from orbit.timeutil import format_utc, parse_utc
from sarcli.errors import FormatError
from sarcli.io.ceos.radarsat1.samples import is_four_bit
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import Radar, RawProduct

DEFAULT_EPOCH_UTC = "2002-06-16T00:00:00.000000Z"
VANCOUVER_PUBLISHED = {
    "published_effective_velocity_mps": 7062.0,
    "published_azimuth_fm_rate_hz_per_s": 1733.0,
    "published_doppler_centroid_hz": -6900.0,
    "published_window_start_s": 6.5956e-3,
    "published_note": ("values used by the Cumming & Wong (2005) processing scripts for the Vancouver "
                       "scene (Vr, Ka magnitude, Doppler centroid 'as given with the data'); published, "
                       "not measured on this block"),
}
_REQUIRED = ("f0", "Fr", "Kr", "Tr", "PRF", "R0", "c")


def _load(path: Path, what: str) -> dict[str, Any]:
    if not path.is_file():
        raise FormatError(f"{path}: no such file")
    try:
        return scipy.io.loadmat(path, squeeze_me=True)
    except NotImplementedError:
        raise FormatError(f"{path}: MATLAB v7.3 (HDF5) {what} files are not supported; save with -v7") from None
    except (scipy.io.matlab.MatReadError, ValueError, TypeError, OSError, EOFError) as e:
        raise FormatError(f"{path}: not a readable MATLAB {what} file ({e})") from None


def _scalar(params: dict, key: str, path: Path) -> float:
    v = np.asarray(params[key])
    if v.size != 1 or not np.issubdtype(v.dtype, np.number):
        raise FormatError(f"{path}: parameter '{key}' is not a number")
    x = float(v.ravel()[0])
    if not np.isfinite(x) or x == 0:
        raise FormatError(f"{path}: parameter '{key}' = {x} is not usable")
    return x


def _is_vancouver(params: dict) -> bool:
    def get(k):
        v = params.get(k)
        return None if v is None else np.asarray(v).ravel()

    name = get("CD_data_file_name")
    lines, cells, prf = get("tot_Nrg_lines"), get("tot_Nrg_cells"), get("PRF")
    return (name is not None and str(name[0]).upper() == "DAT_01.001" and lines is not None
            and int(lines[0]) == 19432 and cells is not None and int(cells[0]) == 9288
            and prf is not None and abs(float(prf[0]) - 1256.98) < 0.01)


def read_matlab_block(data_path: str | os.PathLike, params_path: str | os.PathLike, variable: str | None = None,
                      epoch_utc: str | None = None, chirp_sign: int = -1) -> RawProduct:
    """Read a Cumming & Wong raw block and its run parameters into a RawProduct (module docstring)."""
    data_path, params_path = Path(data_path), Path(params_path)
    if chirp_sign not in (-1, 1):
        raise FormatError(f"chirp sign must be -1 or +1, got {chirp_sign}")
    params = _load(params_path, "parameter")
    missing = [k for k in _REQUIRED if k not in params]
    if missing:
        raise FormatError(f"{params_path}: parameter file lacks {', '.join(missing)} (not a Cumming & Wong "
                          "run-parameter file?)")
    mat = _load(data_path, "data")
    names = [k for k in mat if not k.startswith("__")]
    name = variable or ("data" if "data" in names else (names[0] if len(names) == 1 else None))
    if name is None or name not in mat:
        raise FormatError(f"{data_path}: no variable {'data' if variable is None else variable!r} "
                          f"(variables: {', '.join(names) or 'none'})")
    echo = np.asarray(mat[name])
    if echo.ndim != 2 or not np.issubdtype(echo.dtype, np.number):
        raise FormatError(f"{data_path}: variable '{name}' is not a 2-D numeric array (shape {echo.shape})")
    echo = np.ascontiguousarray(echo, dtype=np.complex64)
    if not np.all(np.isfinite(echo.view(np.float32))):
        raise FormatError(f"{data_path}: variable '{name}' contains NaN or inf")

    f0, fs, kr = (_scalar(params, k, params_path) for k in ("f0", "Fr", "Kr"))
    tr, prf, r0, c_scripts = (_scalar(params, k, params_path) for k in ("Tr", "PRF", "R0", "c"))
    tau0 = 2.0 * r0 / c_scripts
    try:
        epoch = format_utc(parse_utc(epoch_utc)) if epoch_utc else DEFAULT_EPOCH_UTC
    except ValueError as e:
        raise FormatError(str(e)) from None
    radar = Radar(
        carrier_frequency_hz=f0, wavelength_m=C_LIGHT / f0, prf_hz=prf, range_sampling_rate_hz=fs,
        chirp_rate_hz_per_s=chirp_sign * abs(kr), pulse_length_s=tr, window_start_s=tau0,
        first_range_m=C_LIGHT * tau0 / 2.0, quantization_bits=4 if is_four_bit(echo) else 0)
    extra: dict[str, Any] = {
        "orbit_note": "no state vectors: a Cumming & Wong MATLAB block carries no orbit",
        "epoch_note": ("given by the user" if epoch_utc else
                       "date of the Cumming & Wong Vancouver scene; time of day unknown"),
        "published_first_range_m": r0, "published_speed_of_light_mps": c_scripts,
        "matlab_variable": name, "chirp_sign_note": (
            "down-chirp as in the book's scripts (parameter file stores |Kr|)" if chirp_sign < 0
            else "up-chirp requested by the user (parameter file stores |Kr|)"),
    }
    if _is_vancouver(params):
        extra.update(VANCOUVER_PUBLISHED)
    return RawProduct(echo=echo, azimuth_time=np.arange(echo.shape[0]) / prf, epoch_utc=epoch, radar=radar,
                      source="matlab", extra_attrs=extra)
