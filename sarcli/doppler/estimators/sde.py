"""``sde``: the sign Doppler estimator, the CDE on 1 bit per rail.

s = sign(Re h) + j sign(Im h); for a circular complex Gaussian signal of correlation coefficient rho
the arcsine law gives E[s(m+1) conj(s(m))] / 2 = (2/pi) (asin(Re rho) + j asin(Im rho)), inverted per
block: rho = sin(pi/2 Re r) + j sin(pi/2 Im r), r = C_s / (2 N) (``sarcli.doppler.cde``). The scene
centroid is the phase of sum rho N over the valid blocks. Cheaper only on 1-bit hardware (on a CPU
with SIMD floats it is slower than the CDE, ``docs/doppler.md``).
"""

from __future__ import annotations

from sarcli.doppler.estimators.cde import CorrelationEstimator

ESTIMATOR = CorrelationEstimator("sde")
