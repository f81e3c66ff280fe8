"""The rail of a scan as focusing needs it: known, distinct stop positions in increasing order.

Every focuser (DF, RD, BP) and the system table take the rail as increasing positions
``x_0 < x_1 < ... < x_{N-1}``: DF and RD need ``dx = (x_{N-1} - x_0)/(N - 1) > 0``, BP takes the rail
ends from ``x_0`` and ``x_{N-1}``, the aperture gain searches the sorted positions. A scan measured
in the other direction (or in any order) is the same measurement with its stops listed differently:
:func:`ordered` sorts the stops by position, moving each stop's S21 row, height, time and flag with
it, so the image equals that of the increasing-rail scan. What cannot be focused is refused in one
line: a non-finite position or height (the stop's geometry is unknown: a NaN height would make
every pixel's range NaN), fewer than two stops, a rail that does not move, a position measured twice.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from sarcli.errors import ProductError
from sarcli.model.gbsar import Scan


def _stops(mask: np.ndarray) -> str:
    idx = np.flatnonzero(mask)
    return ", ".join(str(int(i)) for i in idx[:5]) + (f" (and {idx.size - 5} more)" if idx.size > 5 else "")


def ordered(scan: Scan) -> tuple[Scan, np.ndarray]:
    """``(scan with stops in increasing rail position, order)``: ``order[k]`` is the stop of the input
    now at index k (the identity, and the scan itself, when it was already increasing)."""
    x = np.asarray(scan.rail_position, np.float64)
    h = np.asarray(scan.rail_height, np.float64)
    if not np.all(np.isfinite(x)):
        raise ProductError(f"rail_position is not finite at stop(s) {_stops(~np.isfinite(x))}: the positions of "
                           "the stops are unknown, so the scan cannot be focused")
    if not np.all(np.isfinite(h)):
        raise ProductError(f"rail_height is not finite at stop(s) {_stops(~np.isfinite(h))}: the antenna heights "
                           "are unknown, so the scan cannot be focused")
    if x.size < 2:
        raise ProductError(f"the scan has {x.size} rail stop(s): focusing needs at least 2 (a synthetic aperture)")
    order = np.argsort(x, kind="stable")
    xs = x[order]
    if xs[-1] == xs[0]:
        raise ProductError(f"the rail does not move: all {x.size} stops are at x = {xs[0]:g} m, there is no "
                           "synthetic aperture to focus")
    same = np.flatnonzero(np.diff(xs) == 0)
    if same.size:
        k = int(same[0])
        raise ProductError(f"rail position x = {xs[k]:g} m is measured twice (stops {int(order[k])} and "
                           f"{int(order[k + 1])}): focusing needs one stop per position; drop the repeated stop")
    if np.all(order == np.arange(x.size)):
        return scan, order

    def take(a):
        return None if a is None else np.asarray(a)[order]

    return dataclasses.replace(scan, s21=np.asarray(scan.s21)[:, order], rail_position=xs, rail_height=h[order],
                               stop_time=take(scan.stop_time), stop_flags=take(scan.stop_flags)), order
