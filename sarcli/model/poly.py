"""A 2-D polynomial in normalized coordinates, clipped to its fitted domain (the Doppler models' form).

The fit lives in ``sarcli.doppler.polyfit``; this is only the evaluation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Poly2D:
    """z = x^p sum c[i, j] u^i v^j with u = (x - x0)/xs, v = (y - y0)/ys, |u|, |v| clipped to 1 (the
    fitted domain is x0 +- xs, y0 +- ys), p = ``x_power`` applied to the physical, unclipped x (0: a
    plain polynomial). Units of z as fitted."""

    coef: np.ndarray  # (dx+1, dy+1)
    x0: float
    xs: float
    y0: float
    ys: float
    x_power: int = 0

    def __call__(self, x, y) -> np.ndarray:
        u = np.clip((np.asarray(x, float) - self.x0) / self.xs, -1.0, 1.0)
        v = np.clip((np.asarray(y, float) - self.y0) / self.ys, -1.0, 1.0)
        u, v = np.broadcast_arrays(u, v)
        out = np.zeros(u.shape)
        for i in range(self.coef.shape[0]):
            for j in range(self.coef.shape[1]):
                out = out + self.coef[i, j] * u**i * v**j
        if self.x_power:
            out = out * np.asarray(x, float) ** self.x_power
        return out
