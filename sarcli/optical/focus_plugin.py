"""``sarcli focus --algorithm optical``: the AOD/CCD emulation as a focusing algorithm (registry plug-in)."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from sarcli.errors import SarcliError
from sarcli.focus.algorithms import register
from sarcli.focus.rda import RdKnobs
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC, DopplerUsed
from sarcli.optical import limitations as lim
from sarcli.optical.devices import CCD, OpticalSettings
from sarcli.optical.emulator import emulate

_SETTINGS = {"reference_offset_hz", "reference_ratio", "magnification", "remove_bias", "light_pulse_s", "seed"}


def focus_optical(raw: RawProduct, doppler=None, channel: int = 0, limitations="all", centre_range_m=None,
                  adc_bits: int = 8, **knobs) -> SLC:
    """Emulated optical image as an SLC. ``doppler`` is not used: the mask follows from the geometry
    (zero Doppler, rate -2 v^2 / (lam R)), as in the analog processor. The Range-Doppler knobs that
    ``sarcli focus`` passes to every algorithm (windows, RCMC, ...) do not apply and are recorded as
    unused; any other unknown name is an error."""
    rd_knobs = {f.name for f in dataclasses.fields(RdKnobs)}
    unused = sorted(set(knobs) & rd_knobs)
    knobs = {k: v for k, v in knobs.items() if k not in rd_knobs}
    unknown = sorted(set(knobs) - _SETTINGS)
    if unknown:
        raise SarcliError(f"unknown optical option(s) {', '.join(unknown)}; known: "
                          f"limitations, centre_range_m, adc_bits, {', '.join(sorted(_SETTINGS))}")
    settings = OpticalSettings(ccd=CCD(adc_bits=int(adc_bits)), **knobs)
    t0 = time.perf_counter()
    out = emulate(raw, lim.parse(limitations) if not isinstance(limitations, frozenset) else limitations,
                  settings, channel=channel, centre_range_m=centre_range_m)
    seconds = time.perf_counter() - t0
    v = out.report["platform_speed_mps"]
    lam = raw.radar.wavelength_m
    fr = -2.0 * v * v / (lam * out.slant_range)
    used = DopplerUsed(block_time=np.array([float(np.mean(out.azimuth_time))]), range_m=out.slant_range,
                       fdc_hz=np.zeros((1, out.slant_range.size)), fr_hz_per_s=fr[None, :],
                       velocity_mps=np.full((1, out.slant_range.size), v))
    params = {"limitations": sorted(out.limitations), "adc_bits": int(adc_bits), "unused_rd_knobs": unused,
              **{k: (v_ if not isinstance(v_, float) or np.isfinite(v_) else None)
                 for k, v_ in out.design.__dict__.items()},
              **{k: getattr(settings, k) for k in sorted(_SETTINGS)}, **out.report}
    rows = out.report["rows_integrated"]
    return SLC(image=out.image, azimuth_time=out.azimuth_time, slant_range=out.slant_range,
               epoch_utc=raw.epoch_utc, radar=raw.radar, doppler=used, look_side=raw.look_side,
               source=raw.source, algorithm="optical", azimuth_spacing_m=v / raw.radar.prf_hz,
               first_full_line=rows // 2, last_full_line=raw.echo.shape[0] - 1 - rows // 2,
               parameters=params, timings={"optical_emulation_s": seconds}, orbit=raw.orbit,
               attitude=raw.attitude, truth=raw.truth)


register("optical", focus_optical)
