"""Backprojection's default image width is the whole track plus the beam footprint at the
top range, X + lam R / L_x; DF's azimuth width lam R / (2 dx) (its FFT's unambiguous width) is no bound
of BP's and caps only DF, RD and auto."""

from __future__ import annotations

import numpy as np
import pytest

from sarcli.gbsar.focus import FocusOptions, default_grid
from sarcli.gbsar.rangecomp import RangeProfiles
from sarcli.model.constants import C_LIGHT


def _profiles(rail_m: float, dx: float, wave_speed: float) -> RangeProfiles:
    """A 4.2 m rail in soil (permittivity 6: v = c / sqrt(6)), 5.3 GHz: ranges 0..R in dr steps."""
    x = np.arange(0.0, rail_m + dx / 2, dx)
    n_r = 64
    return RangeProfiles(data=np.zeros((x.size, n_r), np.complex64), dr_m=0.02, center_frequency_hz=5.3e9,
                         frequency_step_hz=5e6, n_freq=n_r, positions_m=x, heights_m=np.zeros(x.size),
                         weights=np.ones(x.size), skipped=[], wave_speed_m_s=wave_speed)


@pytest.mark.parametrize("algorithm", ["bp", "df"])
def test_default_width(algorithm):
    prof = _profiles(4.2, 0.05, C_LIGHT / np.sqrt(6.0))
    lx = 0.25
    grid = default_grid(prof, lx, FocusOptions(algorithm=algorithm))
    lam, r_top, dx = prof.wavelength_m, float(prof.ranges_m[-1]), 0.05
    footprint = 4.2 + lam * r_top / lx  # X + lam R / L_x (theory)
    df_width = lam * r_top / (2 * dx)   # DF's unambiguous azimuth width
    assert df_width < 4.2 < footprint  # the case of the issue: DF's width covers a quarter of the rail
    want = footprint if algorithm == "bp" else min(df_width, footprint)
    step = float(np.diff(grid.azimuths[:2])[0])
    # the image spans the width to within one pixel at each edge (the lattice k dx from the rail's start)
    assert want - 2 * step <= grid.azimuths[-1] - grid.azimuths[0] <= want
    if algorithm == "bp":
        assert grid.azimuths[0] <= 0.0 and grid.azimuths[-1] >= 4.2  # the whole rail
