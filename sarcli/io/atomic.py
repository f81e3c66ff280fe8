"""Atomic file creation: write to a temporary file in the target folder, rename it into place on success.

A crash or an error never leaves a half-written product behind, and the finished file gets the usual
mode (0666 minus the umask; ``tempfile.mkstemp`` alone would leave it 0600, unreadable to others).

Durability (a power cut right after the command returned): the rename is only atomic for the
*name*; unless the file's data reach the disk before the rename does, a journalled file system may
replay the rename over a file whose blocks were never written (a zero-length or garbage product
under the final name). So the finished temporary file is fsync'ed (after its writer closed it:
h5py, rasterio and PNG writers all close before :func:`atomic_path` continues), then renamed, then
its folder is fsync'ed so that the rename itself is on disk when the command reports success.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from sarcli.errors import ProductError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def fsync_path(path: str | os.PathLike) -> None:
    """Flush a file's (or, where the platform allows opening one, a folder's) data and metadata to disk."""
    flags = os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if os.path.isdir(path) else 0)
    try:
        fd = os.open(path, flags)
    except (IsADirectoryError, PermissionError):  # folders cannot be opened on some platforms (Windows)
        return
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = ".tmp") -> Iterator[str]:
    """Yield a temporary file name in ``path``'s folder; on success it is fsync'ed and renamed to ``path``
    and the folder fsync'ed (see the module docstring); on failure it is removed."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ProductError(f"output folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=folder)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        fsync_path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    fsync_path(folder)
