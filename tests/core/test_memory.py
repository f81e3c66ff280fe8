"""The peak memory reports state: the process's own, not the parent's that started it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

_CHILD = "from sarcli.memory import peak_rss_bytes; print(peak_rss_bytes())"
_PARENT = f"""
import resource, subprocess, sys
import numpy as np
big = np.ones(256 << 20, np.uint8)  # 256 MiB, touched
out = subprocess.run([sys.executable, "-c", {_CHILD!r}], capture_output=True, text=True, check=True).stdout
child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
print(out.strip(), child)
"""


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="VmHWM needs Linux /proc (ru_maxrss elsewhere)")
def test_a_child_of_a_large_process_reports_its_own_peak():
    got, rusage_child = (int(v) for v in subprocess.run([sys.executable, "-c", _PARENT], capture_output=True,
                                                        text=True, check=True).stdout.split())
    # getrusage keeps the exec'ing parent's peak (>= 256 MiB); the child's own image is numpy-free
    assert rusage_child >= 256 << 20
    assert got < 128 << 20
