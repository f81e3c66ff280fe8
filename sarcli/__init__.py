"""sarcli: reproducible SAR processing from raw echoes and GB-SAR scans to products.

Compiled numba kernels are cached per user in ``$XDG_CACHE_HOME/sarcli/numba`` (default
``~/.cache/sarcli/numba``) unless ``NUMBA_CACHE_DIR`` is set: one place, writable whatever the install,
filled by ``make install`` so that a fresh install's first command loads its kernels instead of
compiling them (docs/validation.md, start-up).
"""

import os

__version__ = "0.1.0"


def numba_cache_dir() -> str:
    """The folder numba caches sarcli's kernels in: ``NUMBA_CACHE_DIR`` if set, else the per-user default."""
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given:
        return given
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = xdg if os.path.isabs(xdg) else os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "sarcli", "numba")


os.environ["NUMBA_CACHE_DIR"] = numba_cache_dir()  # before any sarcli module imports numba
