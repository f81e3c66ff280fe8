"""Which device a focuser runs on: ``cpu`` (default) or ``cuda``, and what ``cuda`` means here.

The choice comes from the focuser option ``device`` (``--device``, default from the environment variable
``SARCLI_DEVICE``, else ``cpu``). ``cuda`` is accepted only where it can run, checked before any work:

- with ``NUMBA_ENABLE_CUDASIM=1`` in the environment, numba's CUDA simulator runs the numba.cuda kernels on the
  CPU (slowly: tiny inputs only) and the array namespace is numpy: the GPU code path as CI tests it;
- otherwise CuPy must import, see at least one CUDA device, and numba's CUDA target must be available.

Anything missing is one line (a :class:`sarcli.errors.ConfigError`: exit 2 at the command line) that says what
is missing and how to get it (``pip install 'sarcli[gpu]'``). Nothing GPU-related is imported for ``cpu``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from sarcli.errors import ConfigError

DEVICES = ("cpu", "cuda")
INSTALL_HINT = "install the GPU extra: pip install 'sarcli[gpu]' (CuPy and numba-cuda for CUDA 13)"


def parse_device(name: Any) -> str:
    """``"cpu"`` or ``"cuda"`` (case and blanks ignored); one line for anything else."""
    d = str(name).strip().lower()
    if d not in DEVICES:
        raise ConfigError(f"unknown device {name!r}: use cpu or cuda")
    return d


def default_device() -> str:
    """The device when none is given: ``SARCLI_DEVICE`` (cpu|cuda), else ``cpu``."""
    value = os.environ.get("SARCLI_DEVICE", "").strip()
    return parse_device(value) if value else "cpu"


def simulated() -> bool:
    """True when numba's CUDA simulator is switched on (``NUMBA_ENABLE_CUDASIM=1``)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0").strip() not in ("", "0")


@dataclass(frozen=True)
class Cuda:
    """What ``cuda`` is on this machine: ``xp`` the array namespace (cupy, or numpy under the simulator),
    ``simulator`` whether the numba.cuda kernels run in numba's simulator, ``name`` the device's name."""

    xp: ModuleType
    simulator: bool
    name: str

    def asarray(self, a: Any, dtype: Any = None) -> Any:
        """``a`` on the device: a copy to the card with CuPy; under the simulator a writable host copy (the
        simulator copies every kernel argument back, which a read-only view would refuse)."""
        if self.simulator:
            return np.array(a, dtype=dtype, copy=True)
        return self.xp.asarray(a, dtype=dtype)

    def to_host(self, a: Any) -> np.ndarray:
        """A device array back in host memory (numpy)."""
        return a.get() if hasattr(a, "get") else np.asarray(a)


def require_cuda() -> Cuda:
    """The CUDA device, or one line saying what is missing (module docstring)."""
    if simulated():
        return Cuda(xp=np, simulator=True, name="numba CUDA simulator (NUMBA_ENABLE_CUDASIM=1)")
    try:
        import cupy
    except ImportError:
        raise ConfigError(f"--device cuda needs CuPy, which is not installed: {INSTALL_HINT}") from None
    try:
        n = int(cupy.cuda.runtime.getDeviceCount())
    except Exception as exc:  # CUDA driver missing or broken: CuPy raises its own runtime errors
        raise ConfigError(f"--device cuda: no usable CUDA driver ({str(exc).splitlines()[0]}); use --device cpu"
                          ) from None
    if n < 1:
        raise ConfigError("--device cuda: no CUDA GPU is visible on this machine; use --device cpu")
    try:
        from numba import cuda
    except ImportError:
        raise ConfigError(f"--device cuda needs numba's CUDA target: {INSTALL_HINT}") from None
    if not cuda.is_available():
        raise ConfigError(f"--device cuda: numba sees no CUDA GPU ({INSTALL_HINT})")
    name = cupy.cuda.runtime.getDeviceProperties(0)["name"]
    return Cuda(xp=cupy, simulator=False, name=name.decode() if isinstance(name, bytes) else str(name))


def check_device(value: Any) -> str:
    """A focuser option's device, normalised (``"cpu"``/``"cuda"``); for ``cuda`` also that it can run here
    (:func:`require_cuda`), so that a missing GPU is one line before any work."""
    d = parse_device(value)
    if d == "cuda":
        require_cuda()
    return d


def options_with_device(options_type: type, options: dict[str, Any], device: str | None) -> dict[str, Any]:
    """The focuser options ``options`` with ``device`` set (``None``: as they are). A focuser whose Options
    have no ``device`` field runs on the CPU only: asking it for cuda is one line."""
    if device is None:
        return options
    d = parse_device(device)
    fields = getattr(options_type, "__dataclass_fields__", {})
    if "device" in fields:
        return {**options, "device": d}
    if d == "cuda":
        raise ConfigError(f"this focuser has no CUDA path ({options_type.__name__} has no device option): use "
                          "--device cpu, or --algorithm rd, csa, omegak, backprojection or ffbp")
    return options
