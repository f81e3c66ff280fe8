"""``sarcli gbsar scan|emulate|repeat``: acquisition with a VNA (8753ES via Prologix) and a GRBL rail.

Each command parses its options into the ``Config`` of its workflow (``sarcli.workflows.gbsar_scan``,
``gbsar_emulate``, ``gbsar_repeat``, imported inside the command), runs it and prints the report.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer

from sarcli.cli.common import info
from sarcli.cli.gbsar_app import attach, gbsar_app, run_workflow


@gbsar_app.command("scan")
def scan_cmd(
    port: str = typer.Option(None, "--port", help="VNA serial port (Prologix GPIB-USB), e.g. /dev/ttyUSB0."),
    rail_port: str = typer.Option(None, "--rail-port", help="GRBL rail serial port, e.g. /dev/ttyACM0."),
    config: Path = typer.Option(None, "--config", "-c", help="Acquisition TOML (see samples/scan.toml)."),
    output: Path = typer.Option(None, "-o", "--output", help="New scan product (.h5)."),
    resume: Path = typer.Option(None, "--resume", help="Continue this interrupted scan from its next stop."),
    dry_run: bool = typer.Option(False, "--dry-run", help="Validate the plan and estimate its duration; "
                                 "touches no instrument."),
    start: str = typer.Option(None, "--start", help="Start frequency, e.g. 5.2GHz."),
    stop: str = typer.Option(None, "--stop", help="Stop frequency, e.g. 5.4GHz."),
    points: int = typer.Option(None, "--points", help="Points per sweep (3 11 26 51 101 201 401 801 1601)."),
    ifbw: float = typer.Option(None, "--ifbw", help="IF bandwidth, Hz."),
    power: float = typer.Option(None, "--power", help="Source power, dBm."),
    data_format: str = typer.Option(None, "--data-format", help="FORM4 (ASCII), FORM2 or FORM3 (binary)."),
    pol: str = typer.Option(None, "--pol", help="Polarizations, TX then RX letter, e.g. VV or VV,VH,HV,HH."),
    switch: str = typer.Option(None, "--switch", metavar="[none|grbl|11713a]",
                               help="Polarization switch: none, grbl or 11713a."),
    rail_start: float = typer.Option(None, "--rail-start", help="First stop, m (rail frame)."),
    step: float = typer.Option(None, "--step", help="Rail step, m."),
    count: int = typer.Option(None, "--count", help="Number of stops."),
    settle: float = typer.Option(None, "--settle", help="Settling time after each move, s."),
    lat: float = typer.Option(None, "--lat", help="Rail centre latitude, degrees."),
    lon: float = typer.Option(None, "--lon", help="Rail centre longitude, degrees."),
    site_height: float = typer.Option(None, "--site-height", help="Rail centre ellipsoidal height, m."),
    heading: float = typer.Option(None, "--heading", help="Rail heading, degrees clockwise from north."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON summary on stdout."),
) -> None:
    """Acquire a GB-SAR scan: move the rail stop by stop and sweep the VNA at each stop.

    Settings come from --config and the flags (flags win). Both instruments are identified first
    and the scan refuses to run on a mismatch; every stop is written and flushed to the file
    before the rail moves on. Ctrl-C, an unplugged cable or an instrument fault end the scan with
    every completed stop kept; --resume continues it (the settings must match). Needs pyserial
    (pip install 'sarcli[acquire]') except for --dry-run.

    Examples:

      sarcli gbsar scan --port /dev/ttyUSB0 --rail-port /dev/ttyACM0 -c samples/scan.toml -o scan.h5

      sarcli gbsar scan -c samples/scan.toml --dry-run

      sarcli gbsar scan --port /dev/ttyUSB0 --rail-port /dev/ttyACM0 -c samples/scan.toml --resume scan.h5

      sarcli gbsar scan --port /dev/pts/3 --rail-port /dev/pts/4 -c samples/scan.toml --pol VV,HH --switch grbl -o s.h5
    """
    from sarcli.workflows import gbsar_scan as wf

    cfg = wf.Config(port=port, rail_port=rail_port, config=config, output=output, resume=resume, dry_run=dry_run,
                    start=start, stop=stop, points=points, ifbw=ifbw, power=power, data_format=data_format, pol=pol,
                    switch=switch, rail_start=rail_start, step=step, count=count, settle=settle, lat=lat, lon=lon,
                    site_height=site_height, heading=heading)
    run_workflow(wf, cfg, json_out)


@gbsar_app.command("emulate")
def emulate_cmd(
    scene: Path = typer.Option(None, "--scene", help="GB-SAR scene TOML whose S21 the VNA measures "
                               "(default: a calibrated thru, S21 = 1)."),
    faults: str = typer.Option("", "--faults", help="Faults NAME@N[:ARG],... (vna-timeout garble truncate "
                               "slow-sweep vna-unplug grbl-error alarm stall lost-ok status-garble rail-unplug)."),
    time_scale: float = typer.Option(1.0, "--time-scale", help="Sweep/move duration factor (0 = instant)."),
    switch: str = typer.Option("none", "--switch", metavar="[none|grbl|11713a]",
                               help="Emulated polarization switch: none, grbl, 11713a."),
    pol: str = typer.Option("VV", "--pol", help="The fixed polarization when --switch none."),
    machine_zero: float = typer.Option(None, "--machine-zero", help="Rail-frame position (m) of GRBL X0 "
                                       "(default: the scene's first stop, else 0)."),
    height: float = typer.Option(None, "--height", help="Antenna height, m (default: the scene's)."),
    max_travel_mm: float = typer.Option(4000.0, "--max-travel-mm", help="GRBL $130 (mm)."),
    soft_limits: bool = typer.Option(False, "--soft-limits", help="$20=1: targets beyond travel raise ALARM:2."),
    scan_interval: str = typer.Option(None, "--scan-interval", help="Simulated clock: the scene advances by "
                                      "this much per scan (e.g. 10m); default: a static scene."),
    truth: Path = typer.Option(None, "--truth", help="With --scan-interval: append what each scan simulated "
                               "(JSON lines) to this file."),
    json_out: bool = typer.Option(False, "--json", help='First stdout line: {"vna_port": ..., "rail_port": ...}.'),
) -> None:
    """Emulate the instruments on pseudo-terminals until interrupted: a Prologix GPIB-USB adapter
    with an 8753ES (and an 11713A at GPIB 28) and a GRBL 1.1h rail.

    The VNA's S21 is the GB-SAR simulator's for the rail position the emulated GRBL is at.

    Examples:

      sarcli gbsar emulate --scene samples/gbsar_indoor.toml --switch grbl --time-scale 0

      sarcli gbsar emulate --json --faults garble@3,alarm@5

      sarcli gbsar emulate --scene samples/gbsar_landslide.toml --time-scale 0 --scan-interval 10m --truth t.jsonl
    """
    from sarcli.workflows import gbsar_emulate as wf

    def ready(r) -> None:
        if json_out:
            sys.stdout.write(json.dumps({"vna_port": r.vna_port, "rail_port": r.rail_port}) + "\n")
            sys.stdout.flush()
        info(f"VNA (Prologix + 8753ES) on {r.vna_port}\nrail (GRBL 1.1h) on {r.rail_port}\n"
             f"rail X0 = {r.machine_zero_m:g} m of the rail frame; Ctrl-C to stop")

    cfg = wf.Config(scene=scene, faults=faults, time_scale=time_scale, switch=switch, pol=pol,
                    machine_zero_m=machine_zero, height_m=height, max_travel_mm=max_travel_mm, soft_limits=soft_limits,
                    scan_interval=scan_interval, truth=truth)
    run_workflow(wf, cfg, False, on_ready=ready)


@gbsar_app.command("repeat")
def repeat_cmd(
    every: str = typer.Option(..., "--every", help="Interval between scan starts, e.g. 30m, 1h, 90s."),
    count: int = typer.Option(..., "--count", help="Number of scans."),
    port: str = typer.Option(..., "--port", help="VNA serial port."),
    rail_port: str = typer.Option(..., "--rail-port", help="GRBL rail serial port."),
    config: Path = typer.Option(..., "--config", "-c", help="Acquisition TOML."),
    output: str = typer.Option(..., "-o", "--output", help="Output pattern with {index} and/or {utc}, e.g. "
                               "series/scan_{index:02d}.h5."),
    json_out: bool = typer.Option(False, "--json", help="Print a JSON list of scan summaries on stdout."),
) -> None:
    """Repeated acquisitions (a DInSAR / PS time series): COUNT scans, one every EVERY, each its own product.

    Scan k starts at t0 + k*EVERY (or at once if the previous scan ran late). A scan that fails is
    kept as an interrupted product and the series goes on; Ctrl-C stops the series.

    Examples:

    \b
      sarcli gbsar repeat --every 30m --count 9 --port /dev/ttyUSB0 --rail-port /dev/ttyACM0 \\
          -c samples/scan.toml -o 'series/scan_{index:02d}_{utc}.h5'
    """
    from sarcli.workflows import gbsar_repeat as wf

    cfg = wf.Config(every=every, count=count, port=port, rail_port=rail_port, config=config, output=output)
    run_workflow(wf, cfg, json_out)


def register(app: typer.Typer) -> None:
    attach(app)
