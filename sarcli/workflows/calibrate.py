"""``sarcli calibrate``: the absolute calibration constant K of an SLC from corner reflectors.

For every reflector of the CSV in service for radiometry at the acquisition and inside the image
(:func:`sarcli.calibration.analysis.analyse`), the integrated-energy RCS measured with the product's
current calibration against the trihedral's theoretical RCS along the line of sight gives the error
e_i = sigma_meas / sigma_theory. Since sigma_meas is proportional to 1 / K, the constant that makes the
reflectors right is K_new = K_old * mean(e_i) (the mean of the linear ratios: the estimate of the gain
that is unbiased for independent errors of equal variance [Freeman1992, sec. IV]); the spread of the
e_i (dB) is reported as the calibration's uncertainty. The product's /calibration is rewritten with the
LUTs divided by K_new / K_old (``radiometry.rescaled``), the constant recorded as measured; written
atomically: to ``output``, or in place (a copy renamed over the input once complete).
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sarcli.errors import ConfigError, SarcliError
from sarcli.workflows.base import Progress, Provenance, Report, refuse_overwriting_inputs, using


@dataclass(frozen=True)
class Config:
    """slc: a sarcli SLC (from ``sarcli focus``); reflectors: the corner-reflector CSV; output: the calibrated
    SLC to write (default: the input, rewritten atomically); search_px: the peak search (pixels)."""

    slc: Path
    reflectors: Path
    output: Path | None = None
    search_px: int = 8

    def __post_init__(self) -> None:
        if not 1 <= self.search_px <= 64:
            raise ConfigError(f"search_px must be 1..64 pixels, got {self.search_px}")


@dataclass
class CalibrateReport(Report):
    slc: str
    output: str
    constant_before: float
    constant: float
    reflectors: list[dict]
    spread_db: float
    notes: list[str]

    def lines(self) -> list[str]:
        out = [f"{self.output}: K = {self.constant:.6g} (was {self.constant_before:.6g}) from "
               f"{len(self.reflectors)} reflector(s), spread {self.spread_db:.2f} dB"]
        out += [f"{r['id']}: RCS {r['rcs_dbsm']:.2f} dBm2 measured, {r['rcs_theory_dbsm']:.2f} dBm2 theory "
                f"({r['rcs_error_db']:+.2f} dB before)" for r in self.reflectors]
        return out + [f"note: {n}" for n in self.notes]


def run(config: Config, provenance: Provenance | None = None, progress: Progress | None = None) -> CalibrateReport:
    """Derive K and write it (module docstring)."""
    import h5py

    from sarcli.calibration.analysis import analyse
    from sarcli.calibration.radiometry import rescaled
    from sarcli.calibration.reflectors import VALIDITY_RAD_POL, parse_reflectors
    from sarcli.io.atomic import atomic_path
    from sarcli.io.h5common import cf_time_units
    from sarcli.io.slc import read_slc, write_calibration

    out = Path(config.output) if config.output is not None else Path(config.slc)
    with using(provenance):
        if config.output is not None:
            refuse_overwriting_inputs([config.slc, config.reflectors], [config.output])
        reflectors = parse_reflectors(config.reflectors)
        slc = read_slc(config.slc)
        if slc.calibration is None:
            raise SarcliError(f"{config.slc}: the SLC carries no radiometric calibration (focus it with this sarcli)")
        res = analyse(slc, reflectors, config.search_px, need=VALIDITY_RAD_POL)
        used = [r for r in res.results if np.isfinite(r.rcs_error_db)]
        if not used:
            raise SarcliError(f"{config.reflectors}: no reflector in service for radiometry was measured in the "
                              f"image ({len(res.outside)} outside it)")
        err = np.array([r.rcs_error_db for r in used])
        ratio = float(np.mean(10.0 ** (err / 10.0)))
        k_old = slc.calibration.constant
        k_new = k_old * ratio
        cal = rescaled(slc.calibration, k_new, f"measured on {len(used)} corner reflector(s) by sarcli calibrate")
        cal.details["reflectors"] = [r.id for r in used]
        cal.details["reflector_errors_db"] = [float(e) for e in err]
        with atomic_path(out) as tmp:
            shutil.copyfile(config.slc, tmp)
            with h5py.File(tmp, "r+") as f:
                write_calibration(f, cal, cf_time_units(slc.epoch_utc), slc.slant_range)
    spread = float(np.std(err)) if err.size > 1 else 0.0
    recs = [{"id": r.id, "rcs_dbsm": r.rcs_dbsm, "rcs_theory_dbsm": r.rcs_theory_dbsm,
             "rcs_error_db": r.rcs_error_db} for r in used]
    return CalibrateReport(str(config.slc), str(out), k_old, k_new, recs, spread, list(res.notes))
