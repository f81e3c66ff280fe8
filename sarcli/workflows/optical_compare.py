"""Workflow ``optical_compare``: the emulated AOD/CCD processor of [KimAODCCD] (ideal, each device limitation
alone, all with and without bias removal) against the digital Range-Doppler image of the same simulated
point-target scene (``sarcli.optical.compare``); optionally the comparison figure."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.workflows import base


def settings(reference_offset_hz: float | None, magnification: str, adc_bits: int) -> Any:
    from sarcli.optical.devices import CCD, OpticalSettings

    return OpticalSettings(ccd=CCD(adc_bits=adc_bits), reference_offset_hz=reference_offset_hz,
                           magnification=magnification)


@dataclass(frozen=True)
class Config:
    """raw: simulated airborne raw product with truth; plot: write the comparison figure (PNG);
    reference_offset_hz: dnu = nu2 - nu1 (default the rule dnu = B of [KimAODCCD]); magnification: carrier (pixels
    sample the carrier) or fit_aod; adc_bits: read-out converter bits; centre_range_m: slant range at the
    CCD's centre column (default the brightest target's); quick: skip the one-limitation-at-a-time images."""

    raw: Path
    plot: Path | None = None
    reference_offset_hz: float | None = None
    magnification: str = "carrier"
    adc_bits: int = 8
    centre_range_m: float | None = None
    quick: bool = False

    def __post_init__(self) -> None:
        settings(self.reference_offset_hz, self.magnification, self.adc_bits)  # checked before any work


@dataclass
class Report(base.Report):
    """report: design, seed coefficients, predictions and one row per image (``--json``)."""

    report: dict[str, Any]
    plot: str | None = None

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.report)

    def lines(self) -> list[str]:
        p, d = self.report["predictions"], self.report["design"]
        out = [f"design: dnu = {d['reference_offset_hz'] / 1e6:.2f} MHz, pixel = {d['pixel_delay_s'] * 1e9:.2f} ns "
               f"(magnification {d['magnification']:.3f}), swath {d['swath_slant_m']:.0f} m, "
               f"{d['rows_integrated']} rows integrated",
               f"predicted: range IRW {p['irw_range_m']:.2f} m, azimuth IRW (CCD rows) {p['irw_azimuth_ccd_m']:.2f} m, "
               f"light-pulse gain {p['light_pulse_gain']:.3f}, pixel gain {p['ccd_pixels_gain']:.3f}",
               f"{'image':40s} {'s':>6s} {'dR m':>6s} {'dAz m':>6s} {'IRW r':>6s} {'IRW az':>6s} "
               f"{'PSLR r':>7s} {'PSLR az':>7s} {'DR dB':>6s} {'peak':>8s}"]
        for r in self.report["rows"]:
            out.append(f"{r['processor']:40s} {r['seconds']:6.2f} {r['range_error_m']:6.2f} "
                       f"{r['azimuth_error_m']:6.2f} {r['irw_range_m']:6.2f} {r['irw_azimuth_m']:6.2f} "
                       f"{r['pslr_range_db']:7.1f} {r['pslr_azimuth_db']:7.1f} {r['dynamic_range_db']:6.1f} "
                       f"{r['peak_amplitude']:8.1f}")
        return out


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Compare (module docstring)."""
    from sarcli.io.raw import read_raw
    from sarcli.optical.compare import cases, compare
    from sarcli.optical.plot import comparison_png

    with base.using(provenance):
        base.refuse_overwriting_inputs([config.raw], [config.plot])
        raw = read_raw(config.raw)
        total = len(cases(not config.quick)) + 1
        done = 0

        def step(_label: str) -> None:
            nonlocal done
            done += 1
            if progress is not None:
                progress("images", done, total)

        report = compare(raw, settings(config.reference_offset_hz, config.magnification, config.adc_bits),
                         centre_range_m=config.centre_range_m, single_limitations=not config.quick,
                         keep_images=config.plot is not None, on_step=step)
        images = report.pop("images", None)
        if config.plot is not None:
            comparison_png(config.plot, images,
                           title=f"{config.raw.name}: digital RD vs emulated AOD/CCD processor")
        return Report(report, None if config.plot is None else str(config.plot))
