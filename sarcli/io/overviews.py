"""GeoTIFF overview levels computed from a raster's rows as they are written: one pass, no read-back.

A level of factor f holds one pixel per f x f cell of the full image (partial cells at the right and
bottom edges: ceil(n / f) pixels, as GDAL's own levels). The cell's value is the mean the band's
quantity needs (``kind``), over its finite pixels (NaN = no data is left out; a cell with none is NaN):

- ``power``: an amplitude band, ``sqrt(mean(a^2))`` (GDAL's ``RMS``): the mean intensity
- ``power_db``: a dB band, ``10 log10(mean(10^(x/10)))``: the mean intensity in dB (averaging dB values
  instead would bias dark: the mean of the logs is the log of the geometric mean)
- ``phase``: ``arg(sum exp(j phi))``, the circular mean (an average of wrapped phases is meaningless
  across the +-pi cut)
- ``mean``: the plain mean (coherence, displacement, heights, ratios)

How: every pixel contributes its term (a^2, 10^(x/10), (cos x, sin x) or x; 0 where not finite) and a
count (1 where finite). Level 2's cell sums are those of 2 x 2 pixels (:func:`first_cells`), level 4's
those of 2 x 2 cells of level 2 (:func:`pool2`), and so on: sums add, so each level is exact, and a
level's mean comes from its sums and counts (:func:`level_pixels`). All in float64; every cell is
summed by one thread in one order, (top-left + bottom-left) + top-right + bottom-right, so the levels
do not depend on the thread count or on how the rows arrive (:class:`Pyramid`: whole windows of
``max(factors, 256)`` rows from row 0, whatever the strips).
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numba import njit, prange

from sarcli.errors import ProductError

OverviewKind = Literal["power", "power_db", "phase", "mean"]
#: the kernels' codes of the reductions
KIND_CODES: dict[str, int] = {"power": 0, "power_db": 1, "phase": 2, "mean": 3}
#: ln(10) / 10: 10^(x / 10) = exp(x ln(10) / 10)
_DB_TO_LN = math.log(10.0) / 10.0


def overview_factors(shape: tuple[int, int], block: int) -> list[int]:
    """Factors 2, 4, ... until the reduced image fits one ``block`` x ``block`` tile."""
    out, f = [], 2
    while max(shape) / (f // 2) > block and min(shape) >= f:
        out.append(f)
        f *= 2
    return out


@njit(cache=True, inline="always")
def _term(x: float, kind: int) -> tuple[float, float, float]:
    """(term, its sine part for phase, count) of one pixel value (module docstring)."""
    if not np.isfinite(x):
        return 0.0, 0.0, 0.0
    if kind == 0:
        return x * x, 0.0, 1.0
    if kind == 1:
        return np.exp(x * _DB_TO_LN), 0.0, 1.0  # 10^(x/10): exp is twice as fast as pow, same to 1e-15
    if kind == 2:
        return np.cos(x), np.sin(x), 1.0
    return x, 0.0, 1.0


@njit(cache=True, inline="always")
def _pixel(v: float, s: float, c: float, kind: int) -> float:
    """A level's pixel from its cell's sums (``v``, sine part ``s``) and count ``c``: NaN without data."""
    if c <= 0.0:
        return np.nan
    if kind == 2:
        return np.arctan2(s, v)
    mean = v / c
    if kind == 0:
        return np.sqrt(mean)
    if kind == 1:
        return 10.0 * np.log10(mean)
    return mean


@njit(cache=True, parallel=True)
def first_cells(data: np.ndarray, kind: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Level 2 of ``data`` (rows x cols, float32 or float64) for reduction ``kind`` (:data:`KIND_CODES`):
    its cells' sums of the pixel terms, sine sums (phase; zeros otherwise), counts (float64) and its
    float32 pixels, each (ceil(rows / 2), ceil(cols / 2))."""
    n, m = data.shape
    rn, rm = (n + 1) // 2, (m + 1) // 2
    re = np.empty((rn, rm))
    im = np.zeros((rn, rm))
    cnt = np.empty((rn, rm))
    px = np.empty((rn, rm), np.float32)
    for i in prange(rn):
        a = 2 * i
        two_rows = a + 1 < n
        for j in range(rm):
            b = 2 * j
            v, s, c = _term(np.float64(data[a, b]), kind)
            if two_rows:
                v2, s2, c2 = _term(np.float64(data[a + 1, b]), kind)
                v += v2
                s += s2
                c += c2
            if b + 1 < m:
                v2, s2, c2 = _term(np.float64(data[a, b + 1]), kind)
                v += v2
                s += s2
                c += c2
                if two_rows:
                    v2, s2, c2 = _term(np.float64(data[a + 1, b + 1]), kind)
                    v += v2
                    s += s2
                    c += c2
            re[i, j] = v
            im[i, j] = s
            cnt[i, j] = c
            px[i, j] = _pixel(v, s, c, kind)
    return re, im, cnt, px


