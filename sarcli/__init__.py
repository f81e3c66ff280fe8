"""sarcli: reproducible SAR processing from raw echoes and GB-SAR scans to products."""

import os as _os

__version__ = "0.1.0"

# Compiled numba kernels are cached per user (the sources may be read-only), so that every process --
# a command, a Dask worker -- reuses them: $XDG_CACHE_HOME/sarcli/numba (~/.cache/...) unless
# NUMBA_CACHE_DIR is set. Set here, before any sarcli module imports numba.
if not _os.environ.get("NUMBA_CACHE_DIR"):
    _os.environ["NUMBA_CACHE_DIR"] = _os.path.join(
        _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache"), "sarcli", "numba")
