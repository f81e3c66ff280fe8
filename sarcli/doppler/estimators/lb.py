"""``lb``: the look-balance centroid, robust to scene contrast (``sarcli.doppler.lookbalance``).

Two passes, explicit: (1) the whole pipeline with the CDE (``data.first_pass("cde")``) gives the
Doppler rate, which the azimuth matched filter needs; (2) per block, the look balance started from the
CDE centroid of its range block (whole scene) with that rate at the scene-centre time. Only blocks
that the CDE's noise-floor test also accepts are kept (the look balance alone can keep a root in pure
noise); a kept block gets the look balance's centroid, its inverse variance (prf / (2 pi sigma))^2 as
weight and the centre of the pixels it used as time. The scene centroid is the inverse-variance
circular mean of the kept blocks; the scene quality stays the CDE's.

``estimator_info``: ``band_fraction``, ``margin_lines`` (per range block), ``sigma_hz`` and ``pixels``
(per block), ``cde_fdc_baseband_hz`` (the first pass's scene centroid).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from sarcli.doppler.cde import block_correlation, combine, wrap_frequency
from sarcli.doppler.estimators.base import BasebandBlocks, EstimationInput, correlation_blocks
from sarcli.doppler.lookbalance import look_balance
from sarcli.errors import ConfigError


@dataclass(frozen=True)
class LookBalanceEstimator:
    def baseband(self, data: EstimationInput) -> BasebandBlocks:
        raw, o = data.raw, data.options
        prf, n_lines = raw.radar.prf_hz, raw.echo.shape[0]
        first = data.first_pass("cde")
        bc = block_correlation(raw.echo, o.az_block, o.rg_block)
        cde = correlation_blocks(raw, bc, o)
        t_c = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
        r_blk = cde.range_m[0]
        ka = np.asarray(first.fr(r_blk, np.full_like(r_blk, t_c)), float)
        lb = look_balance(raw.echo, prf, bc.line0, bc.n_lines, bc.sample0, bc.n_samples,
                          combine(bc, 0).baseband(prf)[0], ka, o.lb_band_fraction)
        if not np.any(lb.valid()):
            raise ConfigError(f"look balance: no block owns 32+ lines farther than {lb.margin_lines.max()} lines from "
                              f"the scene ends (scene {n_lines} lines, blocks of {o.az_block}); use a longer scene or "
                              "larger --az-block, a smaller --lb-band, or the CDE")
        valid = cde.valid & lb.valid()  # the CDE's noise-floor test stays: LB alone cannot tell noise
        fbb = np.where(valid, lb.fbb_hz, cde.fbb_hz)
        w = np.where(valid, lb.phase_weight(prf), 0.0)
        T = np.where(valid, np.interp(lb.centre_line, np.arange(n_lines), raw.azimuth_time), cde.time_s)
        total, norm = bc.scene_sum(valid)
        scene = wrap_frequency(prf * np.angle(np.sum(w * np.exp(2j * np.pi * fbb / prf))) / (2 * np.pi), prf)
        info = {"band_fraction": o.lb_band_fraction, "margin_lines": lb.margin_lines.tolist(),
                "sigma_hz": lb.sigma_hz.tolist(), "pixels": lb.pixels.tolist(),
                "cde_fdc_baseband_hz": first.summary.fdc_baseband_hz if first.summary is not None else None}
        return replace(cde, fbb_hz=fbb, valid=valid, weight=w, time_s=T, scene_fbb_hz=float(scene),
                       scene_quality=float(np.abs(total) / max(norm, 1e-300)), info=info)


ESTIMATOR = LookBalanceEstimator()
