"""What a Doppler estimate reports besides its models: scene values, methods and diagnostics (typed).

:class:`DopplerSummary` travels with a :class:`~sarcli.model.doppler.PolyDoppler` (``model.summary``),
is stored as JSON in ``doppler.h5`` (root attribute ``summary_json``) and printed by ``sarcli doppler
--json``. ``to_dict()`` gives that JSON form (the key names are the field names; the diagnostic
sections drop their unset fields), ``from_dict()`` reads it back. Units: Hz, Hz/s, m, s; PRF units
where the name says ``_prf``.

Ambiguity. ``ambiguity`` is the PRF ambiguity number of the absolute centroid at the scene centre,
``ambiguity_source`` says what decided it: ``orbit`` (the orbit + attitude model), ``orbit+data`` (an
orbit prediction half-way between two integers, broken by the data-only estimate), ``data`` (MLCC +
MLBF), ``user`` (given), ``none`` (nothing: the centroid is the baseband one). ``ambiguity_resolved``
is True only when a source decided it: the user; the orbit with a margin of at least the half-integer
tolerance; the data (alone or breaking the orbit's tie) with a non-zero confidence. A model whose
ambiguity is not resolved must not be used silently (the focus workflow refuses it without an opt-in).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sarcli.errors import ProductError

AMBIGUITY_SOURCES = ("orbit", "orbit+data", "data", "user", "none")


def _section_dict(obj: Any) -> dict[str, Any]:
    """A diagnostic section as a dict without its unset (None) fields; nested sections likewise."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        if v is None:
            continue
        out[f.name] = v.to_dict() if hasattr(v, "to_dict") else v
    return out


