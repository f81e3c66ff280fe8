"""``rc-cde``: the CDE after range compression.

The echo is range-compressed over every sample a recorded echo reaches (``rangecomp.
range_compress_extended``: n + 2 (n_ref // 2) samples starting half a pulse before the window; the
partially compressed points at the window edges keep their azimuth phase history), then correlated
like the CDE. On the narrow 384-sample test swath the fully compressed samples alone (222) gave
0.58 % PRF, the extended compression 0.15 % (``docs/doppler.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

from sarcli.doppler.cde import block_correlation
from sarcli.doppler.estimators.base import BasebandBlocks, EstimationInput, correlation_blocks
from sarcli.doppler.rangecomp import can_compress, range_compress_extended
from sarcli.errors import ConfigError


@dataclass(frozen=True)
class RangeCompressedCDE:
    def baseband(self, data: EstimationInput) -> BasebandBlocks:
        raw, o = data.raw, data.options
        if not can_compress(raw):
            raise ConfigError("rc-cde needs a range extent longer than the pulse; use the cde estimator")
        rc, extent = range_compress_extended(raw.echo, raw.radar, raw.replica)
        # block ranges: the compressed array's sample 0 is raw sample extent.start (negative)
        return correlation_blocks(raw, block_correlation(rc, o.az_block, o.rg_block, "cde"), o, extent.start, rc)


ESTIMATOR = RangeCompressedCDE()
