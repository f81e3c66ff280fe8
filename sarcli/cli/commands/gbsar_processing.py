"""``sarcli gbsar simulate|plan|focus|interfere|coherence|polarimetry``: GB-SAR processing commands.

Heavy modules are imported inside the commands so that this module always imports cleanly.
"""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress
from sarcli.cli.gbsar_app import attach, gbsar_app


@gbsar_app.command("simulate")
def simulate_cmd(
    scene: Path = typer.Argument(..., help="Scene TOML (see samples/gbsar_*.toml)."),
    output: Path = typer.Option(..., "-o", "--output", help="Output scan product (.h5)."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Simulate a stop-and-go VNA rail scan of a scene: S21 per polarization, stop and frequency.

    Only the effects listed under [effects.*] in the scene are computed.

    Examples:

      sarcli gbsar simulate samples/gbsar_indoor.toml -o indoor.h5

      sarcli gbsar simulate samples/gbsar_outdoor.toml -o t1.h5 --json
    """
    import numpy as np

    from sarcli.gbsar.scene import load_scene
    from sarcli.gbsar.simulate import simulate
    from sarcli.gbsar.system import system_from_scene
    from sarcli.io.scan import write_scan

    sc = load_scene(scene)
    s = simulate(sc, progress=lambda it: progress(it, total=sc.positions_m.size, label="stops"))
    write_scan(output, s, parameters={"scene": scene.name}, inputs=[scene])
    sysp = system_from_scene(sc)
    r = np.linalg.norm(sc.scatterers.position - np.array([0.0, 0.0, sc.height_m]), axis=1)
    wrapped = int(np.sum(r > sysp.r_max_m)) if np.isfinite(sysp.r_max_m) else 0
    summary = {"output": str(output), "n_pol": len(sc.polarizations), "n_stops": s.n_stops,
               "n_freq": int(s.frequency.size), "n_scatterers": int(r.size), "effects": sorted(sc.effects),
               "r_max_m": sysp.r_max_m, "n_beyond_r_max": wrapped}
    if wrapped:
        info(f"warning: {wrapped} scatterer(s) beyond R_max = {sysp.r_max_m:.2f} m fold back into the image")
    if json_out:
        emit_json(summary)
    else:
        info(f"wrote {output}: {s.n_stops} stops x {s.frequency.size} frequencies x "
             f"{len(sc.polarizations)} polarizations, {r.size} scatterers, effects: "
             f"{', '.join(sorted(sc.effects)) or 'none'}")


def register(app: typer.Typer) -> None:
    attach(app)
