"""The simulator's truth, read for evaluation only: reports compare estimates with it, processing never uses it."""

from __future__ import annotations

from typing import Any


def truth_movers(raw: Any) -> list[dict]:
    """Positions (LOCAL x, y) of the simulated product's truth targets, flagged moving or not."""
    tab = (raw.truth or {}).get("targets")
    if tab is None:
        return []
    return [{"x_m": float(r["x_m"]), "y_m": float(r["y_m"]),
             "moving": bool(abs(r["vel_x_mps"]) + abs(r["vel_y_mps"]) > 0)} for r in tab]
