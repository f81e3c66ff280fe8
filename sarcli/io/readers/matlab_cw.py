"""Reader plug-in ``matlab-cw``: a Cumming & Wong MATLAB raw block and its run-parameter file.

Decoding is in :mod:`sarcli.io.matlab`; this adapts it to the reader interface (:mod:`sarcli.io.readers`).
Sources: ``DATA.mat PARAMS.mat`` (or ``--matlab DATA.mat --params PARAMS.mat`` on the command line), or a
folder holding exactly these two MAT files (the run-parameter file is the one with ``f0``, ``Fr``, ``Kr``,
``Tr``, ``PRF``, ``R0``, ``c``: a block is one scene of ``sarcli batch``);
the pass's AGC table is an option (``agc``, ``--agc TABLE.mat``), and so is an orbit (``orbit``,
``--orbit FILE``: state vectors as CSV or an ESA orbit file, :mod:`sarcli.io.orbit_file`; with the time of
line 1 of the pass, ``epoch``, since a block carries no time of day).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.io.readers import Ingested


@dataclass(frozen=True)
class MatlabOptions:
    """epoch: ISO-8601 UTC time of line 1 of the pass (a block carries none); variable: the array's name
    in the data file (default ``data``, or the only variable); agc: the pass's receiver-attenuation
    table (MAT file, ``nom_attenuation`` dB per line); first_line: the block's first line in the pass
    (1-based; default the parameter file's ``first_rg_line``; ``"auto"``: found from the line power
    against ``agc``); first_cell: its first range cell (1-based; default ``first_rg_cell``); orbit: a
    state-vector file (CSV or ESA orbit file, Earth-fixed) covering the block: needs ``epoch``."""

    epoch: str | None = None
    variable: str | None = None
    agc: Path | None = None
    first_line: int | Literal["auto"] | None = None
    first_cell: int | None = None
    orbit: Path | None = None


def _is_mat(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(10).startswith(b"MATLAB 5.0")


def _pair(folder: Path) -> tuple[Path, Path] | None:
    """(block, run parameters) of a folder holding exactly two MAT files, one of them a run-parameter
    file; None otherwise."""
    import scipy.io

    from sarcli.io.matlab import REQUIRED_PARAMS

    mats = sorted(p for p in folder.iterdir() if p.is_file() and not p.name.startswith("."))
    if len(mats) != 2 or not all(_is_mat(p) for p in mats):
        return None
    is_params = [set(REQUIRED_PARAMS) <= {name for name, _, _ in scipy.io.whosmat(p)} for p in mats]
    if is_params.count(True) != 1:
        return None
    return (mats[1], mats[0]) if is_params[0] else (mats[0], mats[1])


def _notes(attrs: dict, n_lines: int) -> list[str]:
    """What the user must know about the placement and the attenuation (one line each)."""
    line, cell = attrs["pass_first_line"], attrs["pass_first_cell"]
    notes = [f"block placed at line {line} ({attrs['placement_lines_source']}) and cell {cell} "
             f"({attrs['placement_cells_source']}) of the pass"]
    if "agc_start_check" in attrs:
        check = attrs["agc_start_check"]
        z = attrs["agc_start_z"]
        if check == "confirmed":
            notes.append(f"AGC table applied to lines {line}-{line + n_lines - 1}: the line power steps where the "
                         f"table does (z = {z:.1f}, next best start {attrs['agc_next_best_z']:.1f})")
        else:
            notes.append(f"AGC table applied to lines {line}-{line + n_lines - 1}; the line power cannot confirm the "
                         f"start line (z = {z:.1f}, best {attrs['agc_best_z']:.1f} at line {attrs['agc_best_line']})")
    return notes


def _attach_orbit(raw, path: Path) -> None:
    """The file's state vectors as the block's orbit, refused unless they span the block's lines."""
    from orbit.timeutil import add_seconds
    from sarcli.io.orbit_file import read_orbit_file

    orbit = read_orbit_file(path, raw.epoch_utc)
    t0, t1 = float(raw.azimuth_time[0]), float(raw.azimuth_time[-1])
    if t0 < orbit.time[0] or t1 > orbit.time[-1]:
        raise ConfigError(f"{path}: the state vectors span {add_seconds(raw.epoch_utc, orbit.time[0])} .. "
                          f"{add_seconds(raw.epoch_utc, orbit.time[-1])}, the block "
                          f"{add_seconds(raw.epoch_utc, t0)} .. {add_seconds(raw.epoch_utc, t1)}: another pass's "
                          "file, or a wrong epoch")
    raw.orbit = orbit
    raw.extra_attrs["orbit_note"] = f"state vectors from {path.name} ({orbit.time.size}, Earth-fixed)"


class MatlabCwReader:
    name = "matlab-cw"
    description = "Cumming & Wong MATLAB raw block: DATA.mat PARAMS.mat (option agc: the pass's AGC table)"
    Options = MatlabOptions

    def sniff(self, sources: Sequence[Path]) -> bool:
        if len(sources) == 1 and Path(sources[0]).is_dir():
            return _pair(Path(sources[0])) is not None
        return len(sources) == 2 and all(Path(s).is_file() and _is_mat(Path(s)) for s in sources)

    def read(self, sources: Sequence[Path], options: MatlabOptions) -> Ingested:
        from sarcli.io.matlab import read_matlab_block

        if len(sources) == 1 and Path(sources[0]).is_dir():
            pair = _pair(Path(sources[0]))
            if pair is None:
                raise ConfigError(f"{sources[0]}: a MATLAB block folder holds two MAT files, the block and its run "
                                  "parameters (f0, Fr, Kr, Tr, PRF, R0, c)")
            sources = pair
        if len(sources) != 2:
            raise ConfigError("a MATLAB block needs two files: DATA.mat PARAMS.mat")
        data, params = (Path(s) for s in sources)
        if options.orbit is not None and options.epoch is None:
            raise ConfigError("an orbit needs the epoch (--epoch, option epoch: the UTC time of line 1 of the "
                              "pass): a MATLAB block carries no time of day to place it on the orbit")
        raw = read_matlab_block(data, params, variable=options.variable, epoch_utc=options.epoch,
                                agc_path=options.agc, first_line=options.first_line, first_cell=options.first_cell)
        if options.orbit is not None:
            _attach_orbit(raw, Path(options.orbit))
        inputs = ((data, params) + (() if options.agc is None else (Path(options.agc),))
                  + (() if options.orbit is None else (Path(options.orbit),)))
        a = raw.extra_attrs
        summary = {k: a[k] for k in ("pass_first_line", "pass_first_cell", "agc_start_check", "agc_start_z",
                                     "agc_best_line", "agc_output_db_per_input_db") if k in a}
        return Ingested({"": raw}, inputs, {"format": self.name, **to_mapping(options)},
                        _notes(a, raw.shape[0]), {"": summary})


READER = MatlabCwReader()
