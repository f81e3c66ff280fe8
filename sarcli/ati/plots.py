"""PNG figures of the ATI commands: azimuth PSFs ([Ryu2017, Figs. 5b, 8]) and Monte-Carlo errors (Fig. 9)."""

from __future__ import annotations

import os

import numpy as np


def save_figure(fig, path: str | os.PathLike) -> None:
    """Save a matplotlib figure as PNG atomically (``sarcli.io.images.atomic_path``) and close it."""
    import matplotlib.pyplot as plt

    from sarcli.io.images import atomic_path

    try:
        with atomic_path(path, ".png") as tmp:
            fig.savefig(tmp, format="png")
    finally:
        plt.close(fig)


def psf_plot(profiles: dict[str, tuple[np.ndarray, np.ndarray]], path: str | os.PathLike, title: str) -> None:
    """Azimuth PSFs: name -> (azimuth position m, complex or magnitude cut), in dB relative to the
    strongest peak of all of them (so the defocusing loss of the uncompensated mover stays visible)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    top = max(float(np.max(np.abs(v))) for _, v in profiles.values())
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
    for name, (y, v) in profiles.items():
        ax.plot(y, 20 * np.log10(np.maximum(np.abs(v), 1e-12) / top), label=name)
    ax.set_ylim(-50, 3)
    ax.set_xlabel("azimuth position y (m, LOCAL frame)")
    ax.set_ylabel("amplitude (dB)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path)


def montecarlo_plot(result: dict, path: str | os.PathLike) -> None:
    """Relative error (%) of vy, x0, y0 vs SNR, mean and max (like [Ryu2017, Fig. 9])."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = result["per_snr"]
    snr = [e["snr_db"] for e in t]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8), dpi=100)
    for ax, k in zip(axes, ("vy", "x0", "y0"), strict=True):
        ax.semilogy(snr, [100 * e[f"{k}_mean_rel"] for e in t], "o-", label="mean")
        ax.semilogy(snr, [100 * e[f"{k}_max_rel"] for e in t], "s--", label="max")
        ax.semilogy(snr, [100 * e[f"{k}_sigma_mean_rel"] for e in t], ":", label="reported 1-sigma")
        ax.axhline(0.2, color="gray", lw=0.8)
        ax.set_title(f"{k} relative error")
        ax.set_xlabel("SNR (dB)")
        ax.set_ylabel("%")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend()
    fig.suptitle(f"ATI Monte-Carlo, {t[0]['runs']} runs per SNR, route {result['route']}")
    fig.tight_layout()
    save_figure(fig, path)
