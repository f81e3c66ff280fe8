"""``gbsar_import``: frequency-sweep files (MATLAB, NumPy, CSV, Touchstone) -> a GB-SAR scan product.

The files' samples, frequencies, antenna positions (1-D rail positions or a 3-D track) and optional
reference ranges (:mod:`sarcli.io.sweeps`) become one ``gbsar_scan`` (:mod:`sarcli.io.scan`; schema 2
when it has a 3-D track or reference ranges), which ``gbsar focus`` focuses: a rail scan with every
algorithm, a 3-D or referenced one with ``--algorithm bp --grid``. The report says what was read
under which name, how a sample matrix was oriented (frequency x position or position x frequency,
from the lengths), and the polarization's origin (the option, a token of the file names, else VV).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from orbit.timeutil import format_utc, parse_utc
from sarcli.errors import ConfigError
from sarcli.io.scan import write_scan
from sarcli.io.sweeps import Names, polarization_from_names, read_sweeps, to_scan
from sarcli.model.gbsar import Antenna
from sarcli.workflows.base import Progress, Report, using
from sarcli.workflows.gbsar_common import guard, parameters


@dataclass(frozen=True)
class Config:
    """The ``sarcli gbsar import`` options: ``inputs`` (one format; several concatenate along the
    positions), ``output`` scan; the names to read (None: the usual names; :class:`sarcli.io.sweeps.Names`);
    ``layout`` of a square matrix; ``pol`` (None: from the file names, else VV); ``height_m`` the antenna
    height of 1-D rail positions; ``antenna_length_m`` L_x (m) for the rail focusers' beam footprint
    (None: the default antenna, 0.25 m); ``epoch_utc`` of the scan (ISO-8601)."""

    inputs: tuple[Path, ...]
    output: Path
    data: str | None = None
    frequency: str | None = None
    position: str | None = None
    reference_range: str | None = None
    layout: Literal["auto", "frequency-position", "position-frequency"] = "auto"
    pol: str | None = None
    height_m: float = 0.0
    antenna_length_m: float | None = None
    epoch_utc: str = "2000-01-01T00:00:00Z"

    def __post_init__(self) -> None:
        if self.antenna_length_m is not None and not self.antenna_length_m > 0:
            raise ConfigError(f"--antenna-length must be > 0 m, got {self.antenna_length_m:g}")
        try:
            object.__setattr__(self, "epoch_utc", format_utc(parse_utc(self.epoch_utc)))
        except ValueError:
            raise ConfigError(f"--epoch must be an ISO-8601 UTC time such as 2000-01-01T00:00:00Z, "
                              f"got {self.epoch_utc!r}") from None


@dataclass
class GbsarImportReport(Report):
    """What was imported: sizes, the names read, the layout taken, the polarization and notes."""

    output: str
    n_files: int
    n_sweeps: int
    n_frequencies: int
    frequency_hz: tuple[float, float]
    format: str
    used: dict[str, str]
    layout: str
    track: str
    polarization: str
    polarization_from: str
    flagged_sweeps: list[int] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def lines(self) -> list[str]:
        names = ", ".join(f"{k} = {v}" for k, v in self.used.items())
        out = [f"wrote {self.output}: {self.n_sweeps} sweeps x {self.n_frequencies} frequencies "
               f"({self.frequency_hz[0] / 1e9:.6g}-{self.frequency_hz[1] / 1e9:.6g} GHz), {self.track} "
               f"positions, {self.polarization} ({self.polarization_from}), from {self.n_files} {self.format} "
               f"file(s)", f"read {names}; samples laid out {self.layout}"]
        if self.flagged_sweeps:
            out.append(f"flagged {len(self.flagged_sweeps)} sweep(s) holding NaN/inf (focusing skips them): "
                       f"{self.flagged_sweeps[:10]}")
        return out + self.notes


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarImportReport:
    """Read ``config.inputs`` and write the scan ``config.output``."""
    with using(provenance):
        guard(config.inputs, [config.output])
        names = Names(data=config.data, frequency=config.frequency, position=config.position,
                      reference_range=config.reference_range, layout=config.layout)
        sw = read_sweeps(config.inputs, names)
        from_names = polarization_from_names(config.inputs)
        pol, origin = ((config.pol.upper(), "--pol") if config.pol else (from_names, "from the file names")
                       if from_names else ("VV", "default"))
        track = "3-D" if sw.position.ndim == 2 else "rail"
        instrument: dict[str, Any] = {f"import_{k}": v for k, v in sw.used.items()}
        instrument.update(import_format=sw.format, import_layout=sw.layout,
                          import_files=",".join(p.name for p in config.inputs))
        antenna = Antenna(length_azimuth_m=config.antenna_length_m) if config.antenna_length_m else Antenna()
        scan = to_scan(sw, pol, config.height_m, antenna, config.epoch_utc, instrument)
        write_scan(config.output, scan, parameters=parameters(config), inputs=tuple(config.inputs))
        notes = list(sw.notes)
        flags = () if scan.stop_flags is None else scan.stop_flags  # to_scan sets one flag per sweep
        if track == "rail" and config.antenna_length_m is None:
            notes.append(f"antenna L_x {antenna.length_azimuth_m:g} m assumed for the rail focusers' beam footprint "
                         "(--antenna-length)")
        return GbsarImportReport(
            output=str(config.output), n_files=len(config.inputs), n_sweeps=scan.n_stops,
            n_frequencies=int(sw.frequency.size), frequency_hz=(float(sw.frequency[0]), float(sw.frequency[-1])),
            format=sw.format, used=sw.used, layout=sw.layout.replace("-", " x "), track=track, polarization=pol,
            polarization_from=origin, flagged_sweeps=[int(i) for i, f in enumerate(flags) if f],
            notes=notes)
