"""The Doppler centroid estimator interface: what an estimator gets and what it must return.

An estimator turns the (gain-corrected) echo into a baseband centroid per block. The pipeline does
everything after that (unwrap, ambiguity, fit, rate; ``sarcli.doppler.pipeline``), so an estimator
never sees the orbit, the ambiguity or the fits.

Block coordinates (for :func:`block_coordinates`): slant range of the block's centre sample (raw
sample k <-> two-way time window_start + k/fs; for the raw echo the energy at sample k comes from
scatterers at that range, the pulse being centred on its delay) and the azimuth (pulse) time of its
centre line; an estimator whose estimate applies elsewhere (look balance: the centre of the pixels it
used) says so in ``time_s``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from sarcli.doppler.cde import BlockCorrelation, wrap_frequency
from sarcli.model.constants import C_LIGHT
from sarcli.model.raw import RawProduct

if TYPE_CHECKING:
    from sarcli.doppler.options import DopplerOptions
    from sarcli.model.doppler import PolyDoppler

#: ``first_pass(estimator_name) -> PolyDoppler``: the whole pipeline (baseband with the named
#: estimator, unwrap, ambiguity, fit, rate) on the same product, options and terrain. For estimators
#: that need a Doppler model to start from (look balance needs the Doppler rate); a first pass cannot
#: ask for another one (ConfigError).
FirstPass = Callable[[str], "PolyDoppler"]


@dataclass(frozen=True)
class EstimationInput:
    """What an estimator gets: the product with the receiver gain undone (``raw``; AGC and gain steps),
    the options (block sizes ``az_block`` x ``rg_block``, validity thresholds ``noise_sigmas`` and
    ``min_quality``, its own knobs) and the first-pass hook."""

    raw: RawProduct
    options: DopplerOptions
    first_pass: FirstPass


@dataclass(frozen=True)
class BasebandBlocks:
    """Stage 1 output, every array (n_az_blocks, n_rg_blocks):

    ``fbb_hz`` baseband centroid in [-PRF/2, PRF/2); ``quality`` 0..1 (for the block table);
    ``valid`` whether the block holds a usable Doppler signal; ``weight`` inverse phase variance
    (rad^-2, 0 where not valid); ``range_m`` / ``time_s`` where each estimate applies (slant range m,
    azimuth time s after the product epoch). Scene values: ``scene_fbb_hz`` the centroid over the valid
    blocks, ``scene_quality`` its |correlation| (0..1). ``info``: the estimator's own diagnostics,
    JSON-able, reported as ``estimator_info`` in the summary (None: none).
    """

    fbb_hz: np.ndarray
    quality: np.ndarray
    valid: np.ndarray
    weight: np.ndarray
    range_m: np.ndarray
    time_s: np.ndarray
    scene_fbb_hz: float
    scene_quality: float
    info: dict[str, Any] | None = None

    @property
    def shape(self) -> tuple[int, int]:
        return self.fbb_hz.shape  # type: ignore[return-value]


@runtime_checkable
class CentroidEstimator(Protocol):
    """A Doppler centroid estimator (registered in ``sarcli.doppler.estimators.ESTIMATORS``)."""

    def baseband(self, data: EstimationInput) -> BasebandBlocks:
        """Baseband centroid per block of ``data.raw`` (see :class:`BasebandBlocks`)."""
        ...


def block_coordinates(raw: RawProduct, bc: BlockCorrelation, sample_offset: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(azimuth time s, slant range m) of the centre of every block of ``bc`` (module docstring), each
    (n_az_blocks, n_rg_blocks); ``sample_offset`` is the raw-echo index of the correlated array's first
    sample (negative for the extended range compression, which starts before the window)."""
    radar = raw.radar
    lc, sc = bc.centres()
    t_blk = np.interp(lc, np.arange(raw.echo.shape[0]), raw.azimuth_time)
    r_blk = radar.first_range_m + (sc + sample_offset) * C_LIGHT / (2.0 * radar.range_sampling_rate_hz)
    T, R = np.meshgrid(t_blk, r_blk, indexing="ij")
    return T, R


def correlation_blocks(raw: RawProduct, bc: BlockCorrelation, options: DopplerOptions,
                       sample_offset: int = 0, data: np.ndarray | None = None) -> BasebandBlocks:
    """Stage 1 output of a lag-1 correlation estimator (CDE, SDE, RC-CDE): per-block centroid, quality,
    SNR-aware validity and weight (``sarcli.doppler.cde``), and the scene centroid from the summed
    correlation of the valid blocks. ``estimator_info`` holds the standard error of every block
    (``sigma_hz``: speckle and scene contrast, ``sarcli.doppler.contrast``; its two parts
    ``sigma_speckle_hz``, ``sigma_scene_hz``), the fitted first-null Doppler offset of the azimuth
    pattern (``pattern_band_hz``) and the Doppler rate assumed for it. ``data``: the correlated array
    (default ``raw.echo``), for the pattern fit."""
    from sarcli.doppler import contrast

    prf = raw.radar.prf_hz
    valid = bc.valid(options.noise_sigmas, options.min_quality)
    T, R = block_coordinates(raw, bc, sample_offset)
    total, norm = bc.scene_sum(valid)
    scene = float(wrap_frequency(prf * np.angle(total) / (2 * np.pi), prf))
    weight = bc.weight(options.noise_sigmas, options.min_quality)
    quality = bc.quality()
    v = raw.radar.platform_velocity_mps or options.velocity_guess_mps
    fr = -2.0 * v**2 / (raw.radar.wavelength_m * float(np.median(R)))
    band = contrast.fit_band(raw.echo if data is None else data, prf, scene, options.max_lines)
    var_speckle, var_scene = contrast.block_sigmas(bc, contrast.Pattern(band, fr, prf))
    to_hz = prf / (2 * np.pi)
    info = {"sigma_hz": _listed(to_hz * np.sqrt(var_speckle + var_scene)),
            "sigma_speckle_hz": _listed(to_hz * np.sqrt(var_speckle)),
            "sigma_scene_hz": _listed(to_hz * np.sqrt(var_scene)),
            "pattern_band_hz": band, "pattern_fr_hz_per_s": fr}
    return BasebandBlocks(bc.baseband(prf), quality, valid, weight, R, T, scene,
                          float(np.abs(total) / max(norm, 1e-300)), info)


def _listed(a: np.ndarray) -> list:
    """A 2-D array as nested lists for JSON, non-finite values as None."""
    return [[float(x) if np.isfinite(x) else None for x in row] for row in np.asarray(a, np.float64)]
