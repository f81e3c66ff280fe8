"""Workflow ``ati_compensate``: detect and estimate the movers, compensate each one (H_ph on its slow-time
signal, re-compression) and relocate it to its estimated true position (azimuth y0, range
sqrt(x0^2 + H^2)); write the ATI product with the images before and after (``sarcli.ati.compensation``).

The report gives each mover's peak position, -3 dB azimuth width, the conventional method's position for
comparison, and errors against the truth when the product is simulated. With ``png_dir``: before/after
(and conventional) images and the azimuth PSF plot per mover. LOCAL-frame scenes are not geolocated: no
GeoTIFF is written for them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.errors import ConfigError
from sarcli.workflows import base
from sarcli.workflows.ati_detect import check_pfa, write_product
from sarcli.workflows.ati_estimate import check_choices, estimate_movers, failure_lines


@dataclass(frozen=True)
class Config:
    """raw: two-channel raw product; output: ATI product with image_before and image_after; method: exact
    (R - Rs), quadratic ([Ryu2017, eq. 20]) or conventional (neglects vy y0 / R0); compare: also measure the
    conventional method; png_dir: write before/after images and azimuth PSF plots here; route, unwrap,
    bin, pfa: as for ``ati_estimate``."""

    raw: Path
    output: Path
    method: str = "exact"
    compare: bool = True
    png_dir: Path | None = None
    route: str = "exact"
    unwrap: str = "dechirp"
    bin: str = "track"
    pfa: float = 1e-6

    def __post_init__(self) -> None:
        check_choices(route=self.route, unwrap=self.unwrap, bin=self.bin, method=self.method)
        check_pfa(self.pfa)


@dataclass
class Report(base.Report):
    """movers (estimates) and compensation (one record per mover, ``sarcli.ati.compensation``)."""

    movers: list[dict[str, Any]]
    compensation: list[dict[str, Any]]
    summary: dict[str, Any]
    output: str
    pngs: list[str]

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        return {"movers": d["movers"], "compensation": d["compensation"]}

    def lines(self) -> list[str]:
        out = failure_lines(self.summary)
        for rec in self.compensation:
            out.append(f"mover {rec['id']}: before at y = {rec['before_peak_y_local_m']:.1f} m "
                       f"(width {rec['before_width_3db_m']:.1f} m), after ({rec['method']}) at y = "
                       f"{rec['peak_y_local_m']:.2f} m (width {rec['width_3db_m']:.2f} m)"
                       + (f", conventional at y = {rec['conventional_peak_y_local_m']:.2f} m"
                          if "conventional_peak_y_local_m" in rec else ""))
        return out + [f"wrote {self.output}"]


def _pngs(folder: Path, pair: Any, res: Any, after: Any, conv: Any) -> list[Path]:
    """Before/after (and conventional) quicklooks around the mover and its azimuth PSF plot."""
    import numpy as np

    from sarcli.ati.compensation import true_window, y_local
    from sarcli.ati.pipeline import psf_cut
    from sarcli.ati.plots import psf_plot
    from sarcli.io.images import write_quicklook

    mid = res.candidate.id
    n = pair.z0.shape[0]
    ranges = pair.slc0.slant_range
    cols = slice(max(0, res.cols.start - 20), min(ranges.size, res.cols.stop + 20))
    ys = np.asarray(y_local(pair, np.arange(n)), np.float64)
    centre = int(np.argmin(np.abs(ys - res.y_local_m)))
    half = max(res.rows.stop - res.rows.start, 120)
    rows = slice(max(0, min(res.rows.start, centre) - half // 2), min(n, max(res.rows.stop, centre) + half // 2))
    ext = [float(ranges[cols.start]), float(ranges[cols.stop - 1]), float(ys[rows.stop - 1]), float(ys[rows.start])]
    # one dB scale for before / after / conventional: white at the brightest pixel of any of them, 40 dB deep,
    # so the focused mover is visibly brighter than its smeared self
    top = max(float(np.max(np.abs(x[rows, cols]))) for x in (pair.z0, after, conv) if x is not None)
    vmax = 20.0 * np.log10(max(top, float(np.finfo(np.float32).tiny)))
    kw = {"extent": ext, "xlabel": "slant range (m)", "ylabel": "azimuth y (m)", "vmin": vmax - 40.0, "vmax": vmax,
          "colorbar_label": "amplitude (dB, one scale for every panel)"}
    written = [folder / f"mover{mid}_before.png", folder / f"mover{mid}_after.png"]
    write_quicklook(written[0], pair.z0[rows, cols], title="before compensation", **kw)
    write_quicklook(written[1], after[rows, cols], title="after compensation (proposed)", **kw)
    prof = {}
    _, _, cb = psf_cut(pair.z0, res.rows, res.cols)
    prof["before"] = (ys, cb)
    win_r, win_c = true_window(pair, res)
    _, _, ca = psf_cut(after, win_r, win_c)
    prof["proposed"] = (ys, ca)
    if conv is not None:
        written.append(folder / f"mover{mid}_conventional.png")
        write_quicklook(written[-1], conv[rows, cols], title="conventional compensation", **kw)
        _, _, cc = psf_cut(conv, win_r, win_c)
        prof["conventional"] = (ys, cc)
    written.append(folder / f"mover{mid}_psf.png")
    psf_plot({k: (y[rows], v[rows]) for k, (y, v) in prof.items()}, written[-1], f"azimuth PSF, mover {mid}")
    return written


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Detect, estimate, compensate, write (module docstring)."""
    from sarcli.ati.compensation import compensate_movers
    from sarcli.ati.evaluation import truth_movers

    with base.using(provenance):
        base.refuse_overwriting_inputs([config.raw], [config.output, config.png_dir], folders=[config.png_dir])
        if config.png_dir is not None and config.png_dir.exists() and not config.png_dir.is_dir():
            raise ConfigError(f"png_dir: {config.png_dir} is not a folder")
        raw, pair, summary, results = estimate_movers(config.raw, config.route, config.unwrap, config.bin,
                                                      config.pfa)
        after = pair.z0
        records, pngs = [], []
        for i, m in enumerate(compensate_movers(pair, results, config.method, config.compare, truth_movers(raw))):
            records.append(m.record)
            after = m.after
            if config.png_dir is not None:
                config.png_dir.mkdir(parents=True, exist_ok=True)
                pngs += _pngs(config.png_dir, pair, m.result, m.after, m.conventional)
            if progress is not None:
                progress("compensating", i + 1, len(results))
        movers = [r.as_dict() for r in results]
        write_product(config.output, config.raw, pair, summary, movers, "ati_compensate", config, after=after)
        return Report(movers, records, summary, str(config.output), [str(p) for p in pngs])
