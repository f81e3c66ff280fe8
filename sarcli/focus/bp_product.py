"""Backprojection of a whole raw product onto the RDA's output grid (``sarcli focus --algorithm backprojection``).

The grid is the one :func:`sarcli.focus.rda.focus_rd` would produce (zero-Doppler times
``t_raw - shift/PRF``, the raw slant ranges), optionally cut to ``lines=(a, b)`` and
``samples=(a, b)``; pixels are placed on the ground (height ``reference_height_m`` of the truth, else
0) by :mod:`sarcli.focus.geolocation`, antenna positions come from the product's orbit (Hermite).
The processed Doppler band is centred on the model's centroid per range column (scene-centre time).
Cost O(pixels x lines): meant for point-target scenes and as the exact reference.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.fft as sfft

from sarcli.errors import SarcliError
from sarcli.focus.backprojection import backproject_grid
from sarcli.focus.geolocation import platform_state, zero_doppler_points
from sarcli.focus.rangecomp import C, compress_lines, range_filter, reference_pulse
from sarcli.focus.rda import _plan, doppler_on_grid, make_knobs
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC, DopplerUsed


def focus_bp(raw: RawProduct, doppler, channel: int = 0, lines: tuple[int, int] | None = None,
             samples: tuple[int, int] | None = None, upsample: int = 8, **knobs) -> SLC:
    """Backprojected SLC on (a window of) the RD grid; knobs as :func:`sarcli.focus.rda.focus_rd`."""
    t_start = time.perf_counter()
    k = make_knobs(**knobs)
    echo = raw.channel(channel)
    n_lines, nr = echo.shape
    p = _plan(raw, (n_lines, nr), doppler, k)
    la, lb = lines or (0, n_lines)
    sa, sb = samples or (0, nr)
    if not (0 <= la < lb <= n_lines and 0 <= sa < sb <= nr):
        raise SarcliError(f"backprojection window lines={lines} samples={samples} is outside the image")
    radar = raw.radar
    t_out = raw.azimuth_time[0] + (np.arange(n_lines) - p.shift) / p.prf
    ref = reference_pulse(radar, raw.replica if k.use_replica else None)
    h, _ = range_filter(radar, sfft.next_fast_len(nr + ref.size - 1), k.range_window,
                        raw.replica if k.use_replica else None, k.range_bandwidth_fraction)
    gain = raw.line_gain()
    data = echo if gain is None else echo * gain[:, None]
    rc = compress_lines(data, h.astype(np.complex128), nr, k.workers)
    t_rc = time.perf_counter() - t_start
    tt, rr = np.meshgrid(t_out[la:lb], p.ranges[sa:sb], indexing="ij")
    height = 0.0
    if raw.truth is not None and "reference_height_m" in raw.truth:
        height = float(np.asarray(raw.truth["reference_height_m"]))
    pix = zero_doppler_points(raw.orbit, raw.epoch_utc, tt, rr, p.wavelength, raw.look_side, height)
    pos, vel = platform_state(raw.orbit, raw.epoch_utc, raw.azimuth_time)
    tc = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
    fdc, fr, v, _ = doppler_on_grid(doppler, p.ranges, tc, p.wavelength)
    fdc_pix = np.broadcast_to(fdc[sa:sb][None, :], tt.shape).ravel()
    t0 = time.perf_counter()
    img = backproject_grid(rc, radar.first_range_m, C / (2 * radar.range_sampling_rate_hz), p.wavelength,
                           pos, vel, pix.reshape(-1, 3), rr.ravel(), fdc_pix, p.ba, k.azimuth_window,
                           upsample).reshape(tt.shape)
    timings = {"range_compression_s": t_rc, "backprojection_s": time.perf_counter() - t0,
               "total_s": time.perf_counter() - t_start}
    params = {"algorithm": "backprojection", "upsample": upsample, "lines": [la, lb], "samples": [sa, sb],
              "azimuth_bandwidth_hz": p.ba, "prf_hz": p.prf, "shift_lines": p.shift,
              "range_window": k.range_window, "azimuth_window": k.azimuth_window,
              "range_bandwidth_fraction": k.range_bandwidth_fraction, "use_replica": k.use_replica}
    first_full = int(np.ceil(0.5 * p.full_aperture))
    return SLC(
        image=img.astype(np.complex64), azimuth_time=t_out[la:lb], slant_range=p.ranges[sa:sb].copy(),
        epoch_utc=raw.epoch_utc, radar=radar,
        doppler=DopplerUsed(np.array([tc]), p.ranges[sa:sb].copy(), fdc[None, sa:sb], fr[None, sa:sb],
                            v[None, sa:sb]),
        look_side=raw.look_side, source=raw.source, algorithm="backprojection",
        azimuth_spacing_m=float(np.median(v)) / p.prf, first_full_line=max(0, first_full - la),
        last_full_line=min(lb - la - 1, n_lines - 1 - first_full - la), parameters=params, timings=timings,
        orbit=raw.orbit, attitude=raw.attitude, truth=raw.truth,
    )
