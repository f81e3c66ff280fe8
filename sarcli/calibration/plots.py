"""Impulse-response pictures: one per corner reflector (range and azimuth cuts in dB and a 2-D dB chip
with the measured (x) and predicted (+) positions), and one per SLC for its point targets
(``sarcli quality --plot``: the same cuts and chip with contours, one row per target).

The chip (+-``half`` pixels around the measured peak) is demodulated by its carriers (the phase of the
lag-1 correlation along each axis, as ``sarcli.focus.quality`` does) and Fourier-interpolated
``upsample`` times (``scipy.signal.resample``, the chip taken as periodic); the cuts are the rows and
columns of the interpolated chip through its maximum. Axes in metres from the measured peak: slant
range and along-track ground distance.
"""

from __future__ import annotations

import os

import numpy as np

from sarcli.calibration.analysis import ReflectorResult


def _demodulated_chip(image: np.ndarray, row: int, col: int, half: int) -> np.ndarray:
    a, b = max(0, row - half), min(image.shape[0], row + half + 1)
    c, d = max(0, col - half), min(image.shape[1], col + half + 1)
    chip = np.zeros((2 * half + 1, 2 * half + 1), np.complex128)
    chip[a - (row - half):b - (row - half), c - (col - half):d - (col - half)] = image[a:b, c:d]
    for axis in (0, 1):
        x = np.moveaxis(chip, axis, 0)
        f = np.angle(np.sum(x[1:] * np.conj(x[:-1]))) / (2 * np.pi)
        k = np.arange(x.shape[0]) - half
        chip = np.moveaxis(x * np.exp(-2j * np.pi * f * k)[:, None], 0, axis)
    return chip


def draw_irf(axes, image: np.ndarray, row: float, col: float, range_spacing_m: float, along_track_spacing_m: float,
             irw_m: tuple[float, float], irw_theory_m: tuple[float, float] | None = None, half: int = 12,
             upsample: int = 8) -> tuple[np.ndarray, tuple[float, ...], object]:
    """Draw the impulse response at the fractional peak (row, col) on three axes: the range cut, the
    azimuth cut (dB, -3 dB line, the IRWs in the titles) and the 2-D dB chip with contours at -3, -10,
    -20 and -30 dB (module docstring). Returns the chip (dB), its extent (m) and the image artist."""
    from scipy.signal import resample

    r0, c0 = int(round(row)), int(round(col))
    chip = _demodulated_chip(image, r0, c0, half)
    n = chip.shape[0] * upsample
    up = resample(resample(chip, n, axis=0), n, axis=1)
    p = np.abs(up) ** 2
    i, j = np.unravel_index(int(np.argmax(p)), p.shape)
    db = 10.0 * np.log10(np.maximum(p / p[i, j], 1e-12))
    x_rg = ((np.arange(n) / upsample) - half - (col - c0)) * range_spacing_m
    x_az = ((np.arange(n) / upsample) - half - (row - r0)) * along_track_spacing_m
    for k, (ax, x, cut, name) in enumerate(((axes[0], x_rg, db[i, :], "slant range"),
                                            (axes[1], x_az, db[:, j], "along track"))):
        ax.plot(x, cut, "k-", lw=1)
        ax.axhline(-3.0, color="0.6", lw=0.8, ls=":")
        ax.set_ylim(-45, 2)
        ax.set_xlabel(f"{name} from the peak (m)")
        ax.set_ylabel("power (dB)")
        theory = f" (theory {irw_theory_m[k]:.2f} m)" if irw_theory_m is not None else ""
        ax.set_title(f"{name}: IRW {irw_m[k]:.2f} m{theory}")
        ax.grid(alpha=0.3)
    ext = (x_rg[0], x_rg[-1], x_az[-1], x_az[0])
    im = axes[2].imshow(db, cmap="viridis", vmin=-40, vmax=0, extent=ext, aspect="auto", origin="upper")
    cs = axes[2].contour(x_rg, x_az, db, levels=[-30, -20, -10, -3], colors="w", linewidths=0.7)
    axes[2].clabel(cs, fmt="%d dB", fontsize=7)
    axes[2].set_xlabel("slant range (m)")
    axes[2].set_ylabel("along track (m)")
    return db, ext, im


def plot_reflector(path: str | os.PathLike, image: np.ndarray, res: ReflectorResult, range_spacing_m: float,
                   half: int = 12, upsample: int = 8, title: str = "") -> None:
    """Write the IRF picture of one reflector (module docstring) atomically as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sarcli.io.atomic import atomic_path

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), dpi=100)
    _, _, im = draw_irf(axes, image, res.measured_row, res.measured_col, range_spacing_m, res.along_track_spacing_m,
                        (res.range_irw_m, res.azimuth_irw_m), (res.range_irw_theory_m, res.azimuth_irw_theory_m),
                        half, upsample)
    axes[2].plot(0.0, 0.0, "wx", ms=9, mew=2, label="measured")
    axes[2].plot(-res.range_offset_m, -res.azimuth_offset_m, "r+", ms=11, mew=2, label="predicted")
    axes[2].legend(loc="lower right", fontsize=8)
    axes[2].set_title(f"offset rg {res.range_offset_m:+.2f} m, az {res.azimuth_offset_m:+.2f} m")
    fig.colorbar(im, ax=axes[2], label="dB")
    fig.suptitle(title or f"corner reflector {res.id}")
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


def plot_point_targets(path: str | os.PathLike, image: np.ndarray, targets: list[dict], range_spacing_m: float,
                       along_track_spacing_m: float, title: str = "") -> None:
    """One PNG, one row per measured point target (``sarcli quality --plot``): range cut, azimuth cut and
    the 2-D chip with contours (:func:`draw_irf`), PSLR and ISLR in the chip's title. ``targets``:
    records with ``row``/``col`` (fractional peak), ``irw_range_m``, ``irw_azimuth_m``, ``pslr_*_db``,
    ``islr_*_db`` and optionally ``position_error_m``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sarcli.io.atomic import atomic_path

    n = len(targets)
    fig, axes = plt.subplots(n, 3, figsize=(14, 4.0 * n), dpi=100, squeeze=False)
    for k, m in enumerate(targets):
        _, _, im = draw_irf(axes[k], image, m["row"], m["col"], range_spacing_m, along_track_spacing_m,
                            (m["irw_range_m"], m["irw_azimuth_m"]))
        err = f"\nposition error {m['position_error_m']:.2f} m" if "position_error_m" in m else ""
        axes[k, 2].set_title(f"target {k}: PSLR {m['pslr_range_db']:.1f} / {m['pslr_azimuth_db']:.1f} dB,\nISLR "
                             f"{m['islr_range_db']:.1f} / {m['islr_azimuth_db']:.1f} dB (rg / az){err}", fontsize=9)
        fig.colorbar(im, ax=axes[k, 2], label="dB")
    fig.suptitle(title or "point-target impulse responses")
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
