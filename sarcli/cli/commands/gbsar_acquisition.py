"""``sarcli gbsar scan|emulate|repeat``: acquisition with a VNA (8753ES via Prologix) and a GRBL rail.

Heavy modules are imported inside the commands so that this module always imports cleanly.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, progress_bar
from sarcli.cli.gbsar_app import attach, gbsar_app
from sarcli.errors import Interrupted


def _overrides(start, stop, points, ifbw, power, data_format, pol, switch, rail_start, step, count, settle,
               lat, lon, site_height, heading) -> dict:
    from sarcli.acquire.config import parse_frequency

    return {
        "vna": {"start_hz": None if start is None else parse_frequency(start),
                "stop_hz": None if stop is None else parse_frequency(stop), "points": points,
                "if_bandwidth_hz": ifbw, "power_dbm": power, "data_format": data_format},
        "polarization": {"polarizations": None if pol is None else [p.strip().upper() for p in pol.split(",")],
                         "switch": switch},
        "rail": {"start_m": rail_start, "step_m": step, "count": count, "settle_s": settle},
        "site": {"latitude_deg": lat, "longitude_deg": lon, "height_m": site_height, "heading_deg": heading},
    }


def _resume_command(ctx: typer.Context, target: Path) -> str:
    """The ``sarcli gbsar scan`` command line that continues ``target``: the options given to this
    invocation (ports, config, overrides), with -o/--resume replaced by ``--resume target``."""
    import shlex

    parts = ["sarcli", "gbsar", "scan"]
    for p in ctx.command.params:
        v = ctx.params.get(p.name)
        if p.name in ("output", "resume", "dry_run") or v is None or v is False or v == p.default:
            continue
        flag = max((o for o in p.opts if o.startswith("--")), key=len)
        parts += [flag] if v is True else [flag, str(v)]
    return shlex.join([*parts, "--resume", str(target)])


def _series_resume_command(port: str, rail_port: str, config: Path, target: str) -> str:
    """The ``sarcli gbsar scan`` command line that continues scan ``target`` of a repeat series."""
    import shlex

    return shlex.join(["sarcli", "gbsar", "scan", "--port", port, "--rail-port", rail_port, "--config", str(config),
                       "--resume", str(target)])


@gbsar_app.command("scan")
def scan_cmd(
    ctx: typer.Context,
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
    switch: str = typer.Option(None, "--switch", help="Polarization switch: none, grbl or 11713a."),
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
    every completed stop kept; --resume continues it (the settings must match).

    Examples:

      sarcli gbsar scan --port /dev/ttyUSB0 --rail-port /dev/ttyACM0 -c samples/scan.toml -o scan.h5

      sarcli gbsar scan -c samples/scan.toml --dry-run

      sarcli gbsar scan --port /dev/ttyUSB0 --rail-port /dev/ttyACM0 -c samples/scan.toml --resume scan.h5

      sarcli gbsar scan --port /dev/pts/3 --rail-port /dev/pts/4 -c samples/scan.toml --pol VV,HH --switch grbl -o s.h5
    """
    from sarcli.acquire.config import load_config
    from sarcli.acquire.session import StopGuard, acquire, failure, plan_summary
    from sarcli.errors import SarcliError

    cfg = load_config(config, _overrides(start, stop, points, ifbw, power, data_format, pol, switch, rail_start,
                                         step, count, settle, lat, lon, site_height, heading))
    if dry_run:
        plan = plan_summary(cfg)
        if json_out:
            emit_json({"dry_run": True, **plan})
        else:
            info(f"plan OK: {plan['n_stops']} stops x {len(plan['polarizations'])} pol x {plan['points']} points, "
                 f"rail {plan['rail_m'][0]:g}..{plan['rail_m'][1]:g} m, estimated {plan['duration_s'] / 60:.1f} min "
                 f"(sweep {plan['sweep_s']:.2f} s, step move {plan['move_s']:.2f} s); nothing moved")
        return
    if (output is None) == (resume is None):
        raise SarcliError("give exactly one of -o OUTPUT (new scan) or --resume SCAN (continue one)")
    if not port or not rail_port:
        raise SarcliError("--port (VNA) and --rail-port (GRBL) are required unless --dry-run")
    target = resume if resume is not None else output
    with StopGuard() as guard, progress_bar(cfg.rail.count, label="stops") as bar:
        state = {"last": None}

        def on_stop(n: int, total: int) -> None:
            if state["last"] is None:
                bar.update(n)
            else:
                bar.update(n - state["last"])
            state["last"] = n

        summary = acquire(cfg, port, rail_port, target, resume is not None, guard, on_stop)
    if json_out:
        emit_json(summary)
    if summary["status"] != "complete":
        raise failure(summary, _resume_command(ctx, target))
    info(f"wrote {target}: {summary['n_complete']} stops, {summary['elapsed_s']:.1f} s, "
         f"{summary['retries']} retries")


