"""Atomic file creation: write to a temporary file in the target folder, rename it into place on success.

A crash or an error never leaves a half-written product behind, and the finished file gets the usual
mode (0666 minus the umask; ``tempfile.mkstemp`` alone would leave it 0600, unreadable to others).

Durability (a power cut right after the command returned): the rename is only atomic for the
*name*; unless the file's data reach the disk before the rename does, a journalled file system may
replay the rename over a file whose blocks were never written (a zero-length or garbage product
under the final name). So the finished temporary file is fsync'ed (after its writer closed it:
h5py, rasterio and PNG writers all close before :func:`atomic_path` continues), then renamed, then
its folder is fsync'ed so that the rename itself is on disk when the command reports success.

A step that writes several files (an SLC, its GeoTIFFs and quicklook) makes them appear together:
inside :func:`all_or_nothing` the renames wait for the block to complete, and an error removes every
temporary file, so a failure in the last product never leaves the first one behind. Files written in
such a block are not at their names yet: :func:`readable_name` says where to read them.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from sarcli.errors import ProductError

#: the renames waiting for the innermost :func:`all_or_nothing` block (None: rename at once)
_PENDING: contextvars.ContextVar[list[tuple[str, Path]] | None] = contextvars.ContextVar("sarcli_pending",
                                                                                         default=None)


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
    if path.is_dir():  # the rename would fail after all the work, leaving the temporary file
        raise ProductError(f"output {path} is an existing folder: give a file name")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=folder)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        fsync_path(tmp)
        pending = _PENDING.get()
        if pending is not None:
            pending.append((tmp, path))
            return
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    fsync_path(folder)


def readable_name(path: str | os.PathLike) -> Path:
    """Where the bytes of ``path`` are now: the temporary file of a product finished inside the current
    :func:`all_or_nothing` block (not renamed yet), else ``path`` itself. For the provenance of a file
    made from another one of the same block (the GeoTIFF's hash of its SLC)."""
    path = Path(path)
    for tmp, target in reversed(_PENDING.get() or []):
        if target == path:
            return Path(tmp)
    return path


@contextlib.contextmanager
def all_or_nothing() -> Iterator[None]:
    """Every file :func:`atomic_path` finishes inside the block is renamed into place when the block
    completes (then the folders are fsync'ed), or, if the block fails, none is: their temporary files
    are removed (module docstring). Nested blocks join the outer one."""
    if _PENDING.get() is not None:
        yield
        return
    pending: list[tuple[str, Path]] = []
    token = _PENDING.set(pending)
    try:
        yield
    except BaseException:
        for tmp, _ in pending:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        raise
    finally:
        _PENDING.reset(token)
    for tmp, path in pending:
        os.replace(tmp, path)
    for folder in {path.parent if str(path.parent) else Path(".") for _, path in pending}:
        fsync_path(folder)
