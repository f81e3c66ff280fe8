"""Workflow ``simulate``: scene TOML -> raw echo product (HDF5) or a Radarsat-1 CEOS scene folder.

Only the effects the scene lists are computed (``sarcli.sim``). Deterministic: the seed is part of the
scene (``seed`` overrides it, e.g. for Monte-Carlo runs); with ``SOURCE_DATE_EPOCH`` set the HDF5 file
is byte-identical between runs. A CEOS output is checked for representability (one channel, 4-bit
quantization, the Radarsat-1 ADC/PRF/window codes) before anything is simulated.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.workflows import base

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Config:
    """scene: scene file (TOML); output: raw product (hdf5), a folder (ceos) or a packet file (s1-l0);
    format: hdf5, ceos (Radarsat-1 CEOS RAW) or s1-l0 (Sentinel-1 Level-0 packets, FDBAQ; the scene's
    range sampling rate must be a Sentinel-1 rate); compression: HDF5 compression of the echo; seed:
    overrides the scene's seed."""

    scene: Path
    output: Path
    format: Literal["hdf5", "ceos", "s1-l0"] = "hdf5"
    compression: Literal["auto", "gzip", "lzf", "none"] | None = "auto"
    seed: int | None = None

    def __post_init__(self) -> None:
        if self.seed is not None and self.seed < 0:
            raise ConfigError(f"seed must be >= 0, got {self.seed}")


@dataclass
class Report(base.Report):
    """What was simulated and written (``--json`` keys)."""

    scene: str
    output: list[str]
    format: str
    shape: list[int]
    n_channels: int
    effects: list[str]
    n_targets: int
    n_clutter_patches: int
    seed: int
    simulation_time_s: float
    writing_time_s: float
    total_time_s: float

    def lines(self) -> list[str]:
        what = {"hdf5": "HDF5 product", "ceos": "CEOS files", "s1-l0": "s1-l0 packets"}.get(self.format, self.format)
        return [f"simulated {self.scene}: {self.shape[0]} x {self.shape[1]} samples, {self.n_targets} target(s), "
                f"{self.n_clutter_patches} clutter patch(es), effects: {', '.join(self.effects) or 'none'}",
                f"wrote {', '.join(self.output)} in {self.total_time_s:.2f} s ({self.simulation_time_s:.2f} s "
                f"simulating, {self.writing_time_s:.2f} s writing the {what})"]


def check_ceos_scene(sc: Any) -> None:
    """Refuse, before simulating, a scene whose product CEOS RAW cannot hold: channels (second_channel),
    4-bit quantization, samples per line and the Radarsat-1 ADC/PRF/window codes (the rest, e.g. the
    pulse grid, is checked on the product when it is written)."""
    from sarcli.io.ceos.radarsat1 import check_representable

    r = sc.radar
    quant = sc.effect_params.get("quantization")
    four_bit = "quantization" in sc.effects and (quant is None or quant[0] == 4)
    check_representable(2 if "second_channel" in sc.effects else 1, r.n_samples, four_bit,
                        r.range_sampling_rate_hz, r.prf_hz, r.window_start_s)


#: RMS of the echo written as Level-0 samples, in ADC levels: a Level-0 packet carries the digitizer's
#: levels, the simulator's amplitude unit is arbitrary; 32 levels keeps the BAQ/FDBAQ quantizers in their
#: design range (their threshold tables span sigma of about 1 to 1000 levels) for any simulated power.
S1_ECHO_RMS_LEVELS = 32.0


def write_s1_level0(path: Path, raw: Any) -> None:
    """The simulated echo as Sentinel-1 Level-0 packets (FDBAQ), scaled to :data:`S1_ECHO_RMS_LEVELS`;
    an inertial (ECI) orbit is rotated to the Earth-fixed frame the packets carry (GMST, ``orbit.frames``)."""
    import dataclasses

    import numpy as np

    from orbit.frames import eci_to_ecef
    from sarcli.io.sentinel1.product import write_level0
    from sarcli.model.raw import Orbit

    o = raw.orbit
    if o is not None and o.frame == "ECI":
        p, v = eci_to_ecef(raw.epoch_utc, o.time, o.position, o.velocity)
        raw = dataclasses.replace(raw, orbit=Orbit(o.time, p, v, "ECEF"))
    rms = float(np.sqrt(np.mean(np.abs(raw.echo.astype(np.complex128)) ** 2)))
    if rms > 0:
        raw = dataclasses.replace(raw, echo=(raw.echo * np.float32(S1_ECHO_RMS_LEVELS / rms)).astype(np.complex64))
    write_level0(raw, path)


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Simulate the scene and write the product (module docstring)."""
    from sarcli.io.ceos.radarsat1 import SCENE_FILES
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    t_start = time.perf_counter()
    with base.using(provenance):
        output = Path(config.output)
        written = [output / name for name in SCENE_FILES] if config.format == "ceos" else [output]
        base.refuse_overwriting_inputs([config.scene], [output] + (written if config.format == "ceos" else []),
                                       folders=[output] if config.format == "ceos" else [])
        if not output.resolve().parent.is_dir():
            raise ConfigError(f"output folder {output.resolve().parent} does not exist: create it first")
        if output.is_dir() and config.format != "ceos":
            raise ConfigError(f"{output} is a folder: give a file name for the {config.format} output "
                              "(or --format ceos)")
        sc = load_scene(config.scene)
        if config.seed is not None:
            sc.seed = config.seed
        if config.format == "ceos":
            check_ceos_scene(sc)
        from sarcli.memory import fits_in_memory

        channels = 2 if "second_channel" in sc.effects else 1  # the echo and a complex128 working copy of it
        fits_in_memory(f"simulating {sc.radar.n_lines} x {sc.radar.n_samples} samples",
                       channels * sc.radar.n_lines * sc.radar.n_samples * (8.0 + 16.0))
        total = sc.radar.n_lines * (2 if sc.clutter and sc.clutter_model == "binned" else 1)
        done = 0

        def tick(n: int) -> None:
            nonlocal done
            done += n
            if progress is not None:
                progress("simulating", done, total)

        _log.info("simulating %s: %d x %d samples, effects %s", sc.name, sc.radar.n_lines, sc.radar.n_samples,
                  ", ".join(sc.effects) or "none")
        t0 = time.perf_counter()
        raw = simulate(sc, progress=tick)
        elapsed = time.perf_counter() - t0
        t0 = time.perf_counter()
        if config.format == "ceos":
            from sarcli.io.ceos.radarsat1 import write_ceos

            write_ceos(output, raw)  # creates the folder only once the product is known to be representable
        elif config.format == "s1-l0":
            write_s1_level0(output, raw)
        else:
            params = {"scene": sc.name, "effects": list(sc.effects), "seed": sc.seed, "workflow": "simulate",
                      "config": {k: v for k, v in to_mapping(config).items() if k != "output"}}
            from sarcli.io.raw import write_raw

            write_raw(output, raw, parameters=params, inputs=(config.scene,), compression=config.compression)
        writing = time.perf_counter() - t0
        _log.info("simulated in %.3f s, wrote %s in %.3f s", elapsed, ", ".join(map(str, written)), writing)
        return Report(scene=sc.name, output=[str(p) for p in written], format=config.format, shape=list(raw.shape),
                      n_channels=raw.n_channels, effects=list(sc.effects), n_targets=len(sc.targets),
                      n_clutter_patches=len(sc.clutter), seed=sc.seed, simulation_time_s=elapsed,
                      writing_time_s=writing, total_time_s=time.perf_counter() - t_start)
