"""``sarcli ingest``: Radarsat-1 CEOS RAW or a Cumming & Wong MATLAB block -> raw product (HDF5)."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, require_output_folders
from sarcli.errors import SarcliError

F3_PULSES_KNOWN = (8, 9)  # the two published readings of beam F3's pulses in flight (ISCE, ASF MapReady)


def ingest(
    leader: Path = typer.Argument(None, help="CEOS leader file (LEA_01.001) or scene folder; or a "
                                "Sentinel-1 Level-0 .dat file or .SAFE folder."),
    data: Path = typer.Argument(None, help="CEOS signal data file (DAT_01.001); omit with a scene folder."),
    output: Path = typer.Option(..., "-o", "--output", help="Raw product to write (HDF5)."),
    matlab: Path = typer.Option(None, "--matlab", help="Cumming & Wong MATLAB raw block (.mat) instead of CEOS."),
    params: Path = typer.Option(None, "--params", help="Run-parameter .mat file that goes with --matlab."),
    epoch: str = typer.Option(None, "--epoch", help="MATLAB only: ISO-8601 UTC time of the first line."),
    keep_partial: bool = typer.Option(False, "--keep-partial",
                                      help="Keep the complete lines of a truncated data file."),
    missing: str = typer.Option("zero", "--missing",
                                help="Missing lines: zero (insert zero lines), repeat (previous line), keep."),
    max_gap: int = typer.Option(200, "--max-gap", help="Refuse gaps longer than this many lines (zero/repeat)."),
    f3_pulses: int = typer.Option(9, "--f3-pulses",
                                  help="Pulses in flight for beam F3 (9 per ASF MapReady, 8 per ISCE)."),
    compression: str = typer.Option(None, "--compression", help="HDF5 compression of the echo (gzip, lzf)."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Ingest Radarsat-1 CEOS RAW (leader + data, or a scene folder), a MATLAB block, or any single file
    or folder a sensor reader recognises (e.g. Sentinel-1 Level-0 packets: a .dat or a .SAFE folder).

    Nothing is written to the inputs. Missing lines are detected from the aux-block clock against the
    PRF and handled by --missing (reported); a truncated data file is refused unless --keep-partial.

    Examples:

      sarcli ingest demo/ceos -o raw.h5

      sarcli ingest SCENE01/LEA_01.001 SCENE01/DAT_01.001 -o raw.h5 --missing repeat

      sarcli ingest --matlab rs1_vancouver_block1.mat --params rs1_vancouver_run_params.mat -o van.h5

      sarcli ingest s1b-s3-raw-s-vv-20200615t162409.dat -o s3_vv.h5   (several data sets: -o FOLDER)
    """
    from sarcli.io.raw import write_raw

    if compression not in (None, "gzip", "lzf"):
        raise SarcliError(f"--compression must be gzip or lzf, got {compression!r}")
    require_output_folders(output)
    if max_gap < 0:
        raise SarcliError(f"--max-gap must be a number of lines >= 0, got {max_gap}")
    if f3_pulses not in F3_PULSES_KNOWN:
        raise SarcliError(f"--f3-pulses must be {' or '.join(map(str, F3_PULSES_KNOWN))} (pulses in flight of beam F3 "
                          f"per ISCE or ASF MapReady), got {f3_pulses}")
    if matlab is not None:
        if leader is not None or data is not None:
            raise SarcliError("give either CEOS files or --matlab/--params, not both")
        if params is None:
            raise SarcliError("--matlab needs --params PARAMS.mat (the run parameters of the extraction)")
        from sarcli.io.matlab import read_matlab_block

        raw = read_matlab_block(matlab, params, epoch_utc=epoch)
        inputs = (matlab, params)
        parameters = {"format": "matlab", "epoch": epoch}
    else:
        if leader is None:
            raise SarcliError("give LEADER DATA, a CEOS scene folder, or --matlab DATA.mat --params PARAMS.mat")
        if epoch is not None:
            raise SarcliError("--epoch applies to --matlab only (CEOS lines carry their own time)")
        if data is None and (leader.is_file() or leader.suffix.upper() == ".SAFE"):
            _ingest_with_reader(leader, output, keep_partial, compression, as_json)
            return
        from sarcli.io.ceos import find_scene_files, read_ceos

        lea, dat = find_scene_files(leader, data)
        raw = read_ceos(lea, dat, keep_partial=keep_partial, missing=missing, max_gap=max_gap,
                        f3_pulses_in_flight=f3_pulses)
        inputs = (lea, dat)
        parameters = {"format": "ceos", "keep_partial": keep_partial, "missing": missing, "max_gap": max_gap,
                      "f3_pulses_in_flight": f3_pulses}
        x = raw.extra_attrs
        if x["ceos_truncated"]:
            info(f"data file truncated: kept the {x['ceos_records_read']} complete lines of "
                 f"{x['ceos_records_declared']} declared")
        if x["ceos_missing_lines"]:
            info(f"{x['ceos_missing_lines']} missing lines in {len(x['ceos_gaps'])} gap(s): policy {missing}")
    write_raw(output, raw, parameters=parameters, inputs=inputs, compression=compression)
    n_lines, n_samples = raw.shape
    summary = {"output": str(output), "source": raw.source, "shape": [n_lines, n_samples],
               "prf_hz": raw.radar.prf_hz, "first_range_m": raw.radar.first_range_m,
               "azimuth_start_utc": raw.epoch_utc, "n_state_vectors": 0 if raw.orbit is None else raw.orbit.time.size}
    if raw.source == "ceos":
        x = raw.extra_attrs
        summary.update({"beam": x["ceos_beam_name"], "missing_lines": x["ceos_missing_lines"],
                        "missing_policy": x["ceos_missing_policy"], "truncated": x["ceos_truncated"],
                        "replica_lines": len(x["ceos_replica_lines"])})
    if as_json:
        emit_json(summary)
    else:
        info(f"wrote {output}: {n_lines} lines x {n_samples} samples ({raw.source}), "
             f"PRF {raw.radar.prf_hz:.3f} Hz, first range {raw.radar.first_range_m:.2f} m")


