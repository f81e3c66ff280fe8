"""``--plot`` PNG of a Doppler estimate: what helps judge it, against range.

Panels (legends in each): (1) the absolute centroid of every block (coloured by quality |C|/E; invalid
blocks and fit outliers as red crosses) with the fitted model at the scene time, the orbit + attitude
geometry centroid of the blocks (``fdc_orbit_hz``, already in the product) and, for a simulated raw
product, the simulator's truth; (2) the residuals of the blocks from the fitted model (and of the
geometry), with the PRF ambiguity step drawn for scale; (3) the Doppler rate of the blocks, the model
and its geometric seed; (4) only when the scene has more than one azimuth block: the centroid against
azimuth time (with a single block in time that panel would be one column of points).

The truth is read here only to draw it beside the estimate (a picture for people, like ``quality``):
the estimator never sees it.
"""

from __future__ import annotations

import os

import numpy as np

from sarcli.errors import ConfigError
from sarcli.io.images import atomic_path
from sarcli.model.constants import C_LIGHT
from sarcli.model.doppler import PolyDoppler


def _drawn(blocks: dict, key: str) -> bool:
    """Whether the block column ``key`` has a value to draw (a product without an orbit stores NaN: no
    line, so no legend entry)."""
    return key in blocks and bool(np.isfinite(np.asarray(blocks[key], np.float64)).any())


def truth_curves(raw) -> dict[str, np.ndarray] | None:
    """The simulator's Doppler truth of a raw product on its sample ranges (``range_m``, ``fdc_hz``,
    ``fr_hz_per_s``, ``time_s``), or None for a product without one."""
    truth = getattr(raw, "truth", None) or {}
    fdc = truth.get("doppler_centroid_hz")
    if fdc is None:
        return None
    fdc = np.asarray(fdc, np.float64)
    r = raw.radar
    rng = C_LIGHT / 2.0 * (r.window_start_s + np.arange(fdc.size) / r.range_sampling_rate_hz)
    fr = truth.get("doppler_rate_hz_per_s")
    return {"range_m": rng, "fdc_hz": fdc, "fr_hz_per_s": None if fr is None else np.asarray(fr, np.float64),
            "time_s": float(truth.get("doppler_truth_time_s", np.nan))}