@gbsar_app.command("emulate")
def emulate_cmd(
    scene: Path = typer.Option(None, "--scene", help="GB-SAR scene TOML whose S21 the VNA measures "
                               "(default: a calibrated thru, S21 = 1)."),
    faults: str = typer.Option("", "--faults", help="Faults NAME@N[:ARG],... (vna-timeout garble truncate "
                               "slow-sweep vna-unplug grbl-error alarm stall lost-ok status-garble rail-unplug)."),
    time_scale: float = typer.Option(1.0, "--time-scale", help="Sweep/move duration factor (0 = instant)."),
    switch: str = typer.Option("none", "--switch", help="Emulated polarization switch: none, grbl, 11713a."),
    pol: str = typer.Option("VV", "--pol", help="The fixed polarization when --switch none."),
    machine_zero: float = typer.Option(None, "--machine-zero", help="Rail-frame position (m) of GRBL X0 "
                                       "(default: the scene's first stop, else 0)."),
    height: float = typer.Option(None, "--height", help="Antenna height, m (default: the scene's)."),
    max_travel_mm: float = typer.Option(4000.0, "--max-travel-mm", help="GRBL $130 (mm)."),
    soft_limits: bool = typer.Option(False, "--soft-limits", help="$20=1: targets beyond travel raise ALARM:2."),
    json_out: bool = typer.Option(False, "--json", help='First stdout line: {"vna_port": ..., "rail_port": ...}.'),
) -> None:
    """Emulate the instruments on pseudo-terminals until interrupted: a Prologix GPIB-USB adapter
    with an 8753ES (and an 11713A at GPIB 28) and a GRBL 1.1h rail.

    The VNA's S21 is the GB-SAR simulator's for the rail position the emulated GRBL is at.

    Examples:

      sarcli gbsar emulate --scene samples/gbsar_indoor.toml --switch grbl --time-scale 0

      sarcli gbsar emulate --json --faults garble@3,alarm@5
    """
    import signal
    import threading

    from sarcli.acquire.emulator import Emulator, scene_source
    from sarcli.errors import SarcliError

    source, zero, h = None, machine_zero or 0.0, height or 0.0
    if scene is not None:
        from sarcli.gbsar.scene import load_scene

        sc = load_scene(scene)
        zero = float(sc.positions_m[0]) if machine_zero is None else machine_zero
        h = float(sc.rail_heights()[0]) if height is None else height
        source = scene_source(str(scene), h)
    settings = {130: max_travel_mm, 20: 1 if soft_limits else 0}
    if pol.upper() not in ("VV", "VH", "HV", "HH"):
        raise SarcliError(f"--pol {pol}: use VV, VH, HV or HH")
    done = threading.Event()
    old = {s: signal.signal(s, lambda *_: done.set()) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with Emulator(source, faults, time_scale, switch, pol.upper(), settings, machine_zero_m=zero) as emu:
            if json_out:
                sys.stdout.write(json.dumps({"vna_port": emu.vna_port, "rail_port": emu.rail_port}) + "\n")
                sys.stdout.flush()
            info(f"VNA (Prologix + 8753ES) on {emu.vna_port}\nrail (GRBL 1.1h) on {emu.rail_port}\n"
                 f"rail X0 = {zero:g} m of the rail frame; Ctrl-C to stop")
            while not done.wait(0.2):
                pass
            fired = list(emu.faults.fired)
    finally:
        for s, h_old in old.items():
            signal.signal(s, h_old)
    info(f"emulator stopped; faults fired: {', '.join(fired) or 'none'}")


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
    from sarcli.acquire.config import load_config, parse_duration
    from sarcli.acquire.session import StopGuard, acquire, failure
    from sarcli.errors import SarcliError

    period = parse_duration(every)
    if count < 1 or period < 0:
        raise SarcliError("--count must be >= 1 and --every >= 0")
    if "{index" not in output and "{utc" not in output:
        raise SarcliError("--output must contain {index} or {utc} so that every scan is its own product")
    cfg = load_config(config)
    summaries, failed = [], 0
    t0 = time.monotonic()
    with StopGuard() as guard:
        for k in range(count):
            wait_until = t0 + k * period
            while time.monotonic() < wait_until and not guard():
                time.sleep(min(0.2, wait_until - time.monotonic()))
            if guard():
                break
            utc = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
            try:
                path = output.format(index=k + 1, utc=utc)
            except (KeyError, ValueError, IndexError) as e:
                raise SarcliError(f"bad --output pattern '{output}': {e}") from None
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            info(f"scan {k + 1}/{count} -> {path}")
            try:
                s = acquire(cfg, port, rail_port, path, False, guard)
            except SarcliError as e:  # e.g. instruments not answering at this slot
                s = {"output": path, "status": "failed", "error": str(e)}
            if s["status"] != "complete":
                failed += 1
                info(f"scan {k + 1} did not complete: {s['error']}")
            summaries.append(s)
            if guard():
                break
    if json_out:
        emit_json(summaries)
    if guard.requested:
        last = summaries[-1] if summaries else {}
        raise failure(last, _series_resume_command(port, rail_port, config, last["output"])) \
            if "n_complete" in last else Interrupted("interrupted")
    if failed:
        raise SarcliError(f"{failed} of {count} scans did not complete (see above)")
    info(f"{count} scans written")


def register(app: typer.Typer) -> None:
    attach(app)
