"""``sarcli orbit info|interpolate|accuracy``: state vectors of a raw product, and what accuracy costs."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, make_typer, print_report, print_status, run_workflow

orbit_app = make_typer(help="Orbit state vectors: summary, Hermite interpolation, accuracy/cost tables.")


@orbit_app.command("info")
def info_cmd(
    raw_path: Path = typer.Argument(..., help="Raw product (HDF5) with /orbit."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON on stdout."),
) -> None:
    """Summarize a product's state vectors: frame, span, spacing, coverage of the echo, geometry.

    Reports whether every azimuth line lies inside the state-vector span (interpolation refuses times
    outside it), the spacing (non-uniform spacing is fine), the default Hermite order, and for ECI/ECEF
    orbits the altitude, pass direction, and the zero-Doppler look and incidence angles of the first
    (and last) range sample at the scene centre. For ingested CEOS products, the difference between
    the delivered Greenwich hour angle and sarcli's GMST shows which equinox the vectors use.

    Examples:

      sarcli orbit info raw.h5

      sarcli orbit info raw.h5 --json
    """
    print_report(run_workflow("orbit_info", {"raw": raw_path}, flags={"raw": "RAW"}), as_json)


@orbit_app.command("interpolate")
def interpolate_cmd(
    raw_path: Path = typer.Argument(..., help="Raw product (HDF5) with /orbit."),
    times: str = typer.Option(..., "--times", "-t",
                              help="Seconds after the product epoch ('0,10.5', 'start:stop:step') "
                                   "and/or ISO-8601 UTC times."),
    frame: str = typer.Option("native", "--frame", help="Output frame: native (as stored), eci or ecef."),
    n_nodes: int = typer.Option(None, "--n-nodes", "-n", help="Hermite nodes N (2..16); default from the table."),
    extrapolate: float = typer.Option(0.0, "--extrapolate", help="Allow times up to this many s outside the span."),
    csv: Path = typer.Option(None, "--csv", help="Also write the table as CSV (written atomically)."),
    as_json: bool = typer.Option(False, "--json", help="Print the table as JSON on stdout."),
) -> None:
    """Hermite-interpolate the state vectors (positions and velocities) at given times.

    Prints time, position, velocity and acceleration (SI) in the requested frame; in ECEF also the
    geodetic latitude, longitude and height (WGS-84). Times outside the state-vector span are refused
    unless --extrapolate allows them.

    Examples:

      sarcli orbit interpolate raw.h5 --times 0,1.5,3

      sarcli orbit interpolate raw.h5 --times 0:10:0.5 --frame ecef --json

      sarcli orbit interpolate raw.h5 --times 2002-06-16T15:41:02.5Z

      sarcli orbit interpolate raw.h5 --times 0:6720:60 --frame ecef --csv orbit.csv
    """
    report = run_workflow("orbit_interpolate", {"raw": raw_path, "times": times, "frame": frame, "n_nodes": n_nodes,
                                                "extrapolate": extrapolate, "csv": csv}, flags={"raw": "RAW"})
    if as_json:
        emit_json(report.to_dict())
    elif csv is not None:
        print_status(report)
    else:
        print_report(report, False)


@orbit_app.command("accuracy")
def accuracy_cmd(
    plot: Path = typer.Option(None, "--plot", help="Write a PNG of position/velocity error vs time per N."),
    as_json: bool = typer.Option(False, "--json", help="Print the tables as JSON on stdout."),
    timing: bool = typer.Option(True, "--timing/--no-timing", help="Measure evaluations per CPU second."),
) -> None:
    """Accuracy vs cost of the orbit knobs, computed now (a few seconds).

    Hermite order N = 2..12 against a J2-integrated Radarsat-1-like truth sampled 15 x 480 s (max
    position and velocity error away from the span ends and in the end intervals, evaluations per CPU
    second); exact vs small-angle attitude rotation at 0, 1, 10, 100 x the Radarsat-1 limits
    (pointing error, Doppler error, ground error); the Earth-frame model differences in metres at the
    ground.

    Examples:

      sarcli orbit accuracy

      sarcli orbit accuracy --plot orbit_accuracy.png --json
    """
    report = run_workflow("orbit_accuracy", {"plot": plot, "timing": timing})
    if plot is not None:
        info(f"wrote {plot}")
    print_report(report, as_json)


def register(app: typer.Typer) -> None:
    app.add_typer(orbit_app, name="orbit")
