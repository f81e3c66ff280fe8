"""``sarcli export``: a focused image (sarcli SLC or NISAR RSLC) -> an interchange format (NISAR RSLC, ...)."""

from __future__ import annotations

from pathlib import Path

import typer

from sarcli.cli.common import emit_json, info, require_output_folders
from sarcli.errors import SarcliError


def _value(text: str) -> object:
    """A TOML scalar (2, 0.5, true, "x") when the text is one, else the text itself (gzip, ALOS)."""
    import tomllib

    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def _options(values: list[str]) -> dict[str, object]:
    out = {}
    for v in values:
        key, sep, val = v.partition("=")
        if not sep or not key.strip():
            raise SarcliError(f"--option {v!r}: expected KEY=VALUE (e.g. compression=gzip)")
        out[key.strip()] = _value(val.strip())
    return out


def export(
    source: Path = typer.Argument(..., help="Focused image: a sarcli SLC product or a NISAR RSLC file."),
    output: Path = typer.Option(..., "-o", "--output", help="File to write."),
    fmt: str = typer.Option("nisar-rslc", "--format", metavar="[nisar-rslc|sicd|envi|PLUG-IN]",
                            help="Output format (built in: nisar-rslc, sicd, envi)."),
    polarization: str = typer.Option(None, "--polarization",
                                     help="Layer name: for a sarcli SLC the polarization it is (default HH); for "
                                          "an RSLC input the layer to read (default HH, else the first)."),
    frequency: str = typer.Option(None, "--frequency", help="RSLC input only: the sub-band to read (A, B)."),
    option: list[str] = typer.Option(None, "--option", help="Format option KEY=VALUE, repeatable "
                                     "(nisar-rslc: frequency, mission_id, instrument, compression; sicd: "
                                     "collector, classification; envi: gcps)."),
    radiometry: str = typer.Option(None, "--radiometry", metavar="[beta0|sigma0|gamma0]",
                                   help="envi: write that calibrated backscatter in dB (float32, NaN where not "
                                        "calibrated) instead of the complex samples; the SLC must carry "
                                        "/calibration (a SICD and an RSLC carry all the tables anyway)."),
    as_json: bool = typer.Option(False, "--json", help="Print the report as JSON on stdout."),
) -> None:
    """Write a focused image in an interchange format; sarcli's own SLC stays the working format.

    nisar-rslc: the NISAR L1 RSLC HDF5 layout (science/LSAR/RSLC/...): image, zero-Doppler time and
    slant range, ECEF orbit, attitude quaternions, Doppler centroid LUT, geolocation grid,
    identification and sarcli's provenance. ISCE3's NISAR readers open it.

    sicd: NGA SICD 1.4.0 in NITF (RMA/INCA, zero-Doppler grid) through sarkit, checked by its
    consistency checker; every SICD tool opens it (needs the 'sicd' extra: pip install 'sarcli[sicd]').

    envi: the complex image as ENVI .img + .hdr with corner ground control points (GDAL, ENVI, QGIS).

    Examples:

      sarcli export slc.h5 --format nisar-rslc -o rslc.h5

      sarcli export slc.h5 -o rslc.h5 --polarization HV --option compression=gzip --json

      sarcli export isce3_rslc.h5 --polarization VV -o vv_only.h5

      sarcli export slc.h5 --format sicd -o slc.nitf

      sarcli export slc.h5 --format envi -o slc.img

      sarcli export slc.h5 --format envi --radiometry sigma0 -o sigma0.img
    """
    from sarcli.config import from_mapping
    from sarcli.workflows.export import Config, run

    require_output_folders(output)
    cfg = from_mapping(Config, {"input": str(source), "output": str(output), "format": fmt,
                                "options": _options(option or []),
                                **({"polarization": polarization} if polarization else {}),
                                **({"frequency": frequency} if frequency else {}),
                                **({"radiometry": radiometry} if radiometry else {})}, "export")
    report = run(cfg)
    if as_json:
        emit_json(report.to_dict())
    else:
        for line in report.lines():
            info(line)


def register(app: typer.Typer) -> None:
    app.command("export")(export)
