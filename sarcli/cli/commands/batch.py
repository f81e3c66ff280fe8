"""``sarcli batch IN/ -o OUT/``: every scene of a folder through ingest -> doppler -> focus, one Dask task graph."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, parse_option_values, print_status, run_workflow


def batch(
    input_dir: Path = typer.Argument(..., metavar="IN", help="Folder of scenes: raw products (NAME.h5) and inputs "
                                     "a sensor reader recognises (CEOS folders NAME/, ...)."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the products (created)."),
    scheduler: str = typer.Option(None, "--scheduler", metavar="ADDRESS", help="Dask scheduler, tcp://host:8786 "
                                  "(default: $SARCLI_SCHEDULER, else a local cluster)."),
    workers: int = typer.Option(None, "--workers", help="Local cluster: worker processes (default: one per core; "
                                "0: this process, one task after the other, no Dask)."),
    threads_per_worker: int = typer.Option(None, "--threads-per-worker", help="Local cluster: threads per worker "
                                           "(default 1)."),
    report: Path = typer.Option(None, "--report", metavar="HTML", help="Write Dask's performance report here."),
    retries: int = typer.Option(None, "--retries", help="Reruns of a task that failed unexpectedly (default 1; a "
                                "bad input is not retried)."),
    focus: list[str] = typer.Option(None, "--focus", metavar="KEY=VALUE", help="A 'sarcli focus' setting for every "
                                    "scene, as in a [focus] table: looks_az=4, height_m=300, "
                                    "options={block_lines=2048} (repeatable)."),
    geotiff: str = typer.Option(None, "--geotiff", metavar="[auto|always|never]",
                                help="GeoTIFFs: auto (default) for every scene with an Earth orbit, a scene without "
                                     "one gets its SLC and quicklook and a warning; always; never."),
    as_json: bool = typer.Option(False, "--json", help="Print the batch report as JSON on stdout."),
) -> None:
    """Process a folder of scenes: raw -> Doppler -> SLC + GeoTIFF + quicklook, as one task graph.

    Each scene's steps are tasks of one Dask graph ('sarcli ingest' for sensor inputs, 'sarcli
    doppler', 'sarcli focus --geotiff --quicklook'), on a local cluster or on the scheduler at
    --scheduler. Like 'make batch', a step whose products are newer than its inputs is skipped. A bad
    input fails its own scene only; an unexpected failure is retried once. Products in OUT:
    NAME.raw.h5 (ingested), NAME.doppler.h5, NAME.slc.h5, NAME.tif, NAME.png and NAME.json (the
    scene's report). Ends with a table of what failed and why; exit status 1 if anything failed.

    Examples:

      sarcli batch scenes/ -o products/

      sarcli batch scenes/ -o products/ --workers 2 --report dask-report.html --json

      sarcli batch scenes/ -o products/ --scheduler tcp://10.0.0.5:8786

      SARCLI_SCHEDULER=tcp://10.0.0.5:8786 sarcli batch scenes/ -o products/ --focus looks_az=4
    """
    rep = run_workflow("batch", {"input": input_dir, "output": output, "scheduler": scheduler, "workers": workers,
                                 "threads_per_worker": threads_per_worker, "report": report, "retries": retries,
                                 "focus": parse_option_values(focus or [], "--focus"), "geotiff": geotiff},
                       flags={"input": "IN", "output": "--output"})
    if as_json:
        emit_json(rep.to_dict())
    print_status(rep)
    for line in rep.failure_lines():
        typer.echo(line, err=True)
    if rep.failures:
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    app.command("batch")(batch)
