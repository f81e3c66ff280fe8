"""``sarcli simulate``: scene TOML -> raw echo product (HDF5) or a Radarsat-1 CEOS leader + data pair."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress_bar, require_output_folders
from sarcli.errors import SarcliError


def simulate(
    scene: Path = typer.Argument(..., help="Scene file (TOML): radar, antenna, platform, targets, effects."),
    output: Path = typer.Option(..., "-o", "--output", help="Raw product (HDF5) or, with --format ceos, a folder."),
    fmt: str = typer.Option("hdf5", "--format", help="hdf5 (raw product) or ceos (Radarsat-1 leader + data)."),
    compression: str = typer.Option(None, "--compression", help="HDF5 compression of the echo (gzip, lzf)."),
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

      sarcli simulate samples/ati_paper.toml -o ati.h5 --json

      sarcli simulate samples/ati_paper.toml -o ati_run7.h5 --seed 7
    """
    import time

    from sarcli.io.raw import write_raw
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate as run

    if fmt not in ("hdf5", "ceos"):
        raise SarcliError(f"--format must be hdf5 or ceos, got {fmt!r}")
    if compression not in (None, "gzip", "lzf"):
        raise SarcliError(f"--compression must be gzip or lzf, got {compression!r}")
    require_output_folders(output)
    if output.is_dir() and fmt == "hdf5":
        raise SarcliError(f"{output} is a folder: give a file name for the raw product (or --format ceos)")
    sc = load_scene(scene)
    if seed is not None:
        sc.seed = seed
    if fmt == "ceos":
        _check_ceos_scene(sc)
    effects = ", ".join(sc.effects) or "none"
    info(f"simulating {sc.name}: {sc.radar.n_lines} x {sc.radar.n_samples} samples, {len(sc.targets)} target(s), "
         f"{len(sc.clutter)} clutter patch(es), effects: {effects}")
    total = sc.radar.n_lines * (2 if sc.clutter and sc.clutter_model == "binned" else 1)
    t0 = time.perf_counter()
    with progress_bar(total, label="simulating") as bar:
        raw = run(sc, progress=bar.update)
    elapsed = time.perf_counter() - t0
    if fmt == "ceos":
        from sarcli.io.ceos import write_ceos
        from sarcli.io.ceos.writer import SCENE_FILES

        write_ceos(output, raw)  # creates the folder only once the product is known to be representable
        written = [str(output / name) for name in SCENE_FILES]
    else:
        write_raw(output, raw, parameters={"scene": sc.name, "effects": list(sc.effects), "seed": sc.seed},
                  inputs=(scene,), compression=compression)
        written = [str(output)]
    info(f"wrote {', '.join(written)} in {elapsed:.2f} s of simulation")
    if as_json:
        emit_json({"scene": sc.name, "output": written, "format": fmt, "shape": list(raw.shape),
                   "n_channels": raw.n_channels, "effects": list(sc.effects), "n_targets": len(sc.targets),
                   "n_clutter_patches": len(sc.clutter), "seed": sc.seed, "simulation_time_s": elapsed})


def _check_ceos_scene(sc) -> None:
    """Refuse, before simulating, a scene whose product CEOS RAW cannot hold: channels (second_channel),
    4-bit quantization, samples per line and the Radarsat-1 ADC/PRF/window codes (the rest, e.g. the
    pulse grid, is checked on the product when it is written)."""
    from sarcli.io.ceos.writer import check_representable

    r = sc.radar
    quant = sc.effect_params.get("quantization")
    four_bit = "quantization" in sc.effects and (quant is None or quant[0] == 4)
    check_representable(2 if "second_channel" in sc.effects else 1, r.n_samples, four_bit,
                        r.range_sampling_rate_hz, r.prf_hz, r.window_start_s)


def register(app: typer.Typer) -> None:
    app.command("simulate")(simulate)
