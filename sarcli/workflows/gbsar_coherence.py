"""``gbsar_coherence``: two or more images (or scans) of one geometry -> temporal coherence map,
persistent scatterers and their phase / LOS displacement series (``gbsar_ps`` product, CSV, plot).

Temporal coherence ``|sum_i z_i| / sum_i |z_i|`` and PS selection: :mod:`sarcli.gbsar.timeseries`
([LeeGBSAR-I-2007, §3.6]). Memory is bounded: the images are never stacked whole. The reduction is a task graph over
pixel blocks of ``block_rows`` rows (:mod:`sarcli.parallel.gbsar`): each task reads one block of a
group of images from their HDF5 files and adds them, in time order, to the block's running sums, so
the result is the same, bit for bit, as on the full stack. The maps kept whole are the coherence and
the mean amplitude (the PS amplitude floor is relative to the brightest pixel of the whole image); a
second pass reads the PS pixels' values. A scan given instead of an image is focused (``auto``, on
the first image's grid) into a temporary image file beside the output, deleted at the end: the
scans after the first are focused side by side, as tasks. The tasks run in this process, one after
the other, or with ``workers`` / ``scheduler`` on a Dask cluster (:mod:`sarcli.parallel.cluster`;
the files must be visible to the workers).
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
from sarcli.gbsar.interferometry import pol_index
from sarcli.gbsar.timeseries import check_series, ps_series, select_ps
from sarcli.io.atomic import atomic_path
from sarcli.io.gbsar_image import open_gbsar_image, write_gbsar_image
from sarcli.io.interferogram import write_ps
from sarcli.model.gbsar import GbsarImage
from sarcli.workflows.base import Progress, Report, no_progress, using
from sarcli.workflows.gbsar_common import focus_on_the_fly, guard, is_scan, parameters, rail_image, slant_extent

BLOCK_BYTES = 64 * 1024 * 1024  # working memory of one task: a block of a group of images (and temporaries)


@dataclass(frozen=True)
class Config:
    """images: two or more images (or scans) in time order; output: the PS product; threshold: the
    temporal coherence of a PS; dynamic_range_db: PS amplitude floor below the brightest pixel;
    pol (default: the first image's first); csv / plot: optional outputs; block_rows: rows read per
    block (default: as many as fit in ``BLOCK_BYTES``); workers / threads_per_worker / scheduler: run
    the tasks on a Dask cluster (default: here); they do not change the result and are not stored."""

    images: tuple[Path, ...]
    output: Path
    threshold: float = 0.9
    dynamic_range_db: float = 40.0
    pol: str | None = None
    csv: Path | None = None
    plot: Path | None = None
    block_rows: int | None = None
    workers: int | None = None
    threads_per_worker: int = 1
    scheduler: str | None = None

    def __post_init__(self) -> None:
        self.cluster()
        if len(self.images) < 2:
            raise ConfigError("coherence needs at least 2 images")
        if not 0.0 < self.threshold <= 1.0:
            raise ConfigError(f"the coherence threshold (--threshold) must be in (0, 1], got {self.threshold:g}")
        if self.block_rows is not None and self.block_rows < 1:
            raise ConfigError(f"block_rows must be >= 1, got {self.block_rows}")

    def cluster(self):
        """Where the tasks run: None (here) or a :class:`sarcli.parallel.cluster.ClusterSpec`."""
        if self.workers is None and self.scheduler is None:
            return None
        from sarcli.parallel.cluster import cluster_spec

        return cluster_spec(self.scheduler, self.workers, self.threads_per_worker, use_env=False)


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
    csv: str | None = None
    plot: str | None = None

    def lines(self) -> list[str]:
        return [f"wrote {self.output}: {self.n_ps} PS of {self.supported_pixels} supported pixels "
                f"(gamma >= {self.threshold})"] + [f"wrote {p}" for p in (self.csv, self.plot) if p is not None]


def seconds_between(a: str, b: str) -> float:
    """``b - a`` (s) of two ISO-8601 UTC times."""
    try:
        ta, tb = (datetime.fromisoformat(x.replace("Z", "+00:00")) for x in (a, b))
    except ValueError:
        raise ProductError(f"unreadable epoch_utc '{a}' or '{b}'") from None
    return (tb - ta).total_seconds()


def focus_scan_to_file(scan: str, output: str, grid_from: str | None) -> str:
    """A task: ``scan`` focused (``auto``) on the grid of the image product ``grid_from`` (its own when
    None) and written to ``output``."""
    if grid_from is None:
        write_gbsar_image(output, focus_on_the_fly(scan))
    else:
        with open_gbsar_image(grid_from) as like:
            write_gbsar_image(output, focus_on_the_fly(scan, like=like))
    return output


def _image_paths(stack: contextlib.ExitStack, ex, paths: tuple[Path, ...], output: Path) -> list[str]:
    """Every input as an image product; scans are focused into temporary files (the first on its own
    grid, or the first image's; the others on that grid, side by side)."""
    scans = [is_scan(p) for p in paths]
    out = [str(p) for p in paths]
    if not any(scans):
        return out
    tmp = stack.enter_context(tempfile.TemporaryDirectory(prefix=f".{output.name}.", dir=output.parent))
    if scans[0]:
        out[0] = ex.submit(focus_scan_to_file, out[0], str(Path(tmp) / "0.h5"), None, label="gbsar-focus").result()
    focused = {k: ex.submit(focus_scan_to_file, out[k], str(Path(tmp) / f"{k}.h5"), out[0], label="gbsar-focus")
               for k in range(1, len(paths)) if scans[k]}
    for k, f in focused.items():
        out[k] = f.result()
    return out


def _blocks(n: int, size: int) -> list[tuple[int, int]]:
    return [(a, min(a + size, n)) for a in range(0, n, size)]


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
    from sarcli.parallel.cluster import EXECUTION_FIELDS
    from sarcli.parallel.executor import executor
    from sarcli.parallel.gbsar import GROUP, Series, coherence_graph, ps_values

    c = config
    progress = progress or no_progress
    with using(provenance), contextlib.ExitStack() as stack:
        guard(c.images, [c.output, c.csv, c.plot])
        ex = stack.enter_context(executor(c.cluster()))
        paths = _image_paths(stack, ex, c.images, c.output)
        imgs = [rail_image(stack.enter_context(open_gbsar_image(p)), c.images[k]) for k, p in enumerate(paths)]
        ref = imgs[0]
        pol = (c.pol or ref.polarizations[0]).upper()
        check_series(imgs, pol, [str(p) for p in c.images])
        series = Series(tuple(paths), tuple(pol_index(im, pol) for im in imgs), pol)
        n_r, n_x = ref.range_m.size, ref.azimuth_m.size
        size = c.block_rows or max(1, BLOCK_BYTES // (min(len(imgs), GROUP) * max(n_x, 1) * 8 * 4))
        blocks = _blocks(n_r, size)
        gamma = np.empty((n_r, n_x), np.float32)  # NaN outside the common footprint
        mean_amp = np.empty((n_r, n_x), np.float32)
        n_supported = 0
        futures = dict(zip(coherence_graph(ex, series, blocks), blocks, strict=True))
        for done, f in enumerate(ex.as_completed(futures), 1):
            (a, b), (g, amp, n_ok) = futures[f], f.result()
            gamma[a:b], mean_amp[a:b] = g, amp
            n_supported += n_ok
            f.release()
            progress("coherence blocks", done, len(blocks))
        ps_rows, ps_cols = select_ps(gamma, mean_amp, c.threshold, c.dynamic_range_db)
        z = np.empty((ps_rows.size, len(imgs)), np.complex64)
        parts = {}
        for a, b in blocks:  # second pass: the PS pixels' values in every image
            here = np.flatnonzero((ps_rows >= a) & (ps_rows < b))
            for lo in range(0, len(imgs), GROUP) if here.size else ():
                hi = min(lo + GROUP, len(imgs))
                parts[ex.submit(ps_values, series, (a, b), lo, hi, ps_rows[here] - a, ps_cols[here],
                                label="ps-values")] = (here, lo, hi)
        for f in ex.as_completed(parts):
            here, lo, hi = parts[f]
            z[here, lo:hi] = f.result()
        phase, disp = ps_series(z, ref.wavelength_m)
        t = np.array([seconds_between(ref.epoch_utc, im.epoch_utc) + im.scan_time_s for im in imgs])
        by_index = bool(np.any(np.diff(t) <= 0))
        if by_index:
            warnings.warn("the scan times (epoch + mean stop time) are equal or out of order: time_s is kept, "
                          "but the PS plot uses the scan index as its time axis", stacklevel=2)
        attrs = {"pol": pol, "threshold": c.threshold, "dynamic_range_db": c.dynamic_range_db,
                 "epoch_utc": ref.epoch_utc}
        write_ps(c.output, gamma, t, ps_rows, ps_cols, ref.range_m, ref.azimuth_m, phase, disp, attrs,
                 parameters={k: v for k, v in parameters(c).items() if k not in EXECUTION_FIELDS},
                 inputs=c.images)
        if c.csv is not None:
            write_ps_csv(c.csv, ref, ps_rows, ps_cols, gamma, phase, disp)
        if c.plot is not None:
            write_ps_plot(c.plot, ref, gamma, ps_rows, ps_cols, np.arange(t.size) if by_index else t / 60.0,
                          "scan index" if by_index else "time (min)", disp)
        return GbsarCoherenceReport(
            output=str(c.output), n_images=len(imgs), n_ps=int(ps_rows.size), threshold=c.threshold,
            max_abs_phase_change_deg=float(np.degrees(np.max(np.abs(phase)))) if ps_rows.size else None,
            time_s=t.tolist(), plot_time_axis="scan_index" if by_index else "time", supported_pixels=n_supported,
            csv=None if c.csv is None else str(c.csv), plot=None if c.plot is None else str(c.plot))
