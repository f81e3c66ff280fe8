"""The scan record's velocity statistics. ``max_velocity_mm_per_h`` is one point's |v|
(noise-dominated); ``velocity_p95_mm_per_h`` is the 95th percentile of |v| over the measured points and
``alarm_velocity_mm_per_h`` the largest |median| of the areas, which the alarms use. Checked against the
stored velocity and selection maps (plain numpy) and, in the quiet first hour of the landslide sample
(every truth velocity below 1 mm/h), against the lowest alarm threshold."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.monitor.config import load_monitor_config
from sarcli.monitor.store import Store
from tests.monitor.conftest import MONITOR


def test_robust_velocity_statistics(offline_campaign):
    store = Store(offline_campaign)
    lowest = min(t for a in load_monitor_config(MONITOR).areas for t in (a.velocity_mm_per_h or ()))
    for k in range(2, 13):
        rec, maps = store.read_epoch(k)
        v = np.abs(maps["velocity_mm_per_h"][maps["selected"] > 0])
        assert rec["max_velocity_mm_per_h"] == pytest.approx(float(v.max()), rel=1e-6)
        assert rec["velocity_p95_mm_per_h"] == pytest.approx(float(np.percentile(v, 95)), rel=1e-6)
        medians = [abs(a["velocity_mm_per_h"]) for a in rec["areas"].values() if a["velocity_mm_per_h"] is not None]
        assert rec["alarm_velocity_mm_per_h"] == (pytest.approx(max(medians)) if medians else None)
        if k <= 6:  # the quiet first hour: the robust statistics stay below the lowest threshold
            assert rec["velocity_p95_mm_per_h"] < lowest
            assert rec["alarm_velocity_mm_per_h"] is None or rec["alarm_velocity_mm_per_h"] < lowest
