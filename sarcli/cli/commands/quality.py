"""``sarcli quality``: point-target quality of an SLC (IRW, PSLR, ISLR, position error).

Parses the options into :class:`sarcli.workflows.quality.Config`, runs the workflow, prints the report.
"""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, report
from sarcli.errors import ConfigError


def _parse_at(values: list[str]) -> tuple[tuple[float, float], ...]:
    out = []
    for v in values:
        try:
            a, b = (float(x) for x in v.split(","))
        except ValueError:
            raise ConfigError(f"--at {v!r}: expected TIME_S,RANGE_M (zero-Doppler time, slant range)") from None
        out.append((a, b))
    return tuple(out)


def quality(
    slc_path: Path = typer.Argument(..., help="SLC product (from 'sarcli focus')."),
    at: list[str] = typer.Option(None, "--at", help="Target at TIME_S,RANGE_M (zero-Doppler time s after the "
                                 "epoch, slant range m); repeatable. Default: the simulated truth targets."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object per target (a list) on stdout."),
) -> None:
    """Measure point targets: IRW, PSLR and ISLR in range and azimuth, and the peak position error.

    PSLR/ISLR use the main lobe between the first minima and sidelobes out to 20 main-lobe
    half-widths; IRW is the -3 dB width (metres: slant range, ground azimuth). With simulated truth
    (or --at) the position error is the distance between the interpolated peak and the truth.

    Examples:

      sarcli quality slc.h5

      sarcli quality slc.h5 --json

      sarcli quality slc.h5 --at -3.758,993644.5 --at -3.9485,992646.0
    """
    from sarcli.workflows.quality import Config, run

    rep = run(Config(slc=slc_path, at=_parse_at(at or [])))
    if as_json:
        emit_json(rep.to_dict()["targets"])
        return
    for line in rep.lines():
        report(line)


def register(app: typer.Typer) -> None:
    app.command("quality")(quality)
