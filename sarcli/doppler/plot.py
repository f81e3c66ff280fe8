"""``--plot`` PNG: fdc and fr against range and azimuth time, per block, shaded by quality."""

from __future__ import annotations

import os

import numpy as np

from sarcli.errors import ConfigError
from sarcli.io.images import atomic_path
from sarcli.model.doppler import PolyDoppler


def plot_doppler(path: str | os.PathLike, model: PolyDoppler, title: str = "") -> None:
    """Four panels: absolute fdc vs range / vs azimuth time (blocks coloured by quality, outliers and
    invalid blocks marked, the fitted model at the scene centre), and fr vs range / vs azimuth time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    b = model.blocks
    r, t, q = b["range_m"], b["azimuth_time_s"], b["quality"]
    ok = b["valid"].astype(bool) & ~b["outlier"].astype(bool)
    s = model.summary
    if s is None:
        raise ConfigError("plot_doppler needs a model with its summary (from estimate_doppler or read_doppler)")
    rr = np.linspace(r.min(), r.max(), 200)
    tt = np.linspace(t.min(), t.max(), 200)
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), constrained_layout=True)
    for j, (x, xs, xlabel, xc) in enumerate(((r / 1e3, rr, "slant range (km)", s.scene_time_s),
                                               (t, tt, "azimuth time (s)", s.scene_range_m))):
        for i, (key, fn, ylabel) in enumerate((("fdc_hz", model.fdc, "Doppler centroid (Hz)"),
                                               ("fr_hz_per_s", model.fr, "Doppler rate (Hz/s)"))):
            a = ax[i, j]
            y = b[key]
            sc = a.scatter(x[ok], y[ok], c=q[ok], cmap="viridis", vmin=0, vmax=max(float(q.max()), 1e-3), s=14)
            if np.any(~ok):
                a.scatter(x[~ok], y[~ok], marker="x", color="red", s=14, label="invalid / outlier")
                a.legend(loc="best", fontsize=8)
            curve = fn(xs, xc) if j == 0 else fn(xc, xs)
            a.plot(xs / 1e3 if j == 0 else xs, curve, color="k", lw=1, label="model")
            a.set_xlabel(xlabel)
            a.set_ylabel(ylabel)
            a.grid(alpha=0.3)
    fig.colorbar(sc, ax=ax, label="block quality |C|/E", shrink=0.6)
    resolved = "" if s.ambiguity_resolved else ", NOT RESOLVED"
    fig.suptitle(title or (f"fdc {s.fdc_hz:.1f} Hz (ambiguity {s.ambiguity}, {s.ambiguity_source}, "
                           f"confidence {s.ambiguity_confidence:.2f}{resolved}), fr {s.fr_hz_per_s:.2f} Hz/s"))
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
