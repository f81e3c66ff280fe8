"""``sarcli ingest``: raw data in a sensor's format (found by sniffing) -> raw product(s) (HDF5)."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, parse_option_values, print_status, run_workflow
from sarcli.errors import ConfigError


def ingest(
    sources: list[Path] = typer.Argument(None, metavar="INPUT...",
                                         help="A CEOS scene folder, LEADER DATA, DATA.mat PARAMS.mat, a Sentinel-1 "
                                              "Level-0 .dat file or .SAFE folder, or any input a sensor reader "
                                              "recognises."),
    output: Path = typer.Option(..., "-o", "--output",
                                help="Raw product to write (HDF5). Several data sets in the input: a folder "
                                     "(NAME.h5 each), or STEM.h5 for STEM_NAME.h5 files."),
    fmt: str = typer.Option(None, "--format", help="Reader to use instead of sniffing (ceos-rs1, matlab-cw, ...)."),
    option: list[str] = typer.Option(None, "--option", metavar="KEY=VALUE",
                                     help="A reader option (repeatable), e.g. --option missing=repeat."),
    matlab: Path = typer.Option(None, "--matlab", help="Cumming & Wong MATLAB raw block (.mat): --format matlab-cw."),
    params: Path = typer.Option(None, "--params", help="Run-parameter .mat file that goes with --matlab."),
    epoch: str = typer.Option(None, "--epoch", help="MATLAB only: ISO-8601 UTC time of line 1 of the pass."),
    agc: Path = typer.Option(None, "--agc", help="MATLAB only: the pass's AGC table (AGC_attenuation_values.mat); "
                                                 "its attenuation is stored per line and undone by the processing."),
    orbit: Path = typer.Option(None, "--orbit", metavar="FILE",
                               help="MATLAB only: the pass's state vectors (CSV: time_utc,x,y,z,vx,vy,vz in m and "
                                    "m/s, Earth-fixed; or an ESA orbit file, .EOF); needs --epoch."),
    first_line: str = typer.Option(None, "--first-line", metavar="N|auto",
                                   help="MATLAB only: the block's first line in the pass (1-based; default: the "
                                        "params file's first_rg_line; auto: found from the line power vs --agc)."),
    first_cell: int = typer.Option(None, "--first-cell",
                                   help="MATLAB only: the block's first range cell (1-based; default: first_rg_cell)."),
    keep_partial: bool = typer.Option(False, "--keep-partial",
                                      help="CEOS: keep the complete lines of a truncated data file; Sentinel-1: "
                                           "drop a trailing partial packet."),
    missing: str = typer.Option(None, "--missing",
                                help="CEOS missing lines: zero (insert zero lines, default), repeat (previous "
                                     "line), keep."),
    max_gap: int = typer.Option(None, "--max-gap",
                                help="CEOS: refuse gaps longer than this many lines (zero/repeat; default 200)."),
    f3_pulses: int = typer.Option(None, "--f3-pulses",
                                  help="CEOS: pulses in flight for beam F3 (9 per ASF MapReady, default; 8 per ISCE)."),
    compression: str = typer.Option(None, "--compression", metavar="[auto|gzip|lzf|none]",
                                   help="HDF5 compression of the echo: auto = shuffle + gzip where it pays "
                                        "(quantized echoes)."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Ingest raw data: the sensor reader is found by sniffing the input (or named with --format).

    Readers: ceos-rs1 (Radarsat-1 CEOS RAW: a scene folder, or LEADER DATA), matlab-cw (a Cumming & Wong
    MATLAB block: DATA.mat PARAMS.mat), sentinel1-l0 (Sentinel-1 Level-0 packets: a measurement .dat
    file or a .SAFE folder), and any installed plug-in. Several data sets in one input (swaths,
    polarizations): one product each, in the folder -o, or STEM_NAME.h5 for -o STEM.h5. Reader
    options: --option KEY=VALUE; --keep-partial (CEOS, Sentinel-1), --missing, --max-gap, --f3-pulses
    (CEOS) and --epoch, --agc, --orbit, --first-line, --first-cell (MATLAB) are shortcuts. A MATLAB block is placed
    in its pass (azimuth time from the start line, near range from the start cell); with --agc the
    start line is checked against the table (a contradicted one is refused, naming the line that fits).
    Nothing is written to the inputs. CEOS: missing lines are found from the aux-block clock against
    the PRF and handled by --missing (reported); a truncated data file is refused unless --keep-partial.

    Examples:

      sarcli ingest demo/ceos -o raw.h5

      sarcli ingest SCENE01/LEA_01.001 SCENE01/DAT_01.001 -o raw.h5 --missing repeat

      sarcli ingest rs1_vancouver_block1.mat rs1_vancouver_run_params.mat -o van.h5 --epoch 2002-06-16T14:50:00Z

      sarcli ingest --matlab rs1_vancouver_block1.mat --params rs1_vancouver_run_params.mat -o van.h5

      sarcli ingest --matlab squamish_garibaldi.mat --params squamish_garibaldi_run_params.mat
      --agc AGC_attenuation_values.mat -o squamish.h5

      sarcli ingest --matlab rs1_vancouver_block1.mat --params rs1_vancouver_run_params.mat
      --agc AGC_attenuation_values.mat --first-line auto --first-cell 1050 -o van.h5

      sarcli ingest --matlab block.mat --params run_params.mat --epoch UTC_OF_LINE_1
      --orbit orbit.csv -o block.h5   (an orbit: the block can be geocoded)

      sarcli ingest demo/ceos --format ceos-rs1 --option max_gap=50 -o raw.h5 --json

      sarcli ingest s1b-s3-raw-s-vv-20200615t162409.dat -o s3   (several data sets: s3/S3_VV_1.h5, ...)
    """
    sources = list(sources or [])
    if matlab is not None:
        if sources:
            raise ConfigError("give either the input files or --matlab/--params, not both")
        if params is None:
            raise ConfigError("--matlab needs --params PARAMS.mat (the run parameters of the extraction)")
        if fmt not in (None, "matlab-cw"):
            raise ConfigError(f"--matlab reads a MATLAB block (--format matlab-cw), not {fmt}")
        sources, fmt = [matlab, params], "matlab-cw"
    elif params is not None:
        raise ConfigError("--params goes with --matlab DATA.mat")
    options = parse_option_values(option or [])
    if first_line is not None and first_line != "auto":
        if not first_line.isdigit():
            raise ConfigError(f"--first-line must be a line number or auto, got {first_line!r}")
        first_line = int(first_line)
    sugar = {"keep_partial": keep_partial or None, "missing": missing, "max_gap": max_gap, "f3_pulses": f3_pulses,
             "epoch": epoch, "agc": None if agc is None else str(agc),
             "orbit": None if orbit is None else str(orbit), "first_line": first_line,
             "first_cell": first_cell}
    for key, value in sugar.items():
        if value is not None:
            if key in options:
                raise ConfigError(f"--{key.replace('_', '-')} and --option {key}=... both given: choose one")
            options[key] = value
    report = run_workflow("ingest", {"sources": sources, "output": output, "format": fmt, "options": options,
                                     "compression": compression},
                          flags={**{k: f"--{k.replace('_', '-')}" for k in sugar}, "format": "--format"})
    for note in report.notes:
        info(note)
    if as_json:
        emit_json(report.to_dict())
    else:
        print_status(report)


def register(app: typer.Typer) -> None:
    app.command("ingest")(ingest)
