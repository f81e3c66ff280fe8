"""``export``: a focused image (sarcli SLC or NISAR RSLC) -> an interchange format.

Formats are plug-ins in :data:`FORMATS` (``Registry``, entry-point group ``sarcli.export_formats``): an
object with ``name``, ``description``, ``suffix``, ``Options`` (a frozen dataclass, filled with
:func:`sarcli.config.from_mapping` from ``Config.options``) and ``write(slc, output, options, inputs)``.
Built in: ``nisar-rslc`` (:class:`NisarRslcFormat`, the NISAR L1 RSLC layout of
``sarcli.io.nisar.rslc``), ``sicd`` (NGA SICD 1.4 in NITF through sarkit,
:mod:`sarcli.workflows.export_sicd`) and ``envi`` (ENVI complex image with GCP georeferencing,
:mod:`sarcli.workflows.export_envi`). Another format is one more such object; the command does
not change.

``write_format(slc, output, name, options, inputs)`` is the same step for an SLC in memory (``sarcli
focus --format nisar-rslc``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Protocol, runtime_checkable

import numpy as np

from sarcli.config import from_mapping, to_mapping
from sarcli.errors import ConfigError
from sarcli.model.slc import SLC
from sarcli.registry import Registry
from sarcli.workflows.base import Progress, Provenance, Report, refuse_overwriting_inputs, using


@runtime_checkable
class ExportFormat(Protocol):
    """The export plug-in interface (module docstring)."""

    name: str
    description: str
    suffix: str
    Options: type[Any]

    def write(self, slc: SLC, output: Path, options: Any, inputs: tuple[Path, ...]) -> dict[str, Any]: ...


def _check(name: str, obj: Any) -> None:
    for attr in ("name", "description", "suffix", "Options", "write"):
        if not hasattr(obj, attr):
            raise ConfigError(f"export format {name!r} lacks {attr!r}: see sarcli.workflows.export")


FORMATS: Registry[ExportFormat] = Registry("export format", "sarcli.export_formats", {
    "nisar-rslc": "sarcli.workflows.export:NISAR_RSLC",
    "sicd": "sarcli.workflows.export_sicd:SICD",
    "envi": "sarcli.workflows.export_envi:ENVI",
}, check=_check)


@dataclass(frozen=True)
class NisarRslcOptions:
    """polarization: the layer name of the image (HH, HV, VH, VV, LH, LV, RH, RV; a sarcli SLC does not
    record it); frequency: NISAR sub-band letter; mission_id/instrument: identification strings;
    compression: HDF5 compression of the image."""

    polarization: str = "HH"
    frequency: str = "A"
    mission_id: str = "sarcli"
    instrument: str = "sarcli"
    compression: Literal["gzip", "lzf"] | None = None


def spectral_weighting(spec: str, band_hz: float, rate_hz: float, n: int = 256):
    """A sarcli window over a processed band, tabulated as NISAR stores it (``rslc.Weighting``)."""
    from sarcli.focus.windows import parse_window, window
    from sarcli.io.nisar.rslc import Weighting

    kind, p = parse_window(spec)
    f = np.fft.fftshift(np.fft.fftfreq(n)) * rate_hz
    name, shape = {"rect": ("Kaiser", 0.0), "kaiser": ("Kaiser", p), "hamming": ("Cosine", 2.0 * p - 1.0)}[kind]
    return Weighting(window(spec, f / band_hz), name, shape)


def processed_bands(slc: SLC, fmt: str) -> tuple[float, float, float]:
    """(acquired range bandwidth, processed range bandwidth, processed azimuth bandwidth), Hz, from the
    focusing parameters of a sarcli SLC or the RSLC it was read from (``parameters["nisar"]``); an SLC
    that records neither is refused (one line) for the format ``fmt``."""
    from sarcli.focus.rangecomp import chirp_band

    p = slc.parameters or {}
    nisar = p.get("nisar", {})
    acquired = chirp_band(slc.radar) if np.isfinite(slc.radar.chirp_rate_hz_per_s * slc.radar.pulse_length_s) \
        else float(nisar.get("acquired_range_bandwidth_hz", np.nan))
    b_r = acquired * float(p.get("range_bandwidth_fraction", 1.0)) if "range_window" in p \
        else float(nisar.get("processed_range_bandwidth_hz", acquired))
    b_a = float(p.get("azimuth_bandwidth_hz", nisar.get("processed_azimuth_bandwidth_hz", np.nan)))
    for what, v in (("range", b_r), ("azimuth", b_a)):
        if not (np.isfinite(v) and v > 0):
            raise ConfigError(f"the SLC does not record its processed {what} bandwidth: cannot describe it "
                              f"in {fmt}")
    return acquired, b_r, b_a


class NisarRslcFormat:
    """The NISAR L1 RSLC layout (``sarcli.io.nisar.rslc.write_rslc``)."""

    name = "nisar-rslc"
    description = "NISAR L1 RSLC HDF5 layout (opens in ISCE3 / NISAR tools)"
    suffix = ".h5"
    Options = NisarRslcOptions

    def meta(self, slc: SLC, options: NisarRslcOptions, input_names: tuple[str, ...]):
        """The RSLC metadata of an SLC: processed bands and weightings from its focusing parameters
        (a sarcli SLC) or from the RSLC it was read from (``parameters["nisar"]``)."""
        from sarcli.focus.geocode import recorded_height
        from sarcli.io.nisar.rslc import RslcMeta

        p = slc.parameters or {}
        nisar = p.get("nisar", {})
        acquired, b_r, b_a = processed_bands(slc, "an RSLC")
        fs = slc.radar.range_sampling_rate_hz
        rw = spectral_weighting(p["range_window"], b_r, fs) if "range_window" in p else None
        aw = spectral_weighting(p["azimuth_window"], b_a, slc.prf_hz) if "azimuth_window" in p else None
        h = float(nisar["terrain_height_m"]) if "terrain_height_m" in nisar else recorded_height(slc)
        return RslcMeta(processed_range_bandwidth_hz=b_r, processed_azimuth_bandwidth_hz=b_a,
                        acquired_range_bandwidth_hz=acquired, range_weighting=rw, azimuth_weighting=aw,
                        frequency=options.frequency, mission_id=options.mission_id, instrument=options.instrument,
                        terrain_height_m=h, input_names=input_names)

    def write(self, slc: SLC, output: Path, options: NisarRslcOptions, inputs: tuple[Path, ...]) -> dict[str, Any]:
        from sarcli.io.nisar.rslc import write_rslc

        meta = self.meta(slc, options, tuple(Path(i).name for i in inputs))
        write_rslc(output, {options.polarization: slc}, meta, inputs=inputs, compression=options.compression,
                   parameters={"export": {"format": self.name, "options": to_mapping(options)}})
        return {"polarization": options.polarization, "frequency": options.frequency,
                "processed_range_bandwidth_hz": meta.processed_range_bandwidth_hz,
                "processed_azimuth_bandwidth_hz": meta.processed_azimuth_bandwidth_hz}


NISAR_RSLC = NisarRslcFormat()


@dataclass(frozen=True)
class Config:
    """input: a sarcli SLC or a NISAR RSLC; output: the file to write; format: a name in FORMATS;
    options: that format's options; frequency/polarization: the layer of a NISAR RSLC input (a
    sarcli SLC has one: polarization then names it in the output); radiometry: write calibrated
    backscatter (beta0, sigma0, gamma0 on the ellipsoid) in dB instead of the complex samples, for a
    format whose options take it (envi); nisar-rslc and sicd refuse it, as they carry the beta0, sigma0,
    gamma0 and noise tables themselves whenever the SLC has ``/calibration``."""

    input: Path
    output: Path
    format: str = "nisar-rslc"
    options: dict[str, Any] = field(default_factory=dict)
    frequency: str | None = None
    polarization: str | None = None
    radiometry: Literal["beta0", "sigma0", "gamma0"] | None = None


@dataclass
class ExportReport(Report):
    input: str
    output: str
    format: str
    shape: list[int]
    details: dict[str, Any]

    def lines(self) -> list[str]:
        return [f"wrote {self.output} ({self.format}): {self.shape[0]} lines x {self.shape[1]} samples from "
                f"{self.input}", *(f"  {k}: {_rounded(v)}" for k, v in self.details.items())]


def _rounded(value: Any) -> Any:
    """A detail for people: floats to 10 significant digits (30109149, not 30109148.999999996), in
    mappings and lists too."""
    if isinstance(value, float):
        return float(f"{value:.10g}")
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(_rounded(v) for v in value)
    return value


def write_format(slc: SLC, output: Path, name: str, options: dict[str, Any] | None = None,
                 inputs: tuple[Path, ...] = ()) -> dict[str, Any]:
    """Write an in-memory SLC in the format ``name`` (its options from a mapping); returns its details."""
    fmt = FORMATS.get(name)
    opts = from_mapping(fmt.Options, options or {}, f"export format {name}")
    return {"options": to_mapping(opts), **fmt.write(slc, Path(output), opts, tuple(Path(i) for i in inputs))}


def run(config: Config, provenance: Provenance | None = None, progress: Progress | None = None) -> ExportReport:
    """Read ``config.input``, write it as ``config.format`` to ``config.output`` (module docstring)."""
    from sarcli.io.nisar.rslc import read_image, sniff_rslc

    fmt = FORMATS.get(config.format)  # an unknown format is refused before any reading
    takes_radiometry = "radiometry" in getattr(fmt.Options, "__dataclass_fields__", {})
    if config.radiometry is not None and not takes_radiometry:
        raise ConfigError(f"--radiometry has no meaning for --format {config.format}: it writes the complex "
                          "samples (nisar-rslc and sicd carry the beta0, sigma0, gamma0 and noise tables whenever "
                          "the SLC is calibrated); a calibrated image: --format envi")
    refuse_overwriting_inputs([config.input], [config.output])
    with using(provenance):
        # polarization: the layer to read from an RSLC; for a sarcli SLC (one layer) the name it gets
        slc = read_image(config.input, config.frequency, config.polarization if sniff_rslc(config.input) else None)
        if slc.first_full_line > slc.last_full_line:
            warnings.warn(f"{config.input} has no fully focused line (first fully focused line {slc.first_full_line} "
                          f"after the last, {slc.last_full_line}): every line of the export is partly focused",
                          stacklevel=2)
        options = dict(config.options)
        layer = config.polarization or (slc.parameters or {}).get("nisar", {}).get("polarization")
        if layer is not None and "polarization" in getattr(fmt.Options, "__dataclass_fields__", {}):
            options.setdefault("polarization", layer)  # an RSLC layer keeps its name
        if config.radiometry is not None:
            if slc.calibration is None:
                raise ConfigError(f"--radiometry {config.radiometry}: {config.input} carries no radiometric "
                                  "calibration (no /calibration: focus it again with this sarcli)")
            options["radiometry"] = config.radiometry
        details = write_format(slc, config.output, config.format, options, (config.input,))
        if progress is not None:
            progress("export", 1, 1)
    return ExportReport(str(config.input), str(config.output), config.format, list(slc.image.shape), details)
