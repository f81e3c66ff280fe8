"""Workflow ``ati_montecarlo``: relative errors of vy, x0, y0 vs SNR over repeated simulations of a scene
with one moving target, reproducible from ``seed`` (``sarcli.ati.montecarlo``: each run simulates the
scene at the SNR with its own seed, focuses, detects and estimates)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.workflows import base
from sarcli.workflows.ati_estimate import check_choices


def snr_values(snr: str | tuple[float, ...]) -> list[float]:
    """SNR values (dB) from 'start:stop:step', 'a,b,c' or a list."""
    from sarcli.ati.montecarlo import parse_snr_range

    return parse_snr_range(snr) if isinstance(snr, str) else [float(x) for x in snr]


@dataclass(frozen=True)
class Config:
    """scene: scene TOML with one moving target (two channels); runs: runs per SNR; snr: SNR values (dB),
    'start:stop:step', a comma list or a list; seed: master seed (every run's seed derives from it);
    route, unwrap, bin: as for ``ati_estimate``; plot: write the Fig. 9-style error plot (PNG)."""

    scene: Path
    runs: int = 50
    snr: str | tuple[float, ...] = "-5:25:5"
    seed: int = 1
    route: str = "exact"
    unwrap: str = "dechirp"
    bin: str = "track"
    plot: Path | None = None

    def __post_init__(self) -> None:
        check_choices(route=self.route, unwrap=self.unwrap, bin=self.bin)
        if self.runs < 1:
            raise ConfigError(f"runs must be at least 1, got {self.runs}")
        if not snr_values(self.snr):
            raise ConfigError("snr: no SNR value given")


@dataclass
class Report(base.Report):
    """result: scene, seed, route, unwrap, bin_mode and per_snr (mean/max relative errors, misses)."""

    result: dict[str, Any]
    plot: str | None = None

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.result)

    def lines(self) -> list[str]:
        out = [f"{'SNR dB':>7} {'vy mean %':>10} {'vy max %':>9} {'x0 mean %':>10} {'x0 max %':>9} "
               f"{'y0 mean %':>10} {'y0 max %':>9} {'missed':>6}"]
        for e in self.result["per_snr"]:
            out.append(f"{e['snr_db']:7.1f} " + " ".join(
                f"{100 * e[f'{k}_mean_rel']:10.4f} {100 * e[f'{k}_max_rel']:9.4f}"
                if math.isfinite(e[f"{k}_mean_rel"]) else f"{'nan':>10} {'nan':>9}" for k in ("vy", "x0", "y0"))
                + f" {e['missed']:6d}")
        return out + ([f"wrote {self.plot}"] if self.plot else [])


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Run the Monte-Carlo (module docstring)."""
    from sarcli.ati.montecarlo import run as montecarlo
    from sarcli.ati.plots import montecarlo_plot

    with base.using(provenance):
        base.refuse_overwriting_inputs([config.scene], [config.plot])
        snrs = snr_values(config.snr)
        total = config.runs * len(snrs)
        done = 0

        def on_run() -> None:
            nonlocal done
            done += 1
            if progress is not None:
                progress("ati montecarlo", done, total)

        result = montecarlo(str(config.scene), config.runs, snrs, config.seed, config.route, config.unwrap,
                            config.bin, on_run=on_run)
        if config.plot is not None:
            montecarlo_plot(result, config.plot)
        return Report(result, None if config.plot is None else str(config.plot))
