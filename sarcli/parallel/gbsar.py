"""GB-SAR time series as task graphs over pixel blocks: temporal coherence, mean amplitude, PS values.

The images are never stacked: a task opens ``GROUP`` image products (HDF5, pixels left on disk),
reads one block of rows of each and adds them, image by image in time order, to the block's running
sums -- sum z (complex128), sum |z| (float64), sum |z| (float32, for the mean amplitude) and the
support mask (AND over images). The next group's task takes those sums: per pixel block a chain of
ceil(N / GROUP) tasks, and the blocks are independent, so the graph is as wide as there are blocks.
The order of the additions is that of ``np.sum(stack, axis=0)``: the coherence
``|sum z| / sum |z|`` (:func:`sarcli.gbsar.timeseries.coherence_from_sums`) and the mean amplitude
equal the full-stack computation bit for bit, whatever the block size, the group size or where
the tasks ran. Memory per task: GROUP x block rows x columns x 8 bytes, plus 29 bytes per pixel of
sums. The PS values (second pass) are read by one task per (block, group) holding PS.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.gbsar.interferometry import support
from sarcli.gbsar.timeseries import coherence_from_sums
from sarcli.io.gbsar_image import open_gbsar_image

#: images one task reads
GROUP = 16


@dataclass(frozen=True)
class Series:
    """The image products in time order, the plane of ``pol`` in each, the polarization."""

    paths: tuple[str, ...]
    planes: tuple[int, ...]
    pol: str


@dataclass
class Sums:
    """Running sums of one pixel block over the images added so far."""

    sum_z: np.ndarray
    sum_abs: np.ndarray
    sum_amp: np.ndarray
    ok: np.ndarray
    n: int = 0


def add_images(series: Series, rows: tuple[int, int], lo: int, hi: int, sums: Sums | None = None) -> Sums:
    """Images ``lo..hi-1`` of the series added to the sums of rows ``rows`` (new sums when None; the
    sums given are not modified: a task's input stays as it was, should the task run again)."""
    sl = slice(*rows)
    if sums is not None:
        sums = Sums(sums.sum_z.copy(), sums.sum_abs.copy(), sums.sum_amp.copy(), sums.ok.copy(), sums.n)
    for i in range(lo, hi):
        with open_gbsar_image(series.paths[i]) as img:
            z = img.image[series.planes[i], sl]
            ok = support(img, series.pol, sl, z)
        if sums is None:
            sums = Sums(np.zeros(z.shape, np.complex128), np.zeros(z.shape), np.zeros(z.shape, np.float32),
                        np.ones(z.shape, bool))
        sums.sum_z += z
        a = np.abs(z)
        sums.sum_abs += a
        sums.sum_amp += a
        sums.ok &= ok
        sums.n += 1
    return sums


def block_result(sums: Sums) -> tuple[np.ndarray, np.ndarray, int]:
    """(coherence, NaN where a pixel lacks support in some image; mean amplitude; supported pixels)."""
    gamma = np.where(sums.ok, coherence_from_sums(sums.sum_z, sums.sum_abs), np.nan)
    return gamma, sums.sum_amp / sums.n, int(sums.ok.sum())


def coherence_graph(executor, series: Series, blocks: list[tuple[int, int]], group: int = GROUP) -> list:
    """Per block the chain of :func:`add_images` tasks and its :func:`block_result`: the futures of the
    results, in block order."""
    out = []
    n = len(series.paths)
    for rows in blocks:
        sums = None
        for lo in range(0, n, group):
            sums = executor.submit(add_images, series, rows, lo, min(lo + group, n), sums, label="coherence-sums")
        out.append(executor.submit(block_result, sums, label="coherence-block"))
    return out


def ps_values(series: Series, rows: tuple[int, int], lo: int, hi: int, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(n_ps, hi - lo) complex64: the values at rows ``r`` (within the block) and columns ``c`` of
    images lo..hi-1."""
    out = np.empty((r.size, hi - lo), np.complex64)
    for k, i in enumerate(range(lo, hi)):
        with open_gbsar_image(series.paths[i]) as img:
            out[:, k] = img.image[series.planes[i], slice(*rows)][r, c]
    return out
