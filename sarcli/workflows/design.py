"""Workflow ``design``: the SAR design calculator (relations of [KimAODCCD, §2.4], ``sarcli.design``) with a verdict
per constraint, from a design TOML (``[design]`` table), a stripmap or GB-SAR scene TOML, a raw product
or a GB-SAR scan. A violated constraint is reported, not an error."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.workflows import base


@dataclass(frozen=True)
class Config:
    """source: design TOML, stripmap or GB-SAR scene TOML, raw product or GB-SAR scan (.h5)."""

    source: Path


@dataclass
class Report(base.Report):
    """report: resolutions, PRF window and options, constraints, notes, verdict (``--json``)."""

    report: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.report)

    def lines(self) -> list[str]:
        r = self.report
        lines = [f"design of {r['source']} ({r['platform']})",
                 f"  wavelength                 {r['wavelength_m']:.5f} m",
                 f"  bandwidth                  {r['bandwidth_hz'] / 1e6:.3f} MHz",
                 f"  slant-range resolution     {r['slant_range_resolution_m']:.2f} m   c/(2B)",
                 f"  ground-range resolution    {r['ground_range_resolution_m']:.2f} m   c/(2B sin i)",
                 f"  azimuth resolution         {r['azimuth_resolution_m']:.2f} m"]
        if r["platform"] == "gbsar":
            lines += [f"  unambiguous range          {r['r_max_m']:.1f} m   c/(4 df)",
                      f"  rail-limited beyond        {r['rail_limited_beyond_m']:.1f} m"]
            for x in r["resolution_by_range"]:
                lines.append(f"    R = {x['range_m']:8.1f} m: azimuth {x['azimuth_resolution_m']:.3f} m, "
                             f"region {x['region']}")
            for c in r["constraints"]:
                lines.append(f"  [{'ok' if c['ok'] else 'VIOLATED'}] {c['name']}: {c['value']:.4g} vs "
                             f"{c['limit']:.4g} ({c['relation']})")
        else:
            lines += [f"  slant range (centre)       {r['slant_range_m']:.1f} m, "
                      f"incidence {r['incidence_angle_deg']:.2f} deg",
                      f"  swath (slant)              {r['swath_slant_m']:.1f} m",
                      _prf_window_line(r),
                      "  PRF options:"]
            for o in r["prf_options"]:
                broken = ", ".join(c["name"] for c in o["constraints"] if not c["ok"])
                lines.append(f"    {o['prf_hz']:9.1f} Hz: N = {o['doppler_samples']:5d} Doppler samples, "
                             f"aperture {o['synthetic_aperture_m']:.2f} m, azimuth {o['azimuth_resolution_m']:.2f} m "
                             f"-> {'VIOLATES ' + broken if broken else 'ok'}")
        lines += [f"  note: {n}" for n in r["notes"]]
        lines.append("  verdict: " + ("all constraints met" if r["ok"] else "; ".join(r["violations"])))
        return lines


def _prf_window_line(r: dict) -> str:
    lo = f"  PRF window                 {r['prf_min_hz']:.1f} Hz < PRF"
    lo_why = ("2v/D" if any("2v/D" in c["relation"] for o in r["prf_options"] for c in o["constraints"])
              else "processed Doppler bandwidth v / delta_az: no antenna length given")
    if r["platform"] == "spaceborne":
        return (f"{lo}  ({lo_why}); upper bound: the echo-window timing per PRF below (the one-pulse-in-flight "
                f"bound c/(2 R_max) = {r['prf_max_hz']:.1f} Hz does not apply in orbit)")
    return f"{lo} < {r['prf_max_hz']:.1f} Hz  (lower: {lo_why}; upper: c/(2 R_max))"


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Evaluate the design (module docstring)."""
    from sarcli.design.params import load
    from sarcli.design.report import evaluate

    with base.using(provenance):
        params = load(config.source)
        try:
            return Report(evaluate(params))
        except ValueError as e:
            raise ConfigError(f"{config.source}: {e}") from None