def plot_doppler(path: str | os.PathLike, model: PolyDoppler, raw=None, title: str = "") -> None:
    """Write the picture of the module docstring; ``raw``: the raw product, for its truth (optional)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = model.summary
    if s is None:
        raise ConfigError("plot_doppler needs a model with its summary (from estimate_doppler or read_doppler)")
    b = model.blocks
    r, t, q = (np.asarray(b[k], np.float64) for k in ("range_m", "azimuth_time_s", "quality"))
    ok = np.asarray(b["valid"]).astype(bool) & ~np.asarray(b["outlier"]).astype(bool)
    rr = np.linspace(r.min(), r.max(), 200)
    truth = truth_curves(raw) if raw is not None else None
    n_az = int(np.unique(np.round(t, 9)).size)
    panels = 4 if n_az > 1 else 3
    fig, axes = plt.subplots(panels, 1, figsize=(10, 3.2 * panels), constrained_layout=True, sharex=False)
    km = 1e-3

    def blocks(ax, y, label):
        sc = ax.scatter(r[ok] * km, y[ok], c=q[ok], cmap="viridis", vmin=0, vmax=max(float(q.max()), 1e-3), s=16,
                        label=label)
        if np.any(~ok):
            ax.scatter(r[~ok] * km, y[~ok], marker="x", color="red", s=16, label="invalid / outlier")
        return sc

    ax = axes[0]
    sc = blocks(ax, np.asarray(b["fdc_hz"], np.float64), "blocks (colour: quality)")
    ax.plot(rr * km, model.fdc(rr, s.scene_time_s), "k-", lw=1.5, label=f"fitted model at t = {s.scene_time_s:.3g} s")
    if _drawn(b, "fdc_orbit_hz"):
        o = np.argsort(r)
        ax.plot(r[o] * km, np.asarray(b["fdc_orbit_hz"])[o], "--", color="tab:orange", lw=1.2,
                label="orbit + attitude geometry")
    if truth is not None:
        ax.plot(truth["range_m"] * km, truth["fdc_hz"], ":", color="tab:green", lw=2,
                label=f"simulator truth at t = {truth['time_s']:.3g} s")
    ax.set_ylabel("Doppler centroid (Hz)")
    ax.set_title("centroid against slant range")
    ax.legend(loc="best", fontsize=8)
    fig.colorbar(sc, ax=ax, label="block quality |C|/E")

    ax = axes[1]
    res = np.asarray(b["fdc_hz"], np.float64) - model.fdc(r, t)
    blocks(ax, res, "blocks - model")
    if _drawn(b, "fdc_orbit_hz"):
        o = np.argsort(r)
        ax.plot(r[o] * km, (np.asarray(b["fdc_orbit_hz"], np.float64) - model.fdc(r, t))[o], "--",
                color="tab:orange", label="geometry - model")
    if truth is not None:
        ax.plot(truth["range_m"] * km, truth["fdc_hz"] - model.fdc(truth["range_m"], truth["time_s"]), ":",
                color="tab:green", lw=2, label="truth - model")
    ax.axhline(0.0, color="k", lw=0.8)
    span = max(float(np.nanmax(np.abs(res[ok]))) if ok.any() else 1.0, 1.0)
    if model.prf_hz < 4 * span:
        for k in (-1, 1):
            ax.axhline(k * model.prf_hz, color="0.5", ls=":", lw=0.8)
    ax.set_ylabel("residual (Hz)")
    ax.set_title(f"residuals from the fitted model (PRF {model.prf_hz:.1f} Hz = one ambiguity)")
    ax.legend(loc="best", fontsize=8)

    ax = axes[2]
    blocks(ax, np.asarray(b["fr_hz_per_s"], np.float64), "blocks")
    ax.plot(rr * km, model.fr(rr, s.scene_time_s), "k-", lw=1.5, label="model")
    if _drawn(b, "fr_seed_hz_per_s"):
        o = np.argsort(r)
        ax.plot(r[o] * km, np.asarray(b["fr_seed_hz_per_s"])[o], "--", color="tab:orange", label="geometric seed")
    if truth is not None and truth["fr_hz_per_s"] is not None:
        ax.plot(truth["range_m"] * km, truth["fr_hz_per_s"], ":", color="tab:green", lw=2, label="simulator truth")
    ax.set_ylabel("Doppler rate (Hz/s)")
    ax.set_title(f"Doppler rate ({s.fr_method})")
    ax.legend(loc="best", fontsize=8)
    for a in axes[:3]:
        a.set_xlabel("slant range (km)")
        a.grid(alpha=0.3)
    if panels == 4:
        ax = axes[3]
        ax.scatter(t[ok], np.asarray(b["fdc_hz"])[ok], c=q[ok], cmap="viridis", s=16, label="blocks")
        tt = np.linspace(t.min(), t.max(), 200)
        ax.plot(tt, model.fdc(s.scene_range_m, tt), "k-", label=f"model at R = {s.scene_range_m * km:.2f} km")
        ax.set_xlabel("azimuth time (s)")
        ax.set_ylabel("Doppler centroid (Hz)")
        ax.set_title(f"centroid against time ({n_az} azimuth blocks)")
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
    resolved = "" if s.ambiguity_resolved else ", NOT RESOLVED"
    fig.suptitle(title or (f"fdc {s.fdc_hz:.1f} Hz (ambiguity {s.ambiguity}, {s.ambiguity_source}, "
                           f"confidence {s.ambiguity_confidence:.2f}{resolved}), fr {s.fr_hz_per_s:.2f} Hz/s"))
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
