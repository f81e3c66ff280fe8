"""``sarcli focus --algorithm optical``: the AOD/CCD emulation as a focuser (:mod:`sarcli.focus.base`).

The emulated processor works on the whole echo at once (the CCD integrates every line through the
mask), so it does not stream: ``streams = False`` makes the focus workflow load the echo, the plan
runs the emulation and the single block hands its image over. The Doppler model is not used (the
mask follows from the geometry: zero Doppler, rate -2 v^2 / (lam R), as in the analog processor).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC, DopplerUsed
from sarcli.model.terrain import Terrain
from sarcli.optical import limitations as lim
from sarcli.optical.devices import CCD, OpticalSettings
from sarcli.optical.emulator import OpticalImage, emulate


@dataclass(frozen=True)
class OpticalOptions:
    """Knobs of the emulated processor (:class:`sarcli.optical.devices.OpticalSettings`): ``limitations``
    ('all', 'none' or a comma list, :mod:`sarcli.optical.limitations`), the CCD's ``adc_bits``, the
    CCD centre range (m, default mid-swath) and the optical settings."""

    limitations: str = "all"
    centre_range_m: float | None = None
    adc_bits: int = 8
    reference_offset_hz: float | None = None
    reference_ratio: float = 1.0
    magnification: str = "carrier"
    remove_bias: bool = False
    light_pulse_s: float = 20e-9
    seed: int = 0

    def __post_init__(self) -> None:
        lim.parse(self.limitations)
        if not 1 <= self.adc_bits <= 24:
            raise ConfigError(f"adc_bits must be 1..24, got {self.adc_bits}")
        if self.centre_range_m is not None and not (math.isfinite(self.centre_range_m) and self.centre_range_m > 0):
            raise ConfigError(f"centre_range_m must be a positive number of metres, got {self.centre_range_m}")
        self.settings()

    def settings(self) -> OpticalSettings:
        return OpticalSettings(ccd=CCD(adc_bits=self.adc_bits), reference_offset_hz=self.reference_offset_hz,
                               reference_ratio=self.reference_ratio, magnification=self.magnification,
                               remove_bias=self.remove_bias, light_pulse_s=self.light_pulse_s, seed=self.seed)


@dataclass
class OpticalPlan:
    raw: RawProduct
    options: OpticalOptions
    result: OpticalImage
    seconds: float
    output_shape: tuple[int, int]
    n_blocks: int = 1

    def block_rows(self, b: int) -> tuple[int, int]:
        return 0, self.output_shape[0]


class OpticalFocuser:
    """The emulated AOD/CCD processor as a focuser."""

    name = "optical"
    Options = OpticalOptions
    streams = False
    needs_doppler = False

    def plan(self, raw: RawProduct, shape: tuple[int, int], doppler, options: OpticalOptions,
             terrain: Terrain) -> OpticalPlan:
        t0 = time.perf_counter()
        out = emulate(raw, lim.parse(options.limitations), options.settings(), centre_range_m=options.centre_range_m)
        return OpticalPlan(raw, options, out, time.perf_counter() - t0, tuple(out.image.shape))  # type: ignore[arg-type]

    def focus_block(self, plan: OpticalPlan, b: int, read_lines: Callable[[int, int], np.ndarray]) -> np.ndarray:
        return plan.result.image

    def finish(self, plan: OpticalPlan) -> SLC:
        out, raw = plan.result, plan.raw
        v = out.report["platform_speed_mps"]
        fr = -2.0 * v * v / (raw.radar.wavelength_m * out.slant_range)
        used = DopplerUsed(block_time=np.array([float(np.mean(out.azimuth_time))]), range_m=out.slant_range,
                           fdc_hz=np.zeros((1, out.slant_range.size)), fr_hz_per_s=fr[None, :],
                           velocity_mps=np.full((1, out.slant_range.size), v))
        params = {"algorithm": self.name, **to_mapping(plan.options, keep_none=True),
                  "limitations_used": sorted(out.limitations),
                  **{k: (v_ if not isinstance(v_, float) or np.isfinite(v_) else None)
                     for k, v_ in out.design.__dict__.items()}, **out.report}
        rows = out.report["rows_integrated"]
        return SLC.from_raw(raw, image=np.zeros((0, 0), np.complex64), azimuth_time=out.azimuth_time,
                            slant_range=out.slant_range, doppler=used, algorithm=self.name,
                            azimuth_spacing_m=v / raw.radar.prf_hz, first_full_line=rows // 2,
                            last_full_line=raw.azimuth_time.size - 1 - rows // 2, parameters=params,
                            timings={"optical_emulation_s": plan.seconds})


OPTICAL = OpticalFocuser()
