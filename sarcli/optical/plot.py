"""The comparison figure: images around the brightest target (dB) and their azimuth PSFs."""

from __future__ import annotations

import os

import numpy as np

from sarcli.io.images import amplitude_db


def comparison_png(path: str | os.PathLike, images: dict[str, dict[str, np.ndarray]], title: str = "") -> None:
    """One column per image: top the amplitude (dB, 40 dB range, own peak), bottom the azimuth cut
    through the peak normalized to 0 dB."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sarcli.io.images import atomic_path

    n = len(images)
    fig, axes = plt.subplots(2, n, figsize=(3.2 * n, 7), dpi=100, squeeze=False)
    for k, (label, crop) in enumerate(images.items()):
        img, t, r = crop["image"], crop["azimuth_time"], crop["slant_range"]
        db = amplitude_db(img)
        top = float(db.max())
        ax = axes[0, k]
        ax.imshow(db, cmap="gray", vmin=top - 40, vmax=top, aspect="auto", interpolation="nearest",
                  extent=(r[0], r[-1], t[-1], t[0]))
        ax.set_title(label, fontsize=9)
        ax.set_xlabel("slant range (m)")
        if k == 0:
            ax.set_ylabel("zero-Doppler time (s)")
        i, j = np.unravel_index(int(np.argmax(np.abs(img))), img.shape)
        cut = db[:, j] - db[i, j]
        axes[1, k].plot(t, cut, lw=0.8)
        axes[1, k].set_ylim(-50, 3)
        axes[1, k].grid(alpha=0.3)
        axes[1, k].set_xlabel("zero-Doppler time (s)")
        if k == 0:
            axes[1, k].set_ylabel("azimuth PSF (dB)")
    fig.suptitle(title)
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
