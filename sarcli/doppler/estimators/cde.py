"""``cde``: the Correlation Doppler Estimator on the raw echo ([Madsen1989]; the default of [Koh2003, §3.2]).

Per block of ``az_block`` lines x ``rg_block`` samples the lag-1 azimuth correlation
C = sum h(m+1, k) conj(h(m, k)) has phase 2 pi fdc / PRF, so fdc_bb = PRF arg(C) / (2 pi)
(``sarcli.doppler.cde``: numba kernel, quality |C|/E, SNR-aware validity, inverse-variance weight).
The scene centroid is the phase of the sum of C over the valid blocks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from sarcli.doppler.cde import block_correlation
from sarcli.doppler.estimators.base import BasebandBlocks, EstimationInput, correlation_blocks


@dataclass(frozen=True)
class CorrelationEstimator:
    """Lag-1 correlation of the raw echo per block: ``kind`` "cde" (complex samples) or "sde" (their
    signs, ``sarcli.doppler.estimators.sde``)."""

    kind: Literal["cde", "sde"] = "cde"

    def baseband(self, data: EstimationInput) -> BasebandBlocks:
        o = data.options
        return correlation_blocks(data.raw, block_correlation(data.raw.echo, o.az_block, o.rg_block, self.kind), o)


ESTIMATOR = CorrelationEstimator("cde")