def _ingest_with_reader(source: Path, output: Path, keep_partial: bool, compression: str | None,
                        as_json: bool) -> None:
    """A single file or folder through the sensor-reader registry (sniffed); several data sets go to
    OUTPUT/NAME.h5 when OUTPUT is a folder."""
    import dataclasses

    from sarcli.io.raw import write_raw
    from sarcli.io.readers import find_reader
    from sarcli.workflows.base import refuse_overwriting_inputs

    reader = find_reader([source])
    names = {f.name for f in dataclasses.fields(reader.Options)}
    ingested = reader.read([source], reader.Options(**({"keep_partial": keep_partial} if "keep_partial" in names
                                                          else {})))
    if output.is_dir():
        targets = {name: output / f"{name or 'raw'}.h5" for name in ingested.products}
    elif len(ingested.products) > 1:
        raise SarcliError(f"{source} holds {len(ingested.products)} data sets ({', '.join(ingested.products)}): "
                          "give an existing folder as -o to write each to FOLDER/NAME.h5")
    else:
        targets = {name: output for name in ingested.products}
    refuse_overwriting_inputs(ingested.inputs, targets.values())
    summary = []
    for name, raw in ingested.products.items():
        write_raw(targets[name], raw, parameters={**ingested.parameters, "data_set": name}, inputs=ingested.inputs,
                  compression=compression)
        n_lines, n_samples = raw.shape
        summary.append({"output": str(targets[name]), "data_set": name, "source": raw.source,
                        "shape": [n_lines, n_samples], "prf_hz": raw.radar.prf_hz,
                        "first_range_m": raw.radar.first_range_m, "azimuth_start_utc": raw.epoch_utc,
                        "n_state_vectors": 0 if raw.orbit is None else raw.orbit.time.size})
    for note in ingested.notes:
        info(note)
    if as_json:
        emit_json(summary[0] if len(summary) == 1 else summary)
        return
    for s in summary:
        info(f"wrote {s['output']}: {s['data_set'] or 'raw'} {s['shape'][0]} lines x {s['shape'][1]} samples "
             f"({s['source']}), PRF {s['prf_hz']:.3f} Hz, first range {s['first_range_m']:.2f} m")


def register(app: typer.Typer) -> None:
    app.command("ingest")(ingest)