def _known(cls: type, d: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The entries of ``d`` that are fields of ``cls``; a missing required one is a ProductError."""
    if not isinstance(d, Mapping):
        raise ProductError(f"{where}: expected an object, got {d!r}")
    names = {f.name: f for f in dataclasses.fields(cls)}
    missing = [n for n, f in names.items() if n not in d and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if missing:
        raise ProductError(f"{where}: missing {', '.join(missing)}")
    return {k: v for k, v in d.items() if k in names}


def _floats(v: Any) -> np.ndarray:
    """JSON numbers (null = NaN) as a float64 array."""
    return np.array([np.nan if x is None else x for x in np.ravel(np.asarray(v, dtype=object))], np.float64)


#: below this ambiguity confidence (the probability that the ambiguity's rounding is right) a resolved
#: ambiguity is used only with a warning saying how confident and what to do (docs/doppler.md)
AMBIGUITY_CONFIDENCE_LEVEL = 0.9


def low_confidence_note(summary: Any) -> str | None:
    """The warning for a resolved ambiguity of confidence below :data:`AMBIGUITY_CONFIDENCE_LEVEL`, or None."""
    conf = getattr(summary, "ambiguity_confidence", None)
    if summary is None or not summary.ambiguity_resolved or conf is None or not conf < AMBIGUITY_CONFIDENCE_LEVEL:
        return None
    return (f"the Doppler centroid's PRF ambiguity ({summary.ambiguity}, from {summary.ambiguity_source}) holds with "
            f"confidence {conf:.2f} only (below {AMBIGUITY_CONFIDENCE_LEVEL:.2f}): the centroid may be a whole PRF off "
            "(a defocused, shifted image); give the centroid with --fdc/--fr or the ambiguity with sarcli doppler "
            "--ambiguity-value, estimate it on a longer scene or with an orbit, or accept it with "
            "--accept-unresolved-ambiguity")


@dataclass(frozen=True)
class DataOnlyEstimate:
    """Absolute centroid of one data-only method (MLCC, MLBF, or ``combined``: their inverse-variance
    combination) with its ambiguity and confidence (``sarcli.doppler.dataonly``); ``block_fdc_hz`` per
    range block (``combined``: the estimates combined); ``dof`` the degrees of freedom of ``sigma_hz``
    (None: Gaussian, or not recorded by an older product)."""

    method: str
    fdc_hz: float
    sigma_hz: float
    ambiguity: int
    confidence: float
    block_fdc_hz: np.ndarray
    dof: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "data_only") -> DataOnlyEstimate:
        k = _known(cls, d, where)
        nan = float("nan")
        return cls(str(k["method"]), nan if k["fdc_hz"] is None else float(k["fdc_hz"]),
                   nan if k["sigma_hz"] is None else float(k["sigma_hz"]), int(k["ambiguity"]),
                   float(k["confidence"]), _floats(k["block_fdc_hz"]),
                   None if k.get("dof") is None else float(k["dof"]))


@dataclass(frozen=True)
class MapDriftSegment:
    """One range segment of the map-drift rate: its rate, start value, iterations, whether it converged
    and was used in the swath fit, and the swath model's value there."""

    range_m: float
    fr_hz_per_s: float
    start_hz_per_s: float
    iterations: int
    converged: bool
    used: bool
    model_hz_per_s: float

    def to_dict(self) -> dict[str, Any]:
        return _section_dict(self)


@dataclass(frozen=True)
class MapDriftFit:
    """One effective velocity for the swath from the map-drift segments (``fr = -2 Vr^2/(lam R)``);
    its standard error is None for a single segment."""

    velocity_mps: float
    velocity_sigma_mps: float | None
    n_segments_used: int
    segments: tuple[MapDriftSegment, ...]

    def to_dict(self) -> dict[str, Any]:
        return {"velocity_mps": self.velocity_mps, "velocity_sigma_mps": self.velocity_sigma_mps,
                "n_segments_used": self.n_segments_used, "segments": [s.to_dict() for s in self.segments]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "mapdrift") -> MapDriftFit:
        k = _known(cls, d, where)
        segs = tuple(MapDriftSegment(**_known(MapDriftSegment, s, f"{where}.segments")) for s in k["segments"])
        return cls(float(k["velocity_mps"]), k["velocity_sigma_mps"], int(k["n_segments_used"]), segs)


@dataclass(frozen=True)
class RateDiagnostics:
    """How the Doppler rate was obtained: the seed route ([Koh2003, §4]) against the exact one (with an orbit), the
    map-drift fit, or the nominal velocity."""

    seed_vs_exact_max_rel: float | None = None
    seed_domain_failures: int | None = None
    mapdrift: MapDriftFit | None = None
    nominal_velocity_mps: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return _section_dict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "fr_info") -> RateDiagnostics:
        k = _known(cls, d, where)
        if k.get("mapdrift") is not None:
            k["mapdrift"] = MapDriftFit.from_dict(k["mapdrift"], f"{where}.mapdrift")
        return cls(**k)


@dataclass(frozen=True)
class GeometryDiagnostics:
    """With an orbit: the closed form ([Koh2003, eq. 6]) against the vector model, and the data against the model."""

    closed_minus_vector_max_abs_hz: float | None = None
    fdc_data_minus_orbit_rms_hz: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return _section_dict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "geometry") -> GeometryDiagnostics:
        return cls(**_known(cls, d, where))


@dataclass(frozen=True)
class FitDiagnostics:
    """With an orbit: the residual (data - model) coefficients and the error of the dense-grid fits."""

    fdc_grid_fit_max_abs_hz: float | None = None
    residual_coef_hz: np.ndarray | None = None
    fr_grid_fit_max_rel: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return _section_dict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "fit") -> FitDiagnostics:
        k = _known(cls, d, where)
        if k.get("residual_coef_hz") is not None:
            k["residual_coef_hz"] = np.asarray(k["residual_coef_hz"], np.float64)
        return cls(**k)


