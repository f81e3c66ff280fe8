"""``sarcli gbsar monitor|series|serve``: a monitoring campaign, its offline rebuild, its live page.

Each command parses its options into the ``Config`` of its workflow (``sarcli.workflows.gbsar_monitor``,
``gbsar_series``, ``gbsar_serve``, imported inside the command), runs it and prints the report;
``--json`` prints one JSON line per scan as the scans are processed.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer

from sarcli.cli.common import info
from sarcli.cli.gbsar_app import attach, gbsar_app, run_workflow


def _scan_printer(json_out: bool):
    """Each scan's record: one JSON line on stdout (``--json``) or one line for people on stderr."""
    def emit(rec: dict) -> None:
        if json_out:
            sys.stdout.write(json.dumps(rec) + "\n")  # the records hold plain numbers (no NaN: None)
            sys.stdout.flush()
            return
        if rec["status"] != "accepted":
            info(f"scan {rec['scan']} {rec['time_utc']}: {rec['status']} ({rec['reason']})")
            return
        res = rec.get("aps_residual_mm")
        watch = ", ".join(f"{k} {v:+.2f} mm" for k, v in rec.get("displacement_mm", {}).items() if v is not None)
        info(f"scan {rec['scan']} {rec['time_utc']}: {rec['n_points']} points, APS residual "
             f"{'-' if res is None else f'{res:.3f}'} mm, alarm {rec['alarm_level']}" + (f"; {watch}" if watch else ""))
    return emit


@gbsar_app.command("monitor")
def monitor_cmd(
    out: Path = typer.Option(..., "--out", "-o", help="Campaign folder (created, or resumed if it exists)."),
    config: Path = typer.Option(None, "--config", "-c", help="Monitoring TOML (see samples/monitor.toml), or an "
                                "acquisition TOML; needed for a new campaign."),
    port: str = typer.Option(None, "--port", help="VNA serial port (Prologix GPIB-USB)."),
    rail_port: str = typer.Option(None, "--rail-port", help="GRBL rail serial port."),
    every: str = typer.Option("10m", "--every", help="Interval between scan starts, e.g. 10m, 1h."),
    count: int = typer.Option(None, "--count", help="Scans in the whole campaign (default: until Ctrl-C)."),
    time_scale: float = typer.Option(1.0, "--time-scale", help="1: wall clock; < 1: simulated clock, scans stamped "
                                     "EVERY apart, waiting EVERY*SCALE between them (0: no wait)."),
    start_utc: str = typer.Option(None, "--start-utc", help="Simulated clock: time of the first scan "
                                  "(ISO-8601 UTC; default: now)."),
    on_alarm: str = typer.Option(None, "--on-alarm", help="Shell command run for each alarm event, the event as "
                                 "JSON on stdin (a failure is logged, the campaign goes on)."),
    hook_timeout: float = typer.Option(30.0, "--hook-timeout", help="Seconds the --on-alarm command may take."),
    json_out: bool = typer.Option(False, "--json", help="One JSON line per scan on stdout."),
) -> None:
    """Run an unattended monitoring campaign: acquire a scan every EVERY, focus it, update the
    displacement / velocity / acceleration store, correct the atmosphere, raise alarms, rewrite
    CAMPAIGN/index.html. Running the same command again resumes the campaign where it stopped.

    Examples:

    \b
      sarcli gbsar monitor --port /dev/ttyUSB0 --rail-port /dev/ttyACM0 -c samples/monitor.toml \\
          --every 10m --out campaign/ --on-alarm 'mail -s "GB-SAR alarm" ops@example.org'

    \b
      sarcli gbsar emulate --scene samples/gbsar_landslide.toml --time-scale 0 --scan-interval 10m &
      sarcli gbsar monitor --port /dev/pts/3 --rail-port /dev/pts/4 -c samples/monitor.toml --every 10m \\
          --time-scale 0 --start-utc 2026-05-01T06:00:00Z --count 40 --out campaign/ --json
    """
    from sarcli.workflows import gbsar_monitor as wf

    cfg = wf.Config(out=out, config=config, port=port, rail_port=rail_port, every=every, count=count,
                    time_scale=time_scale, start_utc=start_utc, on_alarm=on_alarm, hook_timeout_s=hook_timeout)
    run_workflow(wf, cfg, False, on_record=_scan_printer(json_out))


@gbsar_app.command("series")
def series_cmd(
    inputs: list[Path] = typer.Argument(..., help="A campaign folder, or scan files in time order."),
    config: Path = typer.Option(None, "--config", "-c", help="Monitoring TOML (default: the campaign's)."),
    out: Path = typer.Option(None, "--out", "-o", help="Output folder (default: the campaign folder, whose "
                             "store is rebuilt)."),
    jobs: int = typer.Option(0, "--jobs", "-j", help="Processes focusing scans (0: one per core)."),
    checkpoint_every: int = typer.Option(50, "--checkpoint-every", help="Scans between state commits."),
    on_alarm: str = typer.Option(None, "--on-alarm", help="Run this hook for the alarms of the rebuild too."),
    json_out: bool = typer.Option(False, "--json", help="One JSON line per scan on stdout."),
) -> None:
    """Rebuild a campaign's store from its scans, from scratch (same numbers as the monitor).

    Examples:

      sarcli gbsar series campaign/

      sarcli gbsar series campaign/ --out rebuilt/ --json

      sarcli gbsar series scans/*.h5 -c samples/monitor.toml --out offline/
    """
    from sarcli.workflows import gbsar_series as wf

    cfg = wf.Config(inputs=tuple(inputs), config=config, out=out, jobs=jobs, checkpoint_every=checkpoint_every,
                    on_alarm=on_alarm)
    run_workflow(wf, cfg, False, on_record=_scan_printer(json_out) if json_out else None)


@gbsar_app.command("serve")
def serve_cmd(
    campaign: Path = typer.Argument(..., help="Campaign folder."),
    port: int = typer.Option(8000, "--port", help="TCP port on 127.0.0.1 (0: any free port)."),
) -> None:
    """Serve the campaign's live page on http://127.0.0.1:PORT/ (loopback only) until Ctrl-C.
    The page also works opened as a file: CAMPAIGN/index.html.

    Examples:

      sarcli gbsar serve campaign/ --port 8080
    """
    from sarcli.workflows import gbsar_serve as wf

    def ready(r) -> None:
        sys.stdout.write(r.url + "\n")
        sys.stdout.flush()
        info(f"serving {campaign}/index.html on {r.url}; Ctrl-C to stop")

    run_workflow(wf, wf.Config(campaign=campaign, port=port), False, on_ready=ready)


def register(app: typer.Typer) -> None:
    attach(app)
