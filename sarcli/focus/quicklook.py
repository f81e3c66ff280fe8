"""Quicklook PNG of an SLC: multilooked amplitude in dB, axes in slant range (km) and zero-Doppler time
(UTC clock times, the date in the label).

The time axis is ZERO-DOPPLER time: a target is drawn at its closest approach, not when the beam centre
crossed it. With a squinted beam the two differ by dt = t_beam - t_zd = f_dc / f_r (the Doppler
f = f_r (t - t_zd) equals the centroid at the beam centre): RADARSAT-1 at f_dc = -6560 Hz, f_r = -1781 Hz/s
gives +3.7 s, so a target a scene defines at beam-centre time 0 appears at -3.7 s. The axis label says
so, with the mid-swath value of the product's Doppler.

Lines without their whole synthetic aperture (before ``first_full_line``, after ``last_full_line``)
are shaded and named in the legend; an SLC with no fully focused line says so in its title.

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
    title = title or f"SLC amplitude ({looks})"
    if slc.first_full_line > slc.last_full_line:
        title += "\nno fully focused line: every line lacks part of its aperture"
    write_quicklook(path, np.sqrt(inten), title=title, dynamic_range_db=40.0, extent=extent,
                    xlabel="slant range (km)", ylabel=time_axis_label(slc),
                    decorate=lambda ax: _time_axis_and_focus(ax, slc, extent[3], extent[2]))


def _time_axis_and_focus(ax, slc: SLC, t_top: float, t_bottom: float) -> None:
    """UTC clock times on the time axis (seconds after the epoch underneath: no offset text), and the
    partly focused lines shaded (the fully focused ones are ``first_full_line..last_full_line``)."""
    import datetime as dt

    from matplotlib.patches import Patch
    from matplotlib.ticker import FuncFormatter

    from orbit.timeutil import parse_utc

    epoch = parse_utc(slc.epoch_utc)
    ax.yaxis.set_major_formatter(FuncFormatter(
        lambda v, _pos: (epoch + dt.timedelta(seconds=float(v))).strftime("%H:%M:%S.%f")[:11]))
    t, n = slc.azimuth_time, slc.azimuth_time.size
    first, last = slc.first_full_line, slc.last_full_line
    spans = ([(t_top, t_bottom)] if first > last else
             [(t_top, t[first])] * (first > 0) + [(t[last], t_bottom)] * (last < n - 1))
    for a, b in spans:
        ax.axhspan(a, b, facecolor="orange", alpha=0.25, hatch="//", edgecolor="orange", linewidth=0)
    if spans:
        ax.legend(handles=[Patch(facecolor="orange", alpha=0.25, hatch="//", edgecolor="orange",
                                 label="partly focused lines")], loc="lower right", fontsize=8)


def time_axis_label(slc: SLC) -> str:
    """``zero-Doppler time (UTC, DATE)`` and, for a squinted image, how far the beam-centre time is (module
    docstring), from the Doppler the product was focused with (mid block, mid range)."""
    d = slc.doppler
    base = f"zero-Doppler time (UTC, {slc.epoch_utc[:10]})"
    fdc, fr = np.asarray(d.fdc_hz, np.float64), np.asarray(d.fr_hz_per_s, np.float64)
    if fdc.size == 0 or fr.size == 0:
        return base
    k, j = fdc.shape[0] // 2, fdc.shape[-1] // 2
    f, r = float(fdc[k, j]), float(fr[k, j])
    if not (np.isfinite(f) and np.isfinite(r) and r != 0.0) or abs(f / r) < 0.005:
        return base
    return (f"{base}; beam-centre time = this {f / r:+.2f} s\n"
            f"(squint: fdc {f:.0f} Hz / fr {r:.0f} Hz/s at mid-swath)")
