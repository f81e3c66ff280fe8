"""``sarcli ati detect|estimate|compensate|montecarlo``: SAR-ATI ground moving targets ([Ryu2017])."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, make_typer, print_status, run_workflow

ati_app = make_typer(help="SAR along-track interferometry: detect, estimate, compensate ground movers.")

_ROUTE = typer.Option("exact", "--route", help="Estimation route: exact (closed-form geometry, default), "
                                               "nonlinear (full fit of the exact histories), seed ([Ryu2017]'s chain).")
_UNWRAP = typer.Option("dechirp", "--unwrap", help="Phase unwrapping: dechirp (model-guided, robust) or itoh.")
_BIN = typer.Option("track", "--bin",
                    help="Range bin: track (per-line peak near the ANV bin) or anv ([Ryu2017]: one bin).")
_PFA = typer.Option(1e-6, "--pfa", help="False-alarm probability per pixel of each CFAR test (magnitude, phase).")
_FLAGS = {"raw": "RAW", "png_dir": "--png-dir"}


@ati_app.command("detect")
def detect_cmd(
    raw_path: Path = typer.Argument(..., help="Two-channel raw product (HDF5) of a straight flight (LOCAL frame)."),
    output: Path = typer.Option(None, "-o", "--output", help="Write an ATI product (images, ATI phase, candidates)."),
    pfa: float = _PFA,
    as_json: bool = typer.Option(False, "--json", help="Print the candidates as JSON on stdout."),
) -> None:
    """RD-focus both channels, co-register, form the ATI interferogram and detect movers.

    CFAR on magnitude and on the ATI phase (thermal phase noise of each pixel plus a systematic
    floor); clusters become candidates with their ATI phase, LOS speed, ground-range speed vx and a
    confidence. A phase near +-pi is flagged as a velocity ambiguity.

    Examples:

      sarcli simulate samples/ati_paper.toml -o raw2ch.h5

      sarcli ati detect raw2ch.h5

      sarcli ati detect raw2ch.h5 --pfa 1e-5 --json -o detect.h5
    """
    report = run_workflow("ati_detect", {"raw": raw_path, "output": output, "pfa": pfa}, flags=_FLAGS)
    print_status(report)
    if as_json:
        emit_json(report.to_dict())


@ati_app.command("estimate")
def estimate_cmd(
    raw_path: Path = typer.Argument(..., help="Two-channel raw product (HDF5); detection runs first."),
    route: str = _ROUTE,
    unwrap: str = _UNWRAP,
    bin_mode: str = _BIN,
    pfa: float = _PFA,
    output: Path = typer.Option(None, "-o", "--output", help="Write an ATI product with the movers table."),
    as_json: bool = typer.Option(False, "--json", help="Print the movers as JSON on stdout."),
) -> None:
    """Estimate vx, vy, x0, y0 (and R0) of every detected mover, each with a 1-sigma uncertainty.

    Per mover: sub-image cut, inverse azimuth compression, ANV range bin, phase unwrapping,
    weighted LS fit with covariance, then the chosen route. Positions x0, y0 are relative to the
    platform at the reference time t_ref (scene centre); x_local_m, y_local_m are in the LOCAL frame.

    Examples:

      sarcli ati estimate raw2ch.h5

      sarcli ati estimate raw2ch.h5 --route nonlinear --json

      sarcli ati estimate raw2ch.h5 --route seed --bin anv --unwrap itoh --json
    """
    report = run_workflow("ati_estimate", {"raw": raw_path, "output": output, "route": route, "unwrap": unwrap,
                                           "bin": bin_mode, "pfa": pfa}, flags=_FLAGS)
    print_status(report)
    if as_json:
        emit_json(report.to_dict()["movers"])


@ati_app.command("compensate")
def compensate_cmd(
    raw_path: Path = typer.Argument(..., help="Two-channel raw product (HDF5); detection and estimation run first."),
    output: Path = typer.Option(..., "-o", "--output", help="ATI product with image_before and image_after."),
    method: str = typer.Option("exact", "--method", help="Compensation: exact (R - Rs), quadratic ([Ryu2017, eq. 20]), "
                                                         "conventional (neglects vy*y0/R0)."),
    compare_conventional: bool = typer.Option(True, "--compare/--no-compare",
                                              help="Also measure the conventional method (position error)."),
    png_dir: Path = typer.Option(None, "--png-dir", help="Write before/after images and azimuth PSF plots here."),
    route: str = _ROUTE,
    unwrap: str = _UNWRAP,
    bin_mode: str = _BIN,
    pfa: float = _PFA,
    as_json: bool = typer.Option(False, "--json", help="Print per-mover positions and PSF widths as JSON."),
) -> None:
    """Compensate each mover (H_ph on its slow-time signal, re-compression) and relocate it.

    The compensated mover is placed at its estimated true position (azimuth y0, range
    sqrt(x0^2 + H^2)); the report gives its peak position, -3 dB azimuth width, the conventional
    method's position for comparison, and errors against the truth when the product is simulated.
    LOCAL-frame scenes are not geolocated: no GeoTIFF is written for them.

    Examples:

      sarcli ati compensate raw2ch.h5 -o comp.h5 --png-dir figs

      sarcli ati compensate raw2ch.h5 -o comp.h5 --method quadratic --json
    """
    report = run_workflow("ati_compensate", {"raw": raw_path, "output": output, "method": method,
                                             "compare": compare_conventional, "png_dir": png_dir, "route": route,
                                             "unwrap": unwrap, "bin": bin_mode, "pfa": pfa}, flags=_FLAGS)
    print_status(report)
    if as_json:
        emit_json(report.to_dict())


@ati_app.command("montecarlo")
def montecarlo_cmd(
    scene: Path = typer.Option(..., "--scene", help="Scene TOML with one moving target (two channels)."),
    runs: int = typer.Option(50, "--runs", help="Runs per SNR."),
    snr: str = typer.Option("-5:25:5", "--snr", help="SNR values (dB): start:stop:step or a comma list."),
    seed: int = typer.Option(1, "--seed", help="Master seed; every run's seed derives from it."),
    route: str = _ROUTE,
    unwrap: str = _UNWRAP,
    bin_mode: str = _BIN,
    plot: Path = typer.Option(None, "--plot", help="Write the Fig. 9-style error plot (PNG)."),
    as_json: bool = typer.Option(False, "--json", help="Print per-SNR mean and max relative errors as JSON."),
) -> None:
    """Relative errors of vy, x0, y0 vs SNR over repeated simulations (reproducible from --seed).

    Each run simulates the scene at the SNR with its own seed, focuses, detects and estimates.

    Examples:

      sarcli ati montecarlo --scene samples/ati_paper.toml --runs 50 --snr -5:25:5 --seed 7 --plot mc.png

      sarcli ati montecarlo --scene samples/ati_paper.toml --runs 3 --snr 10,20 --seed 1 --json
    """
    report = run_workflow("ati_montecarlo", {"scene": scene, "runs": runs, "snr": snr, "seed": seed, "route": route,
                                             "unwrap": unwrap, "bin": bin_mode, "plot": plot}, flags=_FLAGS)
    print_status(report)
    if as_json:
        emit_json(report.to_dict())


def register(app: typer.Typer) -> None:
    app.add_typer(ati_app, name="ati")
