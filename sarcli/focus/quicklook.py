"""Quicklook PNG of an SLC: multilooked amplitude in dB, axes in slant range (km) and zero-Doppler time (s).

Extra looks are added (block averages of intensity) until the picture is at most ``max_pixels`` on its
longer side, so a full scene still gives a light PNG.
"""

from __future__ import annotations

import math

import numpy as np

from sarcli.focus.geocode import multilook
from sarcli.model.slc import SLC


def quicklook_looks(shape: tuple[int, int], looks_az: int = 1, looks_rg: int = 1,
                    max_pixels: int = 1600) -> tuple[int, int, int]:
    """(looks in azimuth, looks in range, extra factor) of the quicklook of an image of ``shape``: the
    looks asked for times the factor that fits ``max_pixels`` on the longer side."""
    n, m = shape
    f = max(1, math.ceil(max(n / looks_az, m / looks_rg) / max_pixels))
    return looks_az * f, looks_rg * f, f


def write_slc_quicklook(path, slc: SLC, looks_az: int = 1, looks_rg: int = 1, max_pixels: int = 1600,
                        title: str | None = None, intensity: np.ndarray | None = None) -> None:
    """``intensity``: ``multilook(slc.image, *quicklook_looks(...)[:2])`` when the caller has it (then
    ``slc`` needs no image)."""
    from sarcli.io.images import write_quicklook

    n, m = slc.azimuth_time.size, slc.slant_range.size
    la, lr, f = quicklook_looks((n, m), looks_az, looks_rg, max_pixels)
    inten = multilook(slc.image, la, lr) if intensity is None else intensity
    t = slc.azimuth_time
    r = slc.slant_range / 1e3
    extent = (r[0], r[min(m, inten.shape[1] * lr) - 1], t[min(n, inten.shape[0] * la) - 1], t[0])
    looks = f"{la} x {lr} looks" + (f": {looks_az} x {looks_rg} asked, x{f} to fit {max_pixels} px" if f > 1 else "")
    write_quicklook(path, np.sqrt(inten), title=title or f"SLC amplitude ({looks})", dynamic_range_db=40.0,
                    extent=extent, xlabel="slant range (km)", ylabel="zero-Doppler time (s)")
