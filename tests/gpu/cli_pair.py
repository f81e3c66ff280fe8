"""The GB-SAR command line on the CPU and on the simulated CUDA device (``NUMBA_ENABLE_CUDASIM=1``, a process
of its own: the simulator must be on before numba is imported), for the tests that compare the two images."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[2]
_RUN = ("import sys\nfrom sarcli.cli.app import app\n"
        "try:\n    app(sys.argv[1:])\nexcept SystemExit as e:\n    sys.exit(e.code)\n")


def sim_env() -> dict[str, str]:
    """The environment of a process on numba's CUDA simulator."""
    return {**os.environ, "NUMBA_ENABLE_CUDASIM": "1", "PYTHONPATH": str(REPO), "SARCLI_NO_PROGRESS": "1"}


def _image(path: Path) -> np.ndarray:
    with h5py.File(path) as f:
        key = "image" if "image" in f else next(k for k in f if isinstance(f[k], h5py.Dataset)
                                                and np.iscomplexobj(f[k]))
        return np.asarray(f[key])


def gbsar_cpu_and_cuda(tmp: Path, algorithm: str, grid: str, timeout: int) -> tuple[object, np.ndarray, np.ndarray,
                                                                                        float]:
    """``gbsar simulate samples/gbsar_indoor.toml``, then ``gbsar focus --algorithm ALGORITHM --grid GRID`` with
    ``--device cpu`` and ``--device cuda`` -> (the scan, the CPU image, the CUDA image, the largest range-profile
    sample over the polarizations: what bounds a normalized pixel)."""
    from sarcli.gbsar.rangecomp import range_compress
    from sarcli.io.scan import read_scan

    scan = tmp / "scan.h5"
    steps = [["gbsar", "simulate", "samples/gbsar_indoor.toml", "-o", str(scan)],
             ["gbsar", "focus", str(scan), "--algorithm", algorithm, "--grid", grid, "-o", str(tmp / "cpu.h5")],
             ["gbsar", "focus", str(scan), "--algorithm", algorithm, "--grid", grid, "-o", str(tmp / "gpu.h5"),
              "--device", "cuda"]]
    for args in steps:
        out = subprocess.run([sys.executable, "-c", _RUN, *args], cwd=REPO, env=sim_env(), capture_output=True,
                             text=True, timeout=timeout)
        assert out.returncode == 0, (args, out.stderr[-2000:])
    s = read_scan(scan)
    largest = max(float(np.abs(range_compress(s, p, "hamming", 4, centred=True).data).max()) for p in s.polarizations)
    cpu, gpu = _image(tmp / "cpu.h5"), _image(tmp / "gpu.h5")
    assert cpu.shape == gpu.shape and np.abs(cpu).max() > 0
    return s, cpu, gpu, largest
