"""Fixtures of the Sentinel-1 tests: the three real packets of ``../shared/data/s1_l0_packets`` and
their reference decodes (``.npz``), read without importing the package that wrote them."""

from __future__ import annotations

import io
import pickle
import struct
import warnings
import zipfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

PACKETS = ("000000-noise", "000008-txcal", "000408-echo")


class _Record(SimpleNamespace):
    def __setstate__(self, state):
        self.__dict__.update(state)


class _RefUnpickler(pickle.Unpickler):
    """The headers in the ``.npz`` are pickled objects of the writer's classes (descriptors and
    enums): map them to plain records and ints, and refuse anything else."""

    def find_class(self, module, name):
        if module in ("numpy._core.multiarray", "numpy.core.multiarray") and name == "_reconstruct":
            return np._core.multiarray._reconstruct
        if module == "numpy" and name in ("ndarray", "dtype"):
            return getattr(np, name)
        if module.endswith(".descriptors"):
            return type(name, (_Record,), {})
        if module.endswith(".enums"):
            return int
        raise pickle.UnpicklingError(f"refusing {module}.{name} in a reference file")


def load_reference(path: Path) -> dict:
    """Arrays of the ``.npz`` as arrays, pickled headers as nested records (SimpleNamespace)."""
    out = {}
    with zipfile.ZipFile(path) as z:
        for member in z.namelist():
            raw = z.read(member)
            header_len = struct.unpack("<H", raw[8:10])[0]
            if b"'|O'" in raw[10:10 + header_len]:
                obj = _RefUnpickler(io.BytesIO(raw[10 + header_len:])).load()
                out[member[:-4]] = obj[()] if isinstance(obj, np.ndarray) else obj
            else:
                with warnings.catch_warnings():
                    out[member[:-4]] = np.load(io.BytesIO(raw), allow_pickle=False)
    return out


@pytest.fixture(scope="session")
def s1_packets(shared_data) -> Path:
    d = shared_data / "s1_l0_packets"
    if not all((d / f"{n}.dat").is_file() and (d / f"{n}.npz").is_file() for n in PACKETS):
        pytest.skip("../shared/data/s1_l0_packets: the real Sentinel-1 packets are not available "
                    "(bit-exact decoder tests NOT run)")
    return d
