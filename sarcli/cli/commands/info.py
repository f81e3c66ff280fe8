"""``sarcli info``: describe a sarcli product, a GeoTIFF, or a raw input a sensor reader recognises."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import parse_option_values, print_report, run_workflow


def info(
    sources: list[Path] = typer.Argument(..., metavar="PATH...",
                                         help="A sarcli product (HDF5), a GeoTIFF, or a raw input (a CEOS scene "
                                              "folder, LEADER DATA, DATA.mat PARAMS.mat, ...)."),
    fmt: str = typer.Option(None, "--format", help="Raw inputs: the reader to use instead of sniffing."),
    option: list[str] = typer.Option(None, "--option", metavar="KEY=VALUE",
                                     help="Raw inputs: a reader option (repeatable), as for ingest."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object on stdout."),
) -> None:
    """Describe a product, a GeoTIFF or a raw input; nothing is written.

    Products: type, shape, time span, radar parameters, orbit, provenance (raw products), shape,
    pixel spacings, algorithm, time/range span (SLCs), polarizations, stops, sweep, status (GB-SAR
    scans), and for every product its attributes and datasets. GeoTIFFs: size, CRS, bounds, pixel
    size, nodata, band types, units and descriptions, overviews, tags. Raw inputs (anything
    'sarcli ingest' reads): read and summarized like a raw product.

    Examples:

      sarcli info raw.h5

      sarcli info raw.h5 --json

      sarcli info amplitude.tif

      sarcli info demo/ceos

      sarcli info rs1_vancouver_block1.mat rs1_vancouver_run_params.mat --json
    """
    report = run_workflow("info", {"sources": sources, "format": fmt, "options": parse_option_values(option or [])},
                          flags={"sources": "PATH", "format": "--format"})
    print_report(report, as_json)


def register(app: typer.Typer) -> None:
    app.command("info")(info)
