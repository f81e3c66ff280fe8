"""J2 truth orbits sampled like Radarsat-1 (15 vectors, 480 s apart) and densely, for the orbit tests."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from orbit.accuracy import RS1_ELEMENTS, TruthOrbit, truth_orbit

EPOCH = "2002-06-16T15:41:00Z"
SPACING = 480.0
N_VECTORS = 15


def make_truth(inclination_deg: float, n_dense: int = 1201, mean_anomaly: float = 0.4,
               node_times: np.ndarray | None = None) -> TruthOrbit:
    """Radarsat-1-like orbit (a = 7167 km, e = 0.0011) integrated with J2; ECI nodes + dense truth."""
    k = replace(RS1_ELEMENTS, inclination_rad=np.radians(inclination_deg), mean_anomaly_rad=mean_anomaly)
    tn = np.arange(N_VECTORS) * SPACING if node_times is None else node_times
    return truth_orbit(k, tn, np.linspace(tn[0], tn[-1], n_dense), EPOCH)