@njit(cache=True)
def pool2(x: np.ndarray) -> np.ndarray:
    """Sums over the 2 x 2 cells of ``x`` (float64; an odd last row or column: partial cells). Serial:
    levels past the first are small, and a parallel launch per call costs more than the sums."""
    n, m = x.shape
    rn, rm = (n + 1) // 2, (m + 1) // 2
    out = np.empty((rn, rm))
    for i in range(rn):
        a = 2 * i
        for j in range(rm):
            b = 2 * j
            v = x[a, b]
            if a + 1 < n:
                v += x[a + 1, b]
            if b + 1 < m:
                v += x[a, b + 1]
                if a + 1 < n:
                    v += x[a + 1, b + 1]
            out[i, j] = v
    return out


@njit(cache=True)
def level_pixels(re: np.ndarray, im: np.ndarray, cnt: np.ndarray, kind: int) -> np.ndarray:
    """A level's float32 pixels from its cells' sums and counts: NaN where a cell holds no data."""
    n, m = cnt.shape
    out = np.empty((n, m), np.float32)
    for i in range(n):
        for j in range(m):
            out[i, j] = _pixel(re[i, j], im[i, j], cnt[i, j], kind)
    return out


def levels_of_window(values: np.ndarray, kind: OverviewKind, n_levels: int) -> list[np.ndarray]:
    """The float32 pixels of levels 2, 4, ..., 2^n_levels of one window of a band (rows: whole cells of
    the last level, but at the image's end)."""
    code = KIND_CODES[kind]
    re, im, cnt, px = first_cells(values, code)
    out = [px]
    for _ in range(n_levels - 1):
        re, cnt = pool2(re), pool2(cnt)
        im = pool2(im) if code == 2 else re  # im is read for phase only
        out.append(level_pixels(re, im, cnt, code))
    return out


class Pyramid:
    """The overview levels (``factors`` 2, 4, 8, ...) of a raster of ``shape`` and ``len(kinds)`` bands,
    one GeoTIFF a level in ``folder`` (``names``), fed the raster's rows in order (:meth:`add`: a strip of
    every band); a context manager (the level files are complete when it exits normally)."""

    def __init__(self, folder: str | os.PathLike, shape: tuple[int, int], factors: Sequence[int],
                 kinds: Sequence[OverviewKind], block: int):
        if list(factors) != [2 ** k for k in range(1, len(factors) + 1)]:
            raise ProductError(f"overview factors {list(factors)} are not 2, 4, 8, ...")
        for k in kinds:
            if k not in KIND_CODES:
                raise ProductError(f"unknown overview reduction {k!r}")
        self.folder, self.shape, self.factors, self.kinds = str(folder), shape, list(factors), list(kinds)
        self.block = block
        self.names = [f"ov{f}.tif" for f in factors]
        self.step = max(max(factors, default=1), block)  # rows per window: whole cells of every level
        self._row = 0  # rows done
        self._held: list[np.ndarray] | None = None  # rows of an unfinished window
        self._stack = contextlib.ExitStack()
        self._dst: list = []

    def __enter__(self) -> Pyramid:
        import rasterio

        n, m = self.shape
        for f, name in zip(self.factors, self.names, strict=True):
            h, w = -(-n // f), -(-m // f)
            # tiled like the COG it feeds (band-interleaved, block x block): GDAL's COG copy then reads
            # whole tiles of a level instead of a tile's rows from strips (2.2 s less on a full scene's map);
            # TIFF tiles are multiples of 16
            tiled = min(h, w) >= self.block and self.block % 16 == 0
            tiles = {"tiled": True, "blockxsize": self.block, "blockysize": self.block} if tiled else {}
            self._dst.append(self._stack.enter_context(rasterio.open(
                os.path.join(self.folder, name), "w", driver="GTiff", count=len(self.kinds), dtype="float32",
                nodata=np.nan, height=h, width=w, INTERLEAVE="BAND", **tiles)))
        return self

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            if self._held is not None:
                self._window(self._held)
                self._held = None
            if self.factors and self._row != self.shape[0]:
                self._stack.close()
                raise ProductError(f"overviews: {self._row} of {self.shape[0]} rows received")
        self._stack.close()

    def add(self, values: Sequence[np.ndarray]) -> None:
        """The next rows of every band (float32 arrays of equal rows); nothing to do without levels."""
        if not self.factors:
            return
        if self._held is not None:
            values = [np.concatenate([h, v]) for h, v in zip(self._held, values, strict=True)]
            self._held = None
        rows = values[0].shape[0]
        whole = rows - rows % self.step
        for a in range(0, whole, self.step):
            self._window([v[a:a + self.step] for v in values])
        if whole < rows:
            self._held = [np.array(v[whole:]) for v in values]

    def _window(self, values: Sequence[np.ndarray]) -> None:
        from rasterio.windows import Window

        row = self._row
        for i, (kind, v) in enumerate(zip(self.kinds, values, strict=True), start=1):
            for f, out, cells in zip(self.factors, self._dst, levels_of_window(v, kind, len(self.factors)),
                                     strict=True):
                out.write(cells, i, window=Window(0, row // f, cells.shape[1], cells.shape[0]))
        self._row += values[0].shape[0]
