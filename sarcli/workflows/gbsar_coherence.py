"""``gbsar_coherence``: two or more images (or scans) of one geometry -> temporal coherence map,
persistent scatterers and their phase / LOS displacement series (``gbsar_ps`` product, CSV, plot).

Temporal coherence ``|sum_i z_i| / sum_i |z_i|`` and PS selection: :mod:`sarcli.gbsar.timeseries`
(seed 003). Memory is bounded: the images are never stacked whole. Each image product is read by
blocks of ``block_rows`` rows from its HDF5 file (one block of every image at a time); the per-pixel
sums run over the images only, so the result is the same, bit for bit, as on the full stack. The
maps kept whole are the coherence and the mean amplitude (the PS amplitude floor is relative to the
brightest pixel of the whole image); a second pass reads the PS pixels' values. A scan given instead
of an image is focused (``auto``, on the first image's grid) into a temporary image file beside the
output, deleted at the end.
"""

from __future__ import annotations

import contextlib
import csv
import tempfile
import warnings
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np

from sarcli.errors import ConfigError, ProductError
from sarcli.gbsar.interferometry import pol_index, support
from sarcli.gbsar.timeseries import check_series, ps_series, select_ps, temporal_coherence
from sarcli.io.atomic import atomic_path
from sarcli.io.gbsar_image import open_gbsar_image, write_gbsar_image
from sarcli.io.interferogram import write_ps
from sarcli.model.gbsar import GbsarImage
from sarcli.workflows.base import Progress, Report, no_progress, using
from sarcli.workflows.gbsar_common import focus_on_the_fly, guard, is_scan, parameters, rail_image, slant_extent

BLOCK_BYTES = 64 * 1024 * 1024  # working memory of one block of every image (complex64 and temporaries)


@dataclass(frozen=True)
class Config:
    """images: two or more images (or scans) in time order; output: the PS product; threshold: the
    temporal coherence of a PS; dynamic_range_db: PS amplitude floor below the brightest pixel;
    pol (default: the first image's first); csv / plot: optional outputs; block_rows: rows read per
    block (default: as many as fit in ``BLOCK_BYTES``)."""

    images: tuple[Path, ...]
    output: Path
    threshold: float = 0.9
    dynamic_range_db: float = 40.0
    pol: str | None = None
    csv: Path | None = None
    plot: Path | None = None
    block_rows: int | None = None

    def __post_init__(self) -> None:
        if len(self.images) < 2:
            raise ConfigError("coherence needs at least 2 images")
        if not 0.0 < self.threshold <= 1.0:
            raise ConfigError(f"the coherence threshold (--threshold) must be in (0, 1], got {self.threshold:g}")
        if self.block_rows is not None and self.block_rows < 1:
            raise ConfigError(f"block_rows must be >= 1, got {self.block_rows}")


@dataclass
class GbsarCoherenceReport(Report):
    output: str
    n_images: int
    n_ps: int
    threshold: float
    max_abs_phase_change_deg: float | None
    time_s: list[float] = field(default_factory=list)
    plot_time_axis: str = "time"
    supported_pixels: int = 0

    def lines(self) -> list[str]:
        return [f"wrote {self.output}: {self.n_ps} PS of {self.supported_pixels} supported pixels "
                f"(gamma >= {self.threshold})"]


def seconds_between(a: str, b: str) -> float:
    """``b - a`` (s) of two ISO-8601 UTC times."""
    try:
        ta, tb = (datetime.fromisoformat(x.replace("Z", "+00:00")) for x in (a, b))
    except ValueError:
        raise ProductError(f"unreadable epoch_utc '{a}' or '{b}'") from None
    return (tb - ta).total_seconds()


def _open_all(stack: contextlib.ExitStack, paths: tuple[Path, ...], output: Path) -> list[GbsarImage]:
    """Every input as an image whose pixels stay on disk; scans are focused into temporary files."""
    imgs: list[GbsarImage] = []
    tmp: str | None = None
    for k, p in enumerate(paths):
        if is_scan(p):
            if tmp is None:
                tmp = stack.enter_context(tempfile.TemporaryDirectory(prefix=f".{output.name}.", dir=output.parent))
            focused = Path(tmp) / f"{k}.h5"
            write_gbsar_image(focused, focus_on_the_fly(p, like=imgs[0] if imgs else None))
            p = focused
        imgs.append(rail_image(stack.enter_context(open_gbsar_image(p)), paths[k]))
    return imgs


def _blocks(n: int, size: int) -> list[slice]:
    return [slice(a, min(a + size, n)) for a in range(0, n, size)]


