"""Versions of sarcli and of the libraries its results depend on (``sarcli --version``).

Python packages are looked up in their installed metadata (nothing imported); the GDAL and PROJ C
libraries are asked through rasterio and pyproj (the wheels bundle their own builds, so the system's
``gdalinfo --version`` may differ).
"""

from __future__ import annotations

from importlib import metadata

PACKAGES = ("numpy", "numba", "scipy", "h5py", "rasterio", "pyproj", "snaphu", "sarkit")


def versions() -> dict[str, str]:
    """{name: version}: sarcli, Python, the packages of :data:`PACKAGES` ("not installed" when
    absent), GDAL and PROJ."""
    import platform

    from sarcli import __version__

    out = {"sarcli": __version__, "python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    try:
        import rasterio

        out["GDAL"] = rasterio.__gdal_version__
    except ImportError:
        out["GDAL"] = "not installed"
    try:
        import pyproj

        out["PROJ"] = pyproj.proj_version_str
    except ImportError:
        out["PROJ"] = "not installed"
    return out


def version_text() -> str:
    """``sarcli 0.1.0`` then one ``  name version`` line per library."""
    v = versions()
    return "\n".join([f"sarcli {v.pop('sarcli')}", *(f"  {k} {val}" for k, val in v.items())])
