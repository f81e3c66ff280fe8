"""``sarcli simulate``: scene TOML -> raw echo product (HDF5) or a Radarsat-1 CEOS leader + data pair."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, print_status, run_workflow


def simulate(
    scene: Path = typer.Argument(..., help="Scene file (TOML): radar, antenna, platform, targets, effects."),
    output: Path = typer.Option(..., "-o", "--output", help="Raw product (HDF5) or, with --format ceos, a folder."),
    fmt: str = typer.Option("hdf5", "--format", metavar="[hdf5|ceos|s1-l0]",
                            help="hdf5 (raw product), ceos (Radarsat-1 leader + data) or s1-l0 "
                      "(Sentinel-1 Level-0 packets; needs a Sentinel-1 sampling rate, e.g. samples/s1_stripmap.toml)."),
    compression: str = typer.Option(None, "--compression", metavar="[auto|gzip|lzf|none]",
                                   help="HDF5 compression of the echo: auto = shuffle + gzip where it pays "
                                        "(quantized echoes)."),
    seed: int = typer.Option(None, "--seed", min=0, help="Override the scene's seed (Monte-Carlo runs)."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Simulate the raw echoes of a stripmap scene; only the effects the scene lists are computed.

    Known effects: range_migration, earth_rotation, attitude, antenna_pattern, noise, quantization,
    chirp_replica, second_channel, target_motion. The truth (targets, Doppler centroid and rate per
    range sample) goes to /truth. Deterministic: the seed is part of the scene; with SOURCE_DATE_EPOCH
    set the HDF5 file is byte-identical between runs.

    Examples:

      sarcli simulate samples/rs1_point.toml -o raw.h5

      sarcli simulate samples/rs1_point.toml --format ceos -o demo/ceos

      sarcli simulate samples/s1_stripmap.toml --format s1-l0 -o s1.dat

      sarcli simulate samples/ati_paper.toml -o ati.h5 --json

      sarcli simulate samples/ati_paper.toml -o ati_run7.h5 --seed 7
    """
    report = run_workflow("simulate", {"scene": scene, "output": output, "format": fmt, "compression": compression,
                                       "seed": seed})
    print_status(report)
    if as_json:
        emit_json(report.to_dict())


def register(app: typer.Typer) -> None:
    app.command("simulate")(simulate)
