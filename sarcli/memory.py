"""This process's peak memory, as reports state it; the memory available, checked before a large allocation."""

from __future__ import annotations

import os
import resource
import sys

from sarcli.errors import ProductError


def peak_rss_bytes() -> int:
    """Peak resident set size of this process so far (bytes): ``VmHWM`` of ``/proc/self/status`` where
    there is one (Linux), the high-water mark of this program's own memory; elsewhere getrusage's
    ``ru_maxrss`` (KiB; bytes on macOS). Not ru_maxrss on Linux: it keeps the maximum of the program
    that exec'd this one, so a command started from a large process (a notebook, a benchmark) would
    report its parent's peak."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * (1 if sys.platform == "darwin" else 1024)


def fits_in_memory(what: str, n_bytes: float, fraction: float = 0.8) -> None:
    """Refuse (one line) to allocate ``n_bytes`` for ``what`` when they exceed ``fraction`` of the memory
    available now (Linux ``MemAvailable``; elsewhere the physical memory)."""
    avail = available_memory_bytes()
    if not n_bytes <= fraction * avail:
        raise ProductError(f"{what} needs {n_bytes / 2**30:.4g} GiB of memory, more than the "
                           f"{fraction * avail / 2**30:.4g} GiB this machine has available: refusing (smaller sizes?)")


def available_memory_bytes() -> float:
    """The memory available for new allocations now, bytes (``MemAvailable`` of /proc/meminfo, else the
    physical memory from sysconf)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return float("inf")
