"""``quality --corner-reflectors``: point-target and geolocation analysis with surveyed corner reflectors.

Input: a focused image (sarcli SLC, or a NISAR RSLC as sarcli or ISCE3 writes it) with an Earth orbit,
and a corner-reflector CSV (NISAR or UAVSAR format, ``sarcli.calibration.reflectors``). For every
reflector in service and inside the image: measured minus predicted position (range, along track, in
metres), IRW, PSLR, ISLR in range and azimuth, the theoretical IRWs of the product's bands and windows,
and the corrections to add before reading an offset as a geometry error (``sarcli.calibration``).
Optional: one IRF picture per reflector (``plots``: a folder, ``cr_<id>.png``).

``Report.records()`` is the machine-readable form of ``--json``: one object per reflector with exactly
the keys of ``sarcli.calibration.analysis.RECORD_KEYS``; ``Report.to_dict()`` holds everything.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from sarcli.errors import ConfigError
from sarcli.workflows.base import Progress, Provenance, Report, refuse_overwriting_inputs, using

VALIDITY_NEEDED = {"any": 0, "ipr": 1, "radiometry": 2, "geometry": 4}


@dataclass(frozen=True)
class Config:
    """slc: the image; reflectors: the CSV; plots: a folder for one PNG per reflector (none: no plots);
    frequency/polarization: the RSLC layer (default: the first frequency, HH); search_px: the peak is
    searched +-search_px pixels around the prediction; wet_zenith_delay_m: the zenith wet delay assumed
    for the tropospheric estimate; validity: the reflectors' validity flag required (any = in service)."""

    slc: Path
    reflectors: Path
    plots: Path | None = None
    frequency: str | None = None
    polarization: str | None = None
    search_px: int = 8
    wet_zenith_delay_m: float = 0.15
    validity: Literal["any", "ipr", "radiometry", "geometry"] = "any"

    def __post_init__(self) -> None:
        if self.search_px < 1 or self.search_px > 64:
            raise ConfigError(f"search_px must be 1..64 pixels, got {self.search_px}")
        if not 0.0 <= self.wet_zenith_delay_m <= 1.0:
            raise ConfigError(f"wet_zenith_delay_m must be within 0..1 m, got {self.wet_zenith_delay_m}")


CORRECTIONS_NOTE = [
    "troposphere: one-way slant delay (ZHD Saastamoinen with standard-atmosphere pressure + assumed ZWD) / "
    "cos(incidence): lengthens the range; the estimate is per reflector (troposphere_slant_delay_m)",
    "ionosphere: 40.3 TEC / f^2 per one way; at L-band 0.25-0.35 m per TEC unit: metres for typical TEC (5-50 "
    "TECU), and along-track shifts where TEC varies; needs a TEC map (ionosphere_slant_delay_per_tecu_m)",
    "solid-earth tide: up to ~0.3 m vertical, 0.05 m horizontal (IERS 2010): up to ~0.3 m in slant range",
    "processor conventions: azimuth time reference (the sensor moves v R / c, ~20 m, during the two-way travel: "
    "bistatic_along_track_m), internal range delay, the reflector's phase centre (apex) vs the surveyed point",
    "plate motion: applied from the CSV's velocity (plate_motion_m)",
]


