"""``gbsar_simulate``: scene TOML -> simulated stop-and-go VNA rail scan (``gbsar_scan`` product).

Only the effects listed under ``[effects.*]`` in the scene are computed. A scatterer beyond the
unambiguous range ``R_max = c/(4 df)`` folds back into the image: counted and warned about.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sarcli.gbsar.scene import load_scene
from sarcli.gbsar.simulate import simulate
from sarcli.gbsar.system import system_from_scene
from sarcli.io.scan import write_scan
from sarcli.workflows.base import Progress, Report, no_progress, using
from sarcli.workflows.gbsar_common import guard, parameters


@dataclass(frozen=True)
class Config:
    """scene: GB-SAR scene TOML (``samples/gbsar_*.toml``); output: the scan product (.h5)."""

    scene: Path
    output: Path


@dataclass
class GbsarSimulateReport(Report):
    output: str
    n_pol: int
    n_stops: int
    n_freq: int
    n_scatterers: int
    effects: list[str] = field(default_factory=list)
    r_max_m: float = float("inf")
    n_beyond_r_max: int = 0

    def lines(self) -> list[str]:
        return [f"wrote {self.output}: {self.n_stops} stops x {self.n_freq} frequencies x {self.n_pol} "
                f"polarizations, {self.n_scatterers} scatterers, effects: {', '.join(self.effects) or 'none'}"]


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarSimulateReport:
    """Simulate the scene's scan and write it atomically."""
    progress = progress or no_progress
    with using(provenance):
        guard([config.scene], [config.output])
        sc = load_scene(config.scene)
        n = sc.positions_m.size

        def stops(it):
            for i in it:
                yield i
                progress("stops", i + 1, n)

        s = simulate(sc, progress=stops)
        write_scan(config.output, s, parameters=parameters(config), inputs=(config.scene,))
        sysp = system_from_scene(sc)
        r = np.linalg.norm(sc.scatterers.position - np.array([0.0, 0.0, sc.height_m]), axis=1)
        wrapped = int(np.sum(r > sysp.r_max_m)) if np.isfinite(sysp.r_max_m) else 0
        if wrapped:
            warnings.warn(f"{wrapped} scatterer(s) beyond R_max = {sysp.r_max_m:.2f} m fold back into the image",
                          stacklevel=2)
        return GbsarSimulateReport(output=str(config.output), n_pol=len(sc.polarizations), n_stops=s.n_stops,
                                   n_freq=int(s.frequency.size), n_scatterers=int(r.size), effects=sorted(sc.effects),
                                   r_max_m=sysp.r_max_m, n_beyond_r_max=wrapped)
