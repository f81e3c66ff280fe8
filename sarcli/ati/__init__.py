"""SAR along-track interferometry (ATI) for ground moving targets ([Ryu2017]).

Modules: ``geometry`` (range history, Rs/Rm split, DRA ATI phase), ``unwrap`` (Itoh and
dechirp-guided unwrapping), ``fit`` (weighted LS with covariance, error propagation),
``estimate`` (seed / exact / nonlinear routes), ``nonlinear`` (full fit of the exact histories).
"""
