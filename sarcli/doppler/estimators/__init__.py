"""Doppler centroid estimators: plug-ins that give the baseband centroid per block (pipeline stage 1).

Each estimator is one module holding an object that implements
:class:`~sarcli.doppler.estimators.base.CentroidEstimator` (a ``baseband(data) -> BasebandBlocks``
method), registered here by name. The rest of the pipeline (unwrap, ambiguity, fit, rate:
``sarcli.doppler.pipeline``) is the same for all of them. Built in:

- ``cde``     lag-1 azimuth correlation of the raw echo (Madsen 1989), the default;
- ``sde``     the sign (1-bit) version with the arcsine-law correction;
- ``rc-cde``  the CDE after range compression (every sample a recorded echo reaches);
- ``lb``      look balance on the azimuth-focused scene, started from a CDE first pass.

A new estimator is one file with such an object and one registration: a line in the built-ins below,
``ESTIMATORS.register("name", obj)`` from code, or an entry point in the group ``sarcli.estimators``
(``docs/doppler.md``, "A new Doppler estimator").
"""

from __future__ import annotations

from typing import Any

from sarcli.errors import ConfigError
from sarcli.registry import Registry


def _check(name: str, obj: Any) -> None:
    if not callable(getattr(obj, "baseband", None)):
        raise ConfigError(f"Doppler centroid estimator {name!r} ({obj!r}) has no baseband(data) method")


ESTIMATORS: Registry = Registry("Doppler centroid estimator", "sarcli.estimators", {
    "cde": "sarcli.doppler.estimators.cde:ESTIMATOR",
    "sde": "sarcli.doppler.estimators.sde:ESTIMATOR",
    "rc-cde": "sarcli.doppler.estimators.rc_cde:ESTIMATOR",
    "lb": "sarcli.doppler.estimators.lb:ESTIMATOR",
}, check=_check)
