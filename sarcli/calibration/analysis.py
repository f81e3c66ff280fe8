"""Corner-reflector analysis of a focused image: predicted vs measured position, IRF metrics, theory.

For every reflector of the CSV in service at the acquisition (``reflectors.select``): its position at
the acquisition, the predicted pixel (``predict``), and when that pixel is inside the image the
measured peak and impulse response (``sarcli.focus.quality.point_target_metrics``, the peak searched
within +-``search`` pixels of the prediction). Offsets are measured minus predicted: range in slant
metres (``(col_meas - col_pred) dr``), azimuth in metres along track on the ground at the reflector
(``(row_meas - row_pred) ds``, ds from ``predict``). IRWs in the same metres; the theoretical IRWs
from ``irf.theory`` (range: slant metres; azimuth: seconds x the ground speed ds / dt at the
reflector). The acquisition time is the image's mid zero-Doppler time.

Radiometry (a product with a radiometric calibration, :mod:`sarcli.calibration.radiometry`): the
reflector's RCS by integrated energy (:func:`~sarcli.calibration.radiometry.point_rcs`) against the
theoretical RCS of a triangular trihedral of its side seen from the radar's line of sight at the zero-Doppler
time (:func:`~sarcli.calibration.radiometry.reflector_rcs`: 4 pi a^4 / (3 lam^2) on its boresight, the
trihedral's pattern off it); ``rcs_error_db`` = measured - theory (dB), what ``sarcli calibrate`` removes.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from sarcli.calibration.irf import AxisTheory, theory
from sarcli.calibration.predict import corrections, image_orbit, predict
from sarcli.calibration.reflectors import CornerReflector, position_at, select
from sarcli.errors import ConfigError, SarcliError
from sarcli.model.slc import SLC

#: the keys of one reflector's record (``sarcli quality --corner-reflectors --json``), in this order
RECORD_KEYS = ("id", "range_offset_m", "azimuth_offset_m", "range_irw_m", "azimuth_irw_m", "range_pslr_db",
               "azimuth_pslr_db", "range_islr_db", "azimuth_islr_db", "rcs_dbsm", "rcs_theory_dbsm",
               "rcs_error_db")


@dataclass
class ReflectorResult:
    """Everything measured and predicted for one reflector inside the image (module docstring)."""

    id: str
    range_offset_m: float
    azimuth_offset_m: float
    range_irw_m: float
    azimuth_irw_m: float
    range_pslr_db: float
    azimuth_pslr_db: float
    range_islr_db: float
    azimuth_islr_db: float
    range_irw_theory_m: float
    azimuth_irw_theory_m: float
    range_offset_px: float
    azimuth_offset_px: float
    predicted_row: float
    predicted_col: float
    measured_row: float
    measured_col: float
    zero_doppler_time_s: float
    slant_range_m: float
    along_track_spacing_m: float
    incidence_deg: float
    peak_amplitude: float
    survey_utc: str | None
    validity: int
    plate_motion_m: float
    corrections: dict = field(default_factory=dict)
    rcs_dbsm: float = float("nan")
    rcs_theory_dbsm: float = float("nan")
    rcs_error_db: float = float("nan")

    def record(self) -> dict:
        """Exactly :data:`RECORD_KEYS` (the JSON object of ``--json``)."""
        return {k: getattr(self, k) for k in RECORD_KEYS}


@dataclass
class Analysis:
    """Results per reflector inside the image, the IDs outside it, the theory, notes."""

    acquisition_utc: str
    results: list[ReflectorResult]
    outside: list[str]
    range_theory: AxisTheory
    azimuth_theory: AxisTheory
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return asdict(self)


def analyse(slc: SLC, reflectors: list[CornerReflector], search: int = 8, wet_zenith_m: float = 0.15,
            need: int = 0) -> Analysis:
    """The corner-reflector analysis of ``slc`` (module docstring). ``need``: validity flags required."""
    from orbit.timeutil import add_seconds
    from sarcli.focus.quality import point_target_metrics

    if search < 1:
        raise ConfigError(f"search must be at least 1 pixel, got {search}")
    if slc.azimuth_time.size < 2 or slc.slant_range.size < 2 or slc.image.shape != (slc.azimuth_time.size,
                                                                                     slc.slant_range.size):
        raise SarcliError(f"image {slc.image.shape} too small or not matching its axes: nothing to measure")
    sv = image_orbit(slc)
    acq = add_seconds(slc.epoch_utc, float(0.5 * (slc.azimuth_time[0] + slc.azimuth_time[-1])))
    kept, notes = select(reflectors, acq, need)
    th_r, th_a = theory(slc)
    if "rect (the product records no weighting" in th_r.window + th_a.window:
        notes.append("the product records no spectral weighting: the theoretical IRWs assume rect windows")
    dt = float((slc.azimuth_time[-1] - slc.azimuth_time[0]) / (slc.azimuth_time.size - 1))
    dr = float((slc.slant_range[-1] - slc.slant_range[0]) / (slc.slant_range.size - 1))
    results, outside = [], []
    for cr in kept:
        p, since = position_at(cr, acq)
        pred = predict(slc, sv, p, cr.height_m)
        if pred is None or not pred.inside:
            outside.append(cr.id)
            continue
        try:
            m = point_target_metrics(slc.image, pred.row, pred.col, search=search)
        except SarcliError as e:
            notes.append(f"{cr.id}: not measured ({e})")
            continue
        if abs(round(m["row"]) - round(pred.row)) >= search or abs(round(m["col"]) - round(pred.col)) >= search:
            notes.append(f"{cr.id}: the peak is at the edge of the +-{search} px search window: the reflector may "
                         "lie farther from its prediction, or be outshone by a neighbour")
        ds = pred.along_track_spacing_m
        d_row, d_col = m["row"] - pred.row, m["col"] - pred.col
        motion = float(np.linalg.norm(np.asarray(cr.velocity_enu_mps)) * abs(since))
        corr = corrections(cr.latitude_deg, cr.height_m, pred.incidence_deg, slc.radar.carrier_frequency_hz,
                           pred.slant_range_m, float(np.linalg.norm(sv.interpolate(
                               np.array([pred.zero_doppler_time_s]))[1])))
        rcs = _rcs(slc, sv, cr, p, m, pred.zero_doppler_time_s, notes)
        results.append(ReflectorResult(
            id=cr.id, range_offset_m=d_col * dr, azimuth_offset_m=d_row * ds,
            range_irw_m=m["irw_range_px"] * dr, azimuth_irw_m=m["irw_azimuth_px"] * ds,
            range_pslr_db=m["pslr_range_db"], azimuth_pslr_db=m["pslr_azimuth_db"],
            range_islr_db=m["islr_range_db"], azimuth_islr_db=m["islr_azimuth_db"],
            range_irw_theory_m=th_r.irw, azimuth_irw_theory_m=th_a.irw * ds / dt,
            range_offset_px=d_col, azimuth_offset_px=d_row, predicted_row=pred.row, predicted_col=pred.col,
            measured_row=m["row"], measured_col=m["col"], zero_doppler_time_s=pred.zero_doppler_time_s,
            slant_range_m=pred.slant_range_m, along_track_spacing_m=ds, incidence_deg=pred.incidence_deg,
            peak_amplitude=m["peak_amplitude"], survey_utc=cr.survey_utc, validity=cr.validity,
            plate_motion_m=motion, corrections=corr, **rcs))
    return Analysis(acq, results, outside, th_r, th_a, notes)


def _rcs(slc: SLC, sv, cr: CornerReflector, p: np.ndarray, m: dict, t_zd: float, notes: list[str]) -> dict:
    """rcs_dbsm, rcs_theory_dbsm, rcs_error_db of one reflector (NaN, with a note, when not measurable)."""
    from sarcli.calibration.radiometry import point_rcs, reflector_rcs

    pos = sv.interpolate(np.array([t_zd]))[0][0]
    theory = reflector_rcs(cr, p, pos, slc.radar.wavelength_m)
    out = {"rcs_theory_dbsm": 10.0 * np.log10(theory) if theory > 0 else float("-inf")}
    if slc.calibration is None:
        if not any(n.startswith("radiometry:") for n in notes):
            notes.append("radiometry: the product carries no radiometric calibration: no RCS measured")
        return out
    try:
        rcs = point_rcs(slc, m["row"], m["col"])
    except SarcliError as e:
        notes.append(f"{cr.id}: RCS not measured ({e})")
        return out
    out["rcs_dbsm"] = 10.0 * np.log10(rcs) if rcs > 0 else float("nan")
    out["rcs_error_db"] = out["rcs_dbsm"] - out["rcs_theory_dbsm"]
    return out
