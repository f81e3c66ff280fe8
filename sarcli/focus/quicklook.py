"""Quicklook PNG of an SLC: multilooked amplitude in dB, axes in slant range (km) and zero-Doppler time (s).

Extra looks are added (block averages of intensity) until the picture is at most ``max_pixels`` on its
longer side, so a full scene still gives a light PNG.
"""

from __future__ import annotations

import math

import numpy as np

from sarcli.focus.geocode import multilook
from sarcli.model.slc import SLC


def write_slc_quicklook(path, slc: SLC, looks_az: int = 1, looks_rg: int = 1, max_pixels: int = 1600,
                        title: str | None = None) -> None:
    from sarcli.io.images import write_quicklook

    n, m = slc.image.shape
    f = max(1, math.ceil(max(n / looks_az, m / looks_rg) / max_pixels))
    la, lr = looks_az * f, looks_rg * f
    inten = multilook(slc.image, la, lr)
    t = slc.azimuth_time
    r = slc.slant_range / 1e3
    extent = (r[0], r[min(m, inten.shape[1] * lr) - 1], t[min(n, inten.shape[0] * la) - 1], t[0])
    looks = f"{la} x {lr} looks" + (f": {looks_az} x {looks_rg} asked, x{f} to fit {max_pixels} px" if f > 1 else "")
    write_quicklook(path, np.sqrt(inten), title=title or f"SLC amplitude ({looks})", dynamic_range_db=40.0,
                    extent=extent, xlabel="slant range (km)", ylabel="zero-Doppler time (s)")
