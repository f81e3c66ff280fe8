"""What is computed from the focused blocks as they stream past: one pass over the image, in any block order.

The focus workflow hands every block (``first`` line, lines) to a :class:`BlockSink`, which

- writes it (the SLC product's ``/image`` rows, any order: HDF5 writes rows where they belong);
- keeps its per-line intensity sums (:func:`sarcli.focus.quality.line_sums`; the image statistics over
  the fully focused lines, known only when the focuser finishes, are the sums of those lines' rows:
  :meth:`BlockSink.statistics`);
- feeds :class:`LookAccumulator` s: the multilooked intensity of the GeoTIFFs and of the quicklook,
  computed cell row by cell row as soon as the lines of a cell row are there.

So no second pass reads the SLC back, and the whole image is never in memory. A large multilooked
intensity (more than ``SPILL_BYTES``; a full Radarsat-1 scene at one look is 585 MB) is kept in an
anonymous temporary file while the blocks are focused, and read back once they are all done: it
does not add to the focus's working memory. A cell row split
between two blocks waits for its lines in a buffer of ``looks_az`` lines. Every cell is computed by
:func:`sarcli.focus.geocode.multilook` on exactly its lines, so the result is the same, bit for bit,
as multilooking the whole image (numpy's reduction of one cell does not depend on the rows around it:
tests/parallel/test_sink.py). The statistics are the same up to the order of the float64 sums
(last bits).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable

import numpy as np

from sarcli.errors import SarcliError
from sarcli.focus.geocode import multilook
from sarcli.focus.quality import line_sums, statistics_from_sums

#: a multilooked intensity larger than this waits in a temporary file (``spill_dir``) until all blocks are in
SPILL_BYTES = 64 << 20


class LookAccumulator:
    """``multilook(image, looks_az, looks_rg)`` of an image of ``shape`` received as row blocks in any order;
    with ``spill_dir``, a result larger than :data:`SPILL_BYTES` is kept in an anonymous file there
    until :meth:`result`."""

    def __init__(self, shape: tuple[int, int], looks_az: int, looks_rg: int, spill_dir: str | None = None):
        if looks_az < 1 or looks_rg < 1:
            raise SarcliError("looks must be positive integers")
        n, m = shape[0] // looks_az, shape[1] // looks_rg
        if n < 1 or m < 1:
            raise SarcliError(f"image {tuple(shape)} is smaller than one {looks_az} x {looks_rg} look cell")
        self.looks = (looks_az, looks_rg)
        self.shape = (n, m)
        spill = spill_dir is not None and n * m * 4 > SPILL_BYTES
        self._file = tempfile.TemporaryFile(prefix=".sarcli-looks-", dir=spill_dir) if spill else None
        self.out = None if spill else np.empty((n, m), np.float32)
        self._done = np.zeros(n, bool)
        self._pending: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # cell row -> (lines, which filled)

    def add(self, first: int, lines: np.ndarray) -> None:
        la, lr = self.looks
        n = self.shape[0]
        stop = first + lines.shape[0]
        c0, c1 = -(-first // la), min(stop // la, n)  # cell rows whose lines are all in this block
        if c1 > c0:
            self._store(c0, multilook(lines[c0 * la - first:c1 * la - first], la, lr))
            self._done[c0:c1] = True
        for c in {first // la, (stop - 1) // la}:
            if c >= n or c0 <= c < c1:
                continue
            a, b = max(first, c * la), min(stop, (c + 1) * la)
            buf, got = self._pending.setdefault(c, (np.empty((la, lines.shape[1]), lines.dtype), np.zeros(la, bool)))
            buf[a - c * la:b - c * la] = lines[a - first:b - first]
            got[a - c * la:b - c * la] = True
            if got.all():
                self._store(c, multilook(buf, la, lr))
                self._done[c] = True
                del self._pending[c]

    def _store(self, row: int, cells: np.ndarray) -> None:
        if self._file is None:
            self.out[row:row + cells.shape[0]] = cells
        else:
            os.pwrite(self._file.fileno(), np.ascontiguousarray(cells, np.float32).tobytes(), row * self.shape[1] * 4)

    def result(self) -> np.ndarray:
        """The multilooked intensity (float32); every cell row must have been received."""
        if not self._done.all():
            raise SarcliError(f"multilook: {int((~self._done).sum())} cell rows never received their lines")
        if self._file is not None:
            self._file.seek(0)
            self.out = np.fromfile(self._file, np.float32, self.shape[0] * self.shape[1]).reshape(self.shape)
            self._file.close()
            self._file = None
        return self.out


class BlockSink:
    """Receives the focused blocks of an image of ``shape`` (module docstring). ``write(first, lines)``
    stores them; ``looks``: the (looks_az, looks_rg) of each multilooked intensity wanted; ``spill_dir``:
    where large ones wait (:class:`LookAccumulator`)."""

    def __init__(self, write: Callable[[int, np.ndarray], None], shape: tuple[int, int],
                 looks: tuple[tuple[int, int], ...] = (), spill_dir: str | None = None):
        self.write = write
        self.sums = np.zeros((shape[0], 4))
        self._have = np.zeros(shape[0], bool)
        self.accumulators = {lk: LookAccumulator(shape, *lk, spill_dir) for lk in dict.fromkeys(looks)}

    def __call__(self, first: int, lines: np.ndarray, sums: np.ndarray | None = None) -> None:
        """One block: ``lines`` from line ``first``; ``sums``: its :func:`line_sums` if already computed
        (by the worker that focused it)."""
        stop = first + lines.shape[0]
        self.write(first, lines)
        self.sums[first:stop] = line_sums(lines) if sums is None else sums
        self._have[first:stop] = True
        for acc in self.accumulators.values():
            acc.add(first, lines)

    def statistics(self, first_line: int, last_line: int) -> dict:
        """Image statistics (:func:`sarcli.focus.quality.image_statistics`) of lines first..last
        (inclusive; the whole image when that range is empty); ``{}`` for an image without signal."""
        a, b = first_line, last_line + 1
        if b <= a:
            a, b = 0, self.sums.shape[0]
        if not self._have[a:b].all():
            raise SarcliError("image statistics: some lines were never received")
        try:
            return statistics_from_sums(self.sums[a:b].sum(axis=0))
        except SarcliError:
            return {}

    def intensity(self, looks_az: int, looks_rg: int) -> np.ndarray:
        return self.accumulators[(looks_az, looks_rg)].result()
