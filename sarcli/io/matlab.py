"""Cumming & Wong MATLAB raw blocks -> :class:`RawProduct`.

Input: a MAT-file (v5, ``scipy.io.loadmat``) holding one complex array (``data`` by default; azimuth
along axis 0), as written by the extraction scripts distributed with Cumming & Wong (2005), and the
run-parameter MAT-file of the same extraction (``f0`` Hz, ``Fr`` Hz, ``Kr`` Hz/s (magnitude), ``Tr`` s,
``PRF`` Hz, ``R0`` m and the speed of light ``c`` the scripts used, 2.9979e8 m/s).

Conventions applied:

- chirp rate: the parameter file stores |Kr|; the book's processing scripts use a down-chirp, so the
  product gets ``-|Kr|`` unless ``chirp_sign=+1`` is asked for;
- window start: tau_0 = 2 R0 / c_scripts (6.5956 ms for Vancouver); ``first_range_m`` is recomputed
  with the exact c (988 655.6 m instead of the scripts' 988 647.46 m for cell 1), so that range and time agree
  with the rest of sarcli; the published R0 is kept as ``published_first_range_m``;
- placement in the pass. The run-parameter file says where the block starts in the scene's data file:
  ``first_rg_line`` (1-based line L) and ``first_rg_cell`` (1-based cell K); ``first_line`` /
  ``first_cell`` override them (a file without them: line 1, cell 1). The scripts' R0 is the range of
  cell 1 (``R0 = 0.0065956 c / 2``, "slant range of first radar sample" in the book's
  ``specify_parameters.m``), so the block's window starts at tau_0 = 2 R0 / c_scripts + (K - 1) / Fr
  and ``first_range_m`` = c tau_0 / 2; line n of the block (0-based) has the azimuth time
  (L - 1 + n) / PRF after ``epoch_utc``, so blocks of one pass share one time axis. A block carries no
  time of day: the epoch (the time of line 1 of the pass) defaults to the acquisition date of the
  Cumming & Wong Vancouver scene (2002-06-16T00:00:00Z) and the root attribute ``epoch_note`` says that
  the time of day is unknown; pass ``epoch_utc`` to override;
- receiver attenuation: with the pass's AGC table (``agc_path``, :mod:`sarcli.io.agc_table`) the
  block's lines get ``agc_db = table[L - 1 : L - 1 + N]`` (undone by the processing as
  10**(agc_db / 20) per line). The start line is checked against the table first: the block's
  single-line power jumps must fall where the table steps (matched-filter z, :func:`~sarcli.io.agc_table.align`);
  a start line the table contradicts is refused in one line naming the line the table does match,
  and ``first_line = "auto"`` takes the start from the table. Without a table there is no ``agc_db``;
- no orbit (there are no state vectors in a block): the product has no ``/orbit`` group and
  ``orbit_note`` says so;
- ``quantization_bits`` is 4 when every sample is an odd level in -15..15, else 0;
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
from sarcli.errors import ConfigError, FormatError, MissingFileError
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
REQUIRED_PARAMS = ("f0", "Fr", "Kr", "Tr", "PRF", "R0", "c")


def _load(path: Path, what: str) -> dict[str, Any]:
    if not path.is_file():
        raise MissingFileError(f"{path}: no such file")
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


def _param_int(params: dict, key: str, path: Path) -> int | None:
    """An optional integer entry of the parameter file (None when absent)."""
    if key not in params:
        return None
    v = np.asarray(params[key]).ravel()
    if v.size != 1 or not np.issubdtype(v.dtype, np.number) or not float(v[0]).is_integer() or v[0] < 1:
        raise FormatError(f"{path}: parameter '{key}' is not a positive integer")
    return int(v[0])


def _place_lines(echo: np.ndarray, params: dict, params_path: Path, first_line: int | str | None,
                 agc_path: Path | None, extra: dict[str, Any]) -> tuple[int, np.ndarray | None]:
    """The block's first line in the pass (1-based) and its attenuation (dB per line, None without a
    table), after checking the start line against the table (module docstring). Facts go to ``extra``."""
    from sarcli.io import agc_table

    n = echo.shape[0]
    from_file = _param_int(params, "first_rg_line", params_path)
    if isinstance(first_line, int):
        line, source = first_line, "user"
    elif from_file is not None and first_line is None:
        line, source = from_file, "run-parameter file"
    else:  # no start line in the file, or "auto" (decided below from the table)
        line, source = 1, "default"
    total = _param_int(params, "tot_Nrg_lines", params_path)
    if agc_path is None:
        if total is not None and line + n - 1 > total:
            raise FormatError(f"a block of {n} lines starting at line {line} runs past the {total} lines of the scene")
        extra.update(pass_first_line=line, placement_lines_source=source)
        return line, None
    table = agc_table.read_agc_table(agc_path)
    if total is not None and table.size != total:
        raise FormatError(f"{agc_path}: the AGC table has {table.size} lines, the scene {total} "
                          f"(tot_Nrg_lines of {params_path.name}): not the same pass")
    al = agc_table.align(echo, table)
    best = al.best
    if first_line == "auto":
        found = agc_table.best_start(al)
        if found is None:
            raise FormatError(f"{agc_path}: the block's line power does not single out a start line in the AGC table "
                              f"(best line {best + 1}, z = {al.z[best]:.1f}, next best {al.runner_up(best):.1f}; "
                              f"needs z >= {agc_table.Z_MATCH:g} and twice the next): give first_line")
        line, source = found + 1, "AGC table"
    if line + n - 1 > table.size:
        raise FormatError(f"a block of {n} lines starting at line {line} runs past the {table.size} lines of the "
                          "AGC table")
    verdict = agc_table.check_start(al, line - 1)
    if verdict == "contradicted":
        given = "first_rg_line of " + params_path.name if source == "run-parameter file" else "first_line"
        raise FormatError(f"{agc_path.name}: the block's line power does not follow the AGC table at line {line} "
                          f"({given}; z = {al.z[line - 1]:.1f}) but at line {best + 1} (z = {al.z[best]:.1f}, "
                          f"log likelihood ratio {al.log_likelihood_ratio(best, line - 1):.0f}): "
                          f"give first_line={best + 1} (--first-line {best + 1}) or first_line=auto")
    extra.update(pass_first_line=line, placement_lines_source=source, agc_table_file=agc_path.name,
                 agc_start_check=verdict, agc_start_z=float(al.z[line - 1]),
                 agc_best_line=best + 1, agc_best_z=float(al.z[best]),
                 agc_next_best_z=float(al.runner_up(line - 1)),
                 agc_output_db_per_input_db=float(al.gain[line - 1]), agc_line_power_sigma_db=al.sigma_db)
    return line, table[line - 1:line - 1 + n]


def read_matlab_block(data_path: str | os.PathLike, params_path: str | os.PathLike, variable: str | None = None,
                      epoch_utc: str | None = None, chirp_sign: int = -1, agc_path: str | os.PathLike | None = None,
                      first_line: int | str | None = None, first_cell: int | None = None) -> RawProduct:
    """Read a Cumming & Wong raw block and its run parameters into a RawProduct (module docstring).

    ``agc_path``: the pass's attenuation table; ``first_line`` (1-based, or "auto": from the table) and
    ``first_cell`` (1-based) override the parameter file's ``first_rg_line`` / ``first_rg_cell``."""
    data_path, params_path = Path(data_path), Path(params_path)
    if chirp_sign not in (-1, 1):
        raise FormatError(f"chirp sign must be -1 or +1, got {chirp_sign}")
    if first_cell is not None and first_cell < 1:
        raise ConfigError(f"first_cell must be a cell number >= 1 (1-based), got {first_cell}")
    if first_line != "auto" and first_line is not None and not (isinstance(first_line, int) and first_line >= 1):
        raise ConfigError(f"first_line must be a line number >= 1 (1-based) or 'auto', got {first_line!r}")
    if first_line == "auto" and agc_path is None:
        raise ConfigError("first_line=auto finds the start line from the AGC table: give the table (agc, --agc)")
    params = _load(params_path, "parameter")
    missing = [k for k in REQUIRED_PARAMS if k not in params]
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
    try:
        epoch = format_utc(parse_utc(epoch_utc)) if epoch_utc else DEFAULT_EPOCH_UTC
    except ValueError as e:
        raise FormatError(str(e)) from None
    extra: dict[str, Any] = {}
    line, agc = _place_lines(echo, params, params_path, first_line, None if agc_path is None else Path(agc_path), extra)
    cell_file = _param_int(params, "first_rg_cell", params_path)
    cell, cell_source = ((first_cell, "user") if first_cell is not None else
                         (cell_file, "run-parameter file") if cell_file is not None else (1, "default"))
    total_cells = _param_int(params, "tot_Nrg_cells", params_path)
    if total_cells is not None and cell + echo.shape[1] - 1 > total_cells:
        raise FormatError(f"a block of {echo.shape[1]} cells starting at cell {cell} runs past the {total_cells} cells "
                          "of the scene")
    tau0 = 2.0 * r0 / c_scripts + (cell - 1) / fs
    radar = Radar(
        carrier_frequency_hz=f0, wavelength_m=C_LIGHT / f0, prf_hz=prf, range_sampling_rate_hz=fs,
        chirp_rate_hz_per_s=chirp_sign * abs(kr), pulse_length_s=tr, window_start_s=tau0,
        first_range_m=C_LIGHT * tau0 / 2.0, quantization_bits=4 if is_four_bit(echo) else 0)
    extra.update({
        "pass_first_cell": cell, "placement_cells_source": cell_source,
        "orbit_note": "no state vectors: a Cumming & Wong MATLAB block carries no orbit",
        "epoch_note": ("given by the user (time of line 1 of the pass)" if epoch_utc else
                       "date of the Cumming & Wong Vancouver scene, time of line 1 of the pass; time of day unknown"),
        "published_first_range_m": r0, "published_speed_of_light_mps": c_scripts,
        "matlab_variable": name, "chirp_sign_note": (
            "down-chirp as in the book's scripts (parameter file stores |Kr|)" if chirp_sign < 0
            else "up-chirp requested by the user (parameter file stores |Kr|)"),
    })
    if _is_vancouver(params):
        extra.update(VANCOUVER_PUBLISHED)
    t = (line - 1 + np.arange(echo.shape[0])) / prf
    return RawProduct(echo=echo, azimuth_time=t, epoch_utc=epoch, radar=radar, source="matlab",
                      agc_db=None if agc is None else agc.astype(np.float32), extra_attrs=extra)
