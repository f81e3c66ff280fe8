"""Compensating every estimated mover of an ATI pair and measuring where it lands ([Ryu2017, §IV]).

Each mover's slow-time signal is compensated (``pipeline.compensate``, H_ph of [Ryu2017, eq. 20] with the
chosen method) and re-compressed; the compensated movers are added one after the other into the
channel-0 image. Per mover the record gives, in the LOCAL frame (y along track, m):

- ``peak_y_local_m``, ``peak_range_m``, ``width_3db_m``: the compensated mover's azimuth peak (parabolic
  interpolation of the dB cut), its range and -3 dB azimuth width, in a window around its estimated true
  position (azimuth y0, range sqrt(x0^2 + H^2));
- ``before_*``: the uncompensated smear's peak, width and intensity centroid (its displaced position);
- ``conventional_peak_y_local_m``: the same with the conventional method (neglects vy y0 / R0), when asked;
- with a simulated product's truth: ``true_y_local_m`` and the position errors against it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from sarcli.ati.pipeline import MoverResult, Pair, centroid_row, compensate, peak_position, psf_cut, width_3db


def true_window(pair: Pair, res: MoverResult, half_rows: int = 90, half_cols: int = 3) -> tuple[slice, slice]:
    """Rows/columns around the mover's estimated true position (where the compensation puts it)."""
    t = pair.slc0.azimuth_time
    row = int(np.argmin(np.abs(t - (pair.t_ref + res.estimate.y0_m / pair.platform.speed))))
    col = int(np.argmin(np.abs(pair.slc0.slant_range - math.hypot(res.estimate.x0_m, pair.platform.height))))
    n, m = pair.z0.shape
    return (slice(max(0, row - half_rows), min(n, row + half_rows + 1)),
            slice(max(0, col - half_cols), min(m, col + half_cols + 1)))


def y_local(pair: Pair, row: float | np.ndarray) -> Any:
    """LOCAL along-track position (m) of a (fractional) image row."""
    t = pair.slc0.azimuth_time
    dt = float(t[1] - t[0])
    return pair.origin_xy[1] + (float(t[0]) + row * dt - pair.t_ref) * pair.platform.speed


@dataclass
class MoverCompensation:
    """One mover: its estimate, the measured record (module docstring), the image with every mover so far
    compensated, and the conventional method's image of this mover (when asked)."""

    result: MoverResult
    record: dict[str, Any]
    after: np.ndarray
    conventional: np.ndarray | None


def compensate_movers(pair: Pair, results: list[MoverResult], method: str = "exact", compare_conventional: bool = True,
                      truth: list[dict] | None = None) -> Iterator[MoverCompensation]:
    """Compensate the movers one after the other (module docstring), yielding each as it is done."""
    t = pair.slc0.azimuth_time
    dt = float(t[1] - t[0])
    vp = pair.platform.speed
    after = pair.z0
    moving = [m for m in (truth or []) if m["moving"]]
    for res in results:
        d = res.as_dict()
        comp = compensate(pair, res, method)
        after = comp if after is pair.z0 else after + (comp - pair.z0)  # several movers: add each change
        win_r, win_c = true_window(pair, res)
        r, c, cut = psf_cut(after, win_r, win_c)
        rb, _, cut_b = psf_cut(pair.z0, res.rows, res.cols)
        rec = {"id": d["id"], "method": method, "peak_y_local_m": y_local(pair, peak_position(cut, r)),
               "peak_range_m": float(pair.slc0.slant_range[c]), "width_3db_m": width_3db(cut, r) * dt * vp,
               "before_peak_y_local_m": y_local(pair, peak_position(cut_b, rb)),
               "before_width_3db_m": width_3db(cut_b, rb) * dt * vp,
               "before_centroid_y_local_m": y_local(pair, centroid_row(pair.z0, res.rows, res.cols)),
               "estimated_y_local_m": d["y_local_m"]}
        conv = None
        if compare_conventional:
            conv = compensate(pair, res, "conventional")
            rc, _, cut_c = psf_cut(conv, win_r, win_c)
            rec["conventional_peak_y_local_m"] = y_local(pair, peak_position(cut_c, rc))
        if moving:
            best = min(moving, key=lambda m: abs(m["y_m"] - d["y_local_m"]) + abs(m["x_m"] - d["x_local_m"]))
            rec["true_y_local_m"] = best["y_m"]
            rec["position_error_m"] = rec["peak_y_local_m"] - best["y_m"]
            rec["before_displacement_m"] = rec["before_centroid_y_local_m"] - best["y_m"]
            if compare_conventional:
                rec["conventional_position_error_m"] = rec["conventional_peak_y_local_m"] - best["y_m"]
        yield MoverCompensation(res, rec, after, conv)
