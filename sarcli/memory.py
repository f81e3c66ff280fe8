"""This process's peak memory, as reports state it."""

from __future__ import annotations

import resource
import sys


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
