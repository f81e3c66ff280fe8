"""Every knob of the Doppler estimate in one frozen, validated dataclass (``[doppler.options]`` in TOML).

Built directly, or from a mapping with :func:`sarcli.config.from_mapping` (unknown keys, wrong types
and values outside a ``Literal`` are refused there; the ranges below in ``__post_init__``). The
products store it (``parameters``), so a ``doppler.h5`` says how it was made.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from sarcli.errors import ConfigError

MAX_DEGREE = 6


@dataclass(frozen=True)
class DopplerOptions:
    """Knobs of :func:`sarcli.doppler.api.estimate_doppler` (units in the names; defaults and why in
    ``docs/doppler.md``).

    Blocks: ``az_block`` lines x ``rg_block`` samples (2048 x 128 as in [Koh2003, §5]). ``estimator``: a name in
    :data:`sarcli.doppler.estimators.ESTIMATORS` (built in: cde, sde, rc-cde, lb). ``gain_steps``:
    receiver-gain steps recovered from the echo and undone: auto (quantized products without an AGC
    record) | on | off. ``lb_band_fraction``: look-balance processed band, fraction of the PRF.

    Ambiguity: ``ambiguity`` auto (orbit if the product has ECI/ECEF state vectors, else data when the
    swath is longer than the pulse, else none) | orbit | data (MLCC + MLBF) | none; ``ambiguity_value``
    forces the scene's ambiguity number. ``half_tolerance`` (PRF units): an orbit prediction closer than
    this to a half integer is declared unresolved. ``orbit_sigma_hz``: 1-sigma error of the geometric
    centroid (Radarsat-1's 0.03 deg pitch knowledge, ~140 Hz), for the confidence.

    Blocks used: valid when their quality exceeds ``noise_sigmas`` standard deviations of the white-noise
    floor and ``min_quality``; fits flag blocks beyond ``outlier_sigma`` robust standard deviations.

    Models: ``fdc_model`` vector | closed ([Koh2003, eq. 6]); ``fit_degree`` (range, azimuth) of the block fit
    without an orbit, ``resid_degree`` of the data-minus-orbit residual, ``model_degree`` of the dense
    model-grid fit; ``n_nodes`` Hermite nodes (None: the orbit's), ``exact_attitude`` (False: the
    small-angle rotation of [Koh2003, eq. 1]).

    Rate: ``fr_method`` auto (orbit if present, else map-drift when the swath is longer than the pulse,
    else the nominal velocity) | orbit | seed | mapdrift; ``velocity_guess_mps`` starts map-drift (and is
    the nominal velocity when the product has none); ``mapdrift_segments`` range segments.

    Data-only estimators and map-drift work on the central ``max_lines`` lines (bounded memory), in
    range blocks of ``dataonly_rg_block`` samples (None: valid samples / 8, clipped to 16..128).
    """

    estimator: str = "cde"
    az_block: int = 2048
    rg_block: int = 128
    gain_steps: Literal["auto", "on", "off"] = "auto"
    lb_band_fraction: float = 0.6
    ambiguity: Literal["auto", "orbit", "data", "none"] = "auto"
    ambiguity_value: int | None = None
    half_tolerance: float = 0.02
    orbit_sigma_hz: float = 140.0
    noise_sigmas: float = 5.0
    min_quality: float = 0.02
    outlier_sigma: float = 4.0
    fdc_model: Literal["vector", "closed"] = "vector"
    fit_degree: tuple[int, int] = (2, 1)
    resid_degree: tuple[int, int] = (0, 0)
    model_degree: tuple[int, int] = (4, 2)
    n_nodes: int | None = None
    exact_attitude: bool = True
    fr_method: Literal["auto", "orbit", "seed", "mapdrift"] = "auto"
    velocity_guess_mps: float = 7000.0
    mapdrift_segments: int = 8
    dataonly_rg_block: int | None = None
    max_lines: int = 4096

    def __post_init__(self) -> None:
        from sarcli.doppler.estimators import ESTIMATORS

        if self.estimator not in ESTIMATORS:
            raise ConfigError(f"unknown Doppler centroid estimator {self.estimator!r}; "
                              f"known: {', '.join(ESTIMATORS.names())}")
        if self.az_block < 2 or self.rg_block < 1:
            raise ConfigError(f"block size must be at least 2 lines x 1 sample, got {self.az_block} x {self.rg_block}")
        if not 0.1 <= self.lb_band_fraction <= 0.9:
            raise ConfigError(f"look-balance band fraction must be in [0.1, 0.9], got {self.lb_band_fraction}")
        for name in ("fit_degree", "resid_degree", "model_degree"):
            deg = getattr(self, name)
            if len(deg) != 2 or not all(0 <= d <= MAX_DEGREE for d in deg):
                raise ConfigError(f"{name} must be two degrees (range, azimuth) in 0..{MAX_DEGREE}, got {deg}")
        _interval("half_tolerance", self.half_tolerance, 0.0, 0.5, "PRF", hi_open=True)
        _interval("min_quality", self.min_quality, 0.0, 1.0, "", hi_open=True)
        for name in ("orbit_sigma_hz", "noise_sigmas", "outlier_sigma", "velocity_guess_mps"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ConfigError(f"{name} must be positive and finite, got {v}")
        if self.n_nodes is not None and self.n_nodes < 2:
            raise ConfigError(f"Hermite interpolation needs at least 2 nodes, got {self.n_nodes}")
        if self.mapdrift_segments < 1:
            raise ConfigError(f"mapdrift_segments must be at least 1, got {self.mapdrift_segments}")
        if self.dataonly_rg_block is not None and self.dataonly_rg_block < 1:
            raise ConfigError(f"dataonly_rg_block must be at least 1 sample, got {self.dataonly_rg_block}")
        if self.max_lines < 64:
            raise ConfigError(f"max_lines must be at least 64 (map-drift's minimum), got {self.max_lines}")


def _interval(name: str, v: float, lo: float, hi: float, unit: str, hi_open: bool = False) -> None:
    ok = math.isfinite(v) and lo <= v and (v < hi if hi_open else v <= hi)
    if not ok:
        raise ConfigError(f"{name} must be in [{lo}, {hi}{')' if hi_open else ']'}{' ' + unit if unit else ''}, "
                          f"got {v}")