@dataclass(frozen=True)
class DopplerSummary:
    """Scene values (at ``scene_range_m``, ``scene_time_s``), methods, block counts and diagnostics.

    ``fdc_baseband_hz`` scene baseband centroid in [-PRF/2, PRF/2); ``quality`` its |correlation|;
    ``ambiguity*`` see the module docstring (margin in PRF units, 0.5 = an integer exactly);
    ``fdc_hz``/``fr_hz_per_s`` the fitted models at the scene centre; ``fdc_method`` the centroid
    estimator's name, ``fdc_model`` the geometric model (vector | closed; None without an orbit),
    ``fr_method`` orbit | seed | mapdrift | nominal; ``gain_steps`` (line, dB) receiver-gain steps found
    in the echo and undone (None: not searched); ``estimator_info`` the estimator's own diagnostics
    (JSON-able, e.g. the look balance's per-block standard errors; None when it has none).
    """

    prf_hz: float
    fdc_baseband_hz: float
    quality: float
    ambiguity: int
    ambiguity_source: str
    ambiguity_confidence: float
    ambiguity_margin_prf: float
    ambiguity_resolved: bool
    fdc_hz: float
    fr_hz_per_s: float
    scene_range_m: float
    scene_time_s: float
    fdc_method: str
    fdc_model: str | None
    fr_method: str
    n_blocks: int
    n_az_blocks: int
    n_rg_blocks: int
    n_valid_blocks: int
    n_outlier_blocks: int
    data_only: tuple[DataOnlyEstimate, ...] = ()
    fr_info: RateDiagnostics = field(default_factory=RateDiagnostics)
    geometry: GeometryDiagnostics = field(default_factory=GeometryDiagnostics)
    fit: FitDiagnostics = field(default_factory=FitDiagnostics)
    gain_steps: tuple[tuple[int, float], ...] | None = None
    estimator_info: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        if self.ambiguity_source not in AMBIGUITY_SOURCES:
            raise ProductError(f"ambiguity source {self.ambiguity_source!r} is not one of "
                               f"{', '.join(AMBIGUITY_SOURCES)}")
        if self.ambiguity_source == "none" and self.ambiguity_resolved:
            raise ProductError("an ambiguity with source 'none' cannot be resolved")

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (``--json`` and ``summary_json``), keys in field order."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if f.name == "data_only":
                v = [e.to_dict() for e in v]
            elif f.name == "gain_steps" and v is not None:
                v = [[int(m), float(d)] for m, d in v]
            elif hasattr(v, "to_dict"):
                v = v.to_dict()
            out[f.name] = v
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "summary") -> DopplerSummary:
        """Read the JSON form back (a malformed one is a one-line ProductError). Products written before
        the estimators became plug-ins name the estimator diagnostics ``look_balance``, and those with
        source "none" claimed ``ambiguity_resolved`` (read as not resolved: nothing decided it)."""
        if isinstance(d, Mapping) and "look_balance" in d and "estimator_info" not in d:
            d = {**d, "estimator_info": d["look_balance"]}
        k = _known(cls, d, where)
        if k.get("ambiguity_source") == "none":
            k["ambiguity_resolved"] = False
        try:
            k["data_only"] = tuple(DataOnlyEstimate.from_dict(e, f"{where}.data_only") for e in k.get("data_only", ()))
            for name, sec in (("fr_info", RateDiagnostics), ("geometry", GeometryDiagnostics), ("fit", FitDiagnostics)):
                k[name] = sec.from_dict(k.get(name) or {}, f"{where}.{name}")
            if k.get("gain_steps") is not None:
                k["gain_steps"] = tuple((int(m), float(db)) for m, db in k["gain_steps"])
            for name in ("ambiguity", "n_blocks", "n_az_blocks", "n_rg_blocks", "n_valid_blocks", "n_outlier_blocks"):
                k[name] = int(k[name])
            k["ambiguity_resolved"] = bool(k["ambiguity_resolved"])
            return cls(**k)
        except ProductError:
            raise
        except (TypeError, ValueError) as e:
            raise ProductError(f"{where}: malformed ({e})") from None
