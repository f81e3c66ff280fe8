"""``gbsar_plan``: the derived system table of a scene TOML or a scan product ([LeeGBSAR-II-2007, Table 1]), the
DF minimum range (eq. 12) and the azimuth resolution by region (eq. 22-45). Writes nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.gbsar.rail import ordered
from sarcli.gbsar.scene import load_scene
from sarcli.gbsar.system import System, azimuth_resolution, build_system
from sarcli.io.scan import read_scan
from sarcli.workflows.base import Progress, Report, using
from sarcli.workflows.gbsar_common import criterion_rad


@dataclass(frozen=True)
class Config:
    """source: scene TOML or scan product; max_range_m: image range Rc (m) for RD's N_xfft (default:
    the scene's ``processing.max_range_m``, else R_max); criterion_deg: the DF phase-error criterion."""

    source: Path
    max_range_m: float | None = None
    criterion_deg: float = 45.0


def _fmt(v: float | None) -> str:
    return "n/a" if v is None else f"{v:.4g}"


@dataclass
class GbsarPlanReport(Report):
    table: dict[str, Any]

    def to_dict(self) -> dict[str, Any]:
        from sarcli.io.h5common import to_jsonable

        return to_jsonable(self.table)

    def lines(self) -> list[str]:
        t = self.table
        mb = 1024 * 1024
        out = [
            f"centre frequency f_c       {t['center_frequency_hz'] / 1e9:.4g} GHz (lambda {t['wavelength_m']:.4f} m)",
            f"bandwidth B_R, N_R         {t['bandwidth_hz'] / 1e6:.4g} MHz, {t['n_r']}",
            f"range resolution dR        {_fmt(t['range_resolution_m'])} m",
            f"frequency step df          {_fmt(t['frequency_step_hz'])} Hz",
            f"R_max = c/(4 df)           {_fmt(t['r_max_m'])} m",
            f"N_Rfft, range pixel        {t['n_rfft']}, {_fmt(t['range_pixel_m'])} m (Table 1 formula "
            f"{_fmt(t['range_pixel_paper_m'])} m)",
            f"rail X, dx, N_x            {t['rail_length_m']:.4g} m, {_fmt(t['rail_step_m'])} m, {t['n_x']}"
            + ("" if t["rail_uniform"] else " (NON-UNIFORM steps: BP only)"),
            f"N_xfft DF / RD             {t['n_xfft_df']} / {t['n_xfft_rd']} (RD for Rc = "
            f"{t['image_max_range_m']:.4g} m)",
            f"DF azimuth pixel, width    {_fmt(t['df_azimuth_pixel_per_rc'])} Rc, "
            f"{_fmt(t['df_azimuth_width_per_rc'])} Rc",
            f"RD azimuth pixel, width    {_fmt(t['rd_azimuth_pixel_m'])} m, {_fmt(t['rd_azimuth_width_m'])} m",
            f"u_R                        {t['doppler_rate_coefficient']:.4g}/R0 1/m^2",
            f"memory DF / RD             {t['memory_df_bytes'] / mb:.3g} MB / "
            f"{(t['memory_rd_bytes'] or 0) / mb:.4g} MB (raw {t['raw_bytes'] / mb:.3g} MB)",
            f"DF minimum range (eq. 12)  {t['df_min_range_m']:.4g} m at criterion "
            f"{math.degrees(t['df_criterion_rad']):g} deg",
            "resolution by region (R0, xc -> region, RD, DF):",
        ]
        out += [f"  {g['r0_m']:>8.4g} m {g['xc_m']:>8.3g} m  {g['region']:>3}  {g['rd_resolution_m']:.3g} m  "
                f"{g['df_resolution_m']:.3g} m" for g in t["resolution_by_region"]]
        return out


def system(config: Config) -> System:
    """Table 1 of the scene or scan (a scan's stops in increasing rail position; an unusable rail refused)."""
    crit = criterion_rad(config.criterion_deg)
    if config.source.suffix.lower() == ".toml":
        sc = load_scene(config.source)
        f, x, lx = sc.frequencies(), sc.positions_m, sc.antenna.length_azimuth_m
        max_range = config.max_range_m if config.max_range_m is not None else sc.processing.get("max_range_m")
    else:
        s = read_scan(config.source)
        if not s.is_rail:
            raise ConfigError(f"{config.source} has 3-D antenna positions or reference ranges: plan derives the "
                              "straight-rail system table ([LeeGBSAR-II-2007, Table 1]), which does not apply to it")
        s, _ = ordered(s)
        f, x, lx, max_range = s.frequency, s.rail_position, s.antenna.length_azimuth_m, config.max_range_m
    return build_system(f, x, lx, max_range, crit)


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarPlanReport:
    """The table, with the RD and DF resolution at ranges up to R_max on the rail axis and at the beam edge."""
    with using(provenance):
        sysp = system(config)
        d = sysp.as_dict()
        top = sysp.r_max_m if sysp.r_max_m < float("inf") else 1000.0
        probes = sorted({r for r in (1, 2, 5, 10, 20, 50, 100, 200, 400, 600) if r <= top} | {round(top, 3)})
        lam, lx, rail = sysp.wavelength_m, sysp.antenna_length_azimuth_m, sysp.rail_length_m
        regions = []
        for r0 in probes:
            for xc in (0.0, rail / 2 + lam * r0 / (2 * lx) / 2):
                reg, rd = azimuth_resolution(r0, xc, rail, lam, lx)
                _, df = azimuth_resolution(r0, xc, rail, lam, lx, "df")
                regions.append({"r0_m": r0, "xc_m": xc, "region": reg, "rd_resolution_m": rd, "df_resolution_m": df})
        d["resolution_by_region"] = regions
        return GbsarPlanReport(table=d)