def write_ps_csv(path: Path, img: GbsarImage, rows, cols, gamma, phase, disp) -> None:
    """One line per PS: position, coherence, phase (deg) and LOS displacement (mm) per scan; atomic."""
    n = phase.shape[1] if phase.ndim == 2 else 0
    with atomic_path(path, ".csv") as tmp, open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["ps", "azimuth_m", "range_m", "coherence"] + [f"phase_deg_{i}" for i in range(n)]
                   + [f"displacement_mm_{i}" for i in range(n)])
        for k, (r, c) in enumerate(zip(rows, cols, strict=True)):
            w.writerow([k, f"{img.azimuth_m[c]:.3f}", f"{img.range_m[r]:.3f}", f"{gamma[r, c]:.5f}"]
                       + [f"{v:.3f}" for v in np.degrees(phase[k])] + [f"{v:.4f}" for v in disp[k]])


def write_ps_plot(path: Path, img: GbsarImage, gamma, rows, cols, t_axis, t_label: str, disp) -> None:
    """PNG: the temporal coherence map with the PS marked, and the first 20 PS displacement series."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 5), dpi=100)
    im = a1.imshow(gamma, vmin=0, vmax=1, cmap="viridis", aspect="auto", interpolation="nearest",
                   extent=slant_extent(img))
    a1.plot(img.azimuth_m[cols], img.range_m[rows], "r.", ms=3, label="PS")
    a1.set(xlabel="azimuth x (m)", ylabel="range R0 (m)", title="temporal coherence")
    fig.colorbar(im, ax=a1)
    for k in range(min(rows.size, 20)):
        a2.plot(t_axis, disp[k], ".-")
    a2.set(xlabel=t_label, ylabel="LOS displacement (mm)", title=f"{rows.size} PS (first 20 shown)")
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


def run(config: Config, provenance=None, progress: Progress | None = None) -> GbsarCoherenceReport:
    """Temporal coherence, PS selection and PS series of ``config.images`` (module docstring)."""
    c = config
    progress = progress or no_progress
    with using(provenance), contextlib.ExitStack() as stack:
        guard(c.images, [c.output, c.csv, c.plot])
        imgs = _open_all(stack, c.images, c.output)
        ref = imgs[0]
        pol = (c.pol or ref.polarizations[0]).upper()
        check_series(imgs, pol, [str(p) for p in c.images])
        planes = [pol_index(im, pol) for im in imgs]
        n_r, n_x = ref.range_m.size, ref.azimuth_m.size
        size = c.block_rows or max(1, BLOCK_BYTES // (len(imgs) * max(n_x, 1) * 8 * 4))
        gamma = np.empty((n_r, n_x), np.float32)  # NaN outside the common footprint
        mean_amp = np.empty((n_r, n_x), np.float32)
        n_supported = 0

        def read(rows: slice) -> np.ndarray:
            return np.stack([im.image[k, rows] for im, k in zip(imgs, planes, strict=True)])

        for rows in _blocks(n_r, size):
            blk = read(rows)
            ok = np.logical_and.reduce([support(im, pol, rows, b) for im, b in zip(imgs, blk, strict=True)])
            gamma[rows] = np.where(ok, temporal_coherence(blk), np.nan)
            mean_amp[rows] = np.mean(np.abs(blk), axis=0)
            n_supported += int(ok.sum())
            progress("coherence rows", rows.stop, n_r)
        ps_rows, ps_cols = select_ps(gamma, mean_amp, c.threshold, c.dynamic_range_db)
        z = np.empty((ps_rows.size, len(imgs)), np.complex64)
        for rows in _blocks(n_r, size):  # second pass: the PS pixels' values in every image
            here = (ps_rows >= rows.start) & (ps_rows < rows.stop)
            if here.any():
                z[here] = read(rows)[:, ps_rows[here] - rows.start, ps_cols[here]].T
        phase, disp = ps_series(z, ref.wavelength_m)
        t = np.array([seconds_between(ref.epoch_utc, im.epoch_utc) + im.scan_time_s for im in imgs])
        by_index = bool(np.any(np.diff(t) <= 0))
        if by_index:
            warnings.warn("the scan times (epoch + mean stop time) are equal or out of order: time_s is kept, "
                          "but the PS plot uses the scan index as its time axis", stacklevel=2)
        attrs = {"pol": pol, "threshold": c.threshold, "dynamic_range_db": c.dynamic_range_db,
                 "epoch_utc": ref.epoch_utc}
        write_ps(c.output, gamma, t, ps_rows, ps_cols, ref.range_m, ref.azimuth_m, phase, disp, attrs,
                 parameters=parameters(c), inputs=c.images)
        if c.csv is not None:
            write_ps_csv(c.csv, ref, ps_rows, ps_cols, gamma, phase, disp)
        if c.plot is not None:
            write_ps_plot(c.plot, ref, gamma, ps_rows, ps_cols, np.arange(t.size) if by_index else t / 60.0,
                          "scan index" if by_index else "time (min)", disp)
        return GbsarCoherenceReport(
            output=str(c.output), n_images=len(imgs), n_ps=int(ps_rows.size), threshold=c.threshold,
            max_abs_phase_change_deg=float(np.degrees(np.max(np.abs(phase)))) if ps_rows.size else None,
            time_s=t.tolist(), plot_time_axis="scan_index" if by_index else "time", supported_pixels=n_supported)
