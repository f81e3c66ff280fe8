"""``sarcli quality``: point-target quality of an SLC (IRW, PSLR, ISLR, position error)."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, report
from sarcli.errors import SarcliError


def _parse_at(values: list[str]) -> list[tuple[float, float]]:
    import math

    out = []
    for v in values:
        try:
            a, b = (float(x) for x in v.split(","))
        except ValueError:
            raise SarcliError(f"--at {v!r}: expected TIME_S,RANGE_M (zero-Doppler time, slant range)") from None
        if not (math.isfinite(a) and math.isfinite(b)):
            raise SarcliError(f"--at {v!r}: the time and range must be finite numbers")
        out.append((a, b))
    return out


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
    from sarcli.focus.quality import measure_targets, truth_targets
    from sarcli.io.slc import read_slc

    slc = read_slc(slc_path)
    if slc.azimuth_time.size < 2 or slc.slant_range.size < 2:
        raise SarcliError(f"{slc_path}: image too small to measure")
    positions = _parse_at(at) if at else truth_targets(slc.truth)
    if not positions:
        raise SarcliError(f"{slc_path}: no truth targets in the product; give positions with --at TIME_S,RANGE_M")
    res = measure_targets(slc, positions, truth_known=not at)
    if as_json:
        emit_json(res)
        return
    for i, m in enumerate(res):
        err = f", position error {m['position_error_m']:.3f} m" if "position_error_m" in m else ""
        report(f"target {i}: t {m['azimuth_time_s']:.6f} s, R {m['range_m']:.2f} m; IRW rg {m['irw_range_m']:.2f} m, "
             f"az {m['irw_azimuth_m']:.2f} m; PSLR rg {m['pslr_range_db']:.2f} dB, az {m['pslr_azimuth_db']:.2f} dB; "
             f"ISLR rg {m['islr_range_db']:.2f} dB, az {m['islr_azimuth_db']:.2f} dB{err}")


def register(app: typer.Typer) -> None:
    app.command("quality")(quality)