@dataclass
class CornerReflectorReport(Report):
    slc: str
    reflectors_csv: str
    acquisition_utc: str
    theory: dict[str, Any]
    reflectors: list[dict[str, Any]]
    outside_image: list[str]
    plots: list[str]
    corrections: list[str] = field(default_factory=lambda: list(CORRECTIONS_NOTE))
    notes: list[str] = field(default_factory=list)

    def records(self) -> list[dict[str, Any]]:
        """One object per measured reflector with exactly the RECORD_KEYS (``--json``)."""
        from sarcli.calibration.analysis import RECORD_KEYS
        from sarcli.io.h5common import to_jsonable

        return [to_jsonable({k: r[k] for k in RECORD_KEYS}) for r in self.reflectors]

    def lines(self) -> list[str]:
        th = self.theory
        out = [f"{self.slc}: {len(self.reflectors)} reflector(s) measured, {len(self.outside_image)} outside the image "
               f"(acquisition {self.acquisition_utc})",
               f"theory: range IRW {th['range_irw_m']:.3f} m ({th['range_bandwidth_hz'] / 1e6:.3f} MHz, "
               f"{th['range_window']}), azimuth IRW {th['azimuth_irw_s'] * 1e3:.4f} ms x ground speed "
               f"({th['azimuth_bandwidth_hz']:.1f} Hz, {th['azimuth_window']})"]
        for r in self.reflectors:
            c = r["corrections"]
            out.append(f"{r['id']}: offset rg {r['range_offset_m']:+.3f} m ({r['range_offset_px']:+.3f} px), az "
                       f"{r['azimuth_offset_m']:+.3f} m ({r['azimuth_offset_px']:+.3f} px); IRW rg "
                       f"{r['range_irw_m']:.3f} m (theory {r['range_irw_theory_m']:.3f}), "
                       f"az {r['azimuth_irw_m']:.3f} m (theory {r['azimuth_irw_theory_m']:.3f}); "
                       f"PSLR rg {r['range_pslr_db']:.2f} dB, az {r['azimuth_pslr_db']:.2f} dB; "
                       f"ISLR rg {r['range_islr_db']:.2f} dB, az {r['azimuth_islr_db']:.2f} dB; "
                       f"troposphere ~{c['troposphere_slant_delay_m']:.2f} m slant (incidence "
                       f"{r['incidence_deg']:.1f} deg), ionosphere "
                       f"{c['ionosphere_slant_delay_per_tecu_m']:.3f} m per TECU; RCS {r['rcs_dbsm']:.2f} dBm2 "
                       f"(trihedral theory {r['rcs_theory_dbsm']:.2f}, {r['rcs_error_db']:+.2f} dB)")
        if self.outside_image:
            out.append(f"outside the image: {', '.join(self.outside_image)}")
        out += [f"note: {n}" for n in self.notes]
        out += [f"correction to consider: {c}" for c in self.corrections]
        return out


def _plot_name(cid: str) -> str:
    return "cr_" + re.sub(r"[^A-Za-z0-9_.-]+", "_", cid) + ".png"


def run(config: Config, provenance: Provenance | None = None,
        progress: Progress | None = None) -> CornerReflectorReport:
    """The corner-reflector analysis (module docstring). Writes only the plots (never an input)."""
    from sarcli.calibration.analysis import analyse
    from sarcli.calibration.reflectors import parse_reflectors
    from sarcli.io.nisar.rslc import read_image

    if config.plots is not None and not Path(config.plots).is_dir():
        raise ConfigError(f"plot folder {config.plots} does not exist: create it first")
    with using(provenance):
        reflectors = parse_reflectors(config.reflectors)
        if config.plots is not None:  # every picture the CSV could give, checked before any work
            refuse_overwriting_inputs([config.slc, config.reflectors],
                                      sorted({Path(config.plots) / _plot_name(r.id) for r in reflectors}))
        slc = read_image(config.slc, config.frequency, config.polarization)
        res = analyse(slc, reflectors, config.search_px, config.wet_zenith_delay_m, VALIDITY_NEEDED[config.validity])
        plots = []
        if config.plots is not None:
            from sarcli.calibration.plots import plot_reflector

            names = [Path(config.plots) / _plot_name(r.id) for r in res.results]
            dr = float(slc.slant_range[1] - slc.slant_range[0])
            for i, (r, name) in enumerate(zip(res.results, names, strict=True)):
                plot_reflector(name, slc.image, r, dr, title=f"{Path(config.slc).name}: corner reflector {r.id}")
                plots.append(str(name))
                if progress is not None:
                    progress("plots", i + 1, len(names))
    th_r, th_a = res.range_theory, res.azimuth_theory
    theory = {"range_bandwidth_hz": th_r.bandwidth_hz, "range_window": th_r.window, "range_window_factor": th_r.factor,
              "range_irw_m": th_r.irw, "azimuth_bandwidth_hz": th_a.bandwidth_hz, "azimuth_window": th_a.window,
              "azimuth_window_factor": th_a.factor, "azimuth_irw_s": th_a.irw}
    return CornerReflectorReport(str(config.slc), str(config.reflectors), res.acquisition_utc, theory,
                                 [vars(r) for r in res.results], res.outside, plots, notes=res.notes)
