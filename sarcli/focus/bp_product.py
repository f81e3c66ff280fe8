"""Backprojection of a raw product onto the RDA's output grid (``sarcli focus --algorithm backprojection``).

The grid is the one the RD focuser produces (:func:`sarcli.focus.rda.plan_grid`: zero-Doppler times
``t_raw - shift/PRF``, the raw slant ranges), optionally cut to ``lines=(a, b)`` and
``samples=(a, b)``; pixels are placed on the terrain (``--height``/``--dem``) by
:mod:`sarcli.focus.geolocation`, antenna positions come from the product's orbit (Hermite).
The processed Doppler band is centred on the model's centroid per range column (scene-centre time).
Streamed like the RDA: a block of output lines reads the raw lines its apertures need (the RD
overlap either side), range-compresses them and backprojects. Cost O(pixels x lines): meant for
point-target scenes and as the exact reference.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import scipy.fft as sfft

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, SarcliError
from sarcli.focus.backprojection import backproject_grid
from sarcli.focus.geolocation import platform_state, zero_doppler_points
from sarcli.focus.rangecomp import C, compress_lines, range_filter, reference_pulse
from sarcli.focus.rda import OutputGrid, doppler_on_grid, plan_grid
from sarcli.focus.windows import parse_window
from sarcli.gpu.device import check_device
from sarcli.model.raw import RawProduct
from sarcli.model.slc import SLC, DopplerUsed
from sarcli.model.terrain import Terrain


@dataclass(frozen=True)
class BpOptions:
    """Backprojection knobs: windows, bands and replica as the RDA (:class:`sarcli.focus.rda.RdOptions`);
    ``upsample``: range Fourier upsampling before the linear interpolation of each line;
    ``lines``/``samples``: the output window [a, b) of the RD grid (default: all of it);
    ``block_lines``: output lines per block (memory: the block's raw lines are range-compressed at once);
    ``precision``: single (float32 phasor-recurrence kernel) | double (the complex128 reference kernel)
    (:mod:`sarcli.focus.backprojection`); ``device``: cpu, or cuda (the backprojection kernel on the GPU,
    :mod:`sarcli.gpu.bp_cuda`)."""

    range_window: str = "kaiser:2.5"
    range_bandwidth_fraction: float = 1.0
    azimuth_window: str = "kaiser:2.5"
    azimuth_bandwidth_hz: float | None = None
    use_replica: bool = True
    upsample: int = 8
    lines: tuple[int, int] | None = None
    samples: tuple[int, int] | None = None
    block_lines: int = 4096
    workers: int = -1
    precision: Literal["single", "double"] = "single"
    device: Literal["cpu", "cuda"] = "cpu"

    def __post_init__(self) -> None:
        object.__setattr__(self, "device", check_device(self.device))
        parse_window(self.range_window)
        parse_window(self.azimuth_window)
        if not 1 <= self.upsample <= 64:
            raise ConfigError(f"upsample must be 1..64, got {self.upsample}")
        if self.precision not in ("single", "double"):
            raise ConfigError(f"precision must be 'single' or 'double', got {self.precision!r}")
        if self.block_lines < 1:
            raise ConfigError(f"block_lines must be positive, got {self.block_lines}")
        if not (math.isfinite(self.range_bandwidth_fraction) and 0 < self.range_bandwidth_fraction <= 1):
            raise ConfigError(f"range_bandwidth_fraction must be in (0, 1], got {self.range_bandwidth_fraction}")


@dataclass
class BpPlan:
    raw: RawProduct
    options: BpOptions
    terrain: Terrain
    grid: OutputGrid
    window: tuple[int, int, int, int]
    output_shape: tuple[int, int]
    n_blocks: int
    h: np.ndarray
    t_out: np.ndarray
    centre_time: float
    fdc: np.ndarray
    fr: np.ndarray
    v: np.ndarray
    timings: dict[str, float] = field(default_factory=dict)

    def block_rows(self, b: int) -> tuple[int, int]:
        s = b * self.options.block_lines
        return s, min(s + self.options.block_lines, self.output_shape[0])


class Backprojection:
    """Time-domain backprojection as a focuser (:mod:`sarcli.focus.base`)."""

    name = "backprojection"
    Options = BpOptions
    streams = True
    needs_doppler = True

    def plan(self, raw: RawProduct, shape: tuple[int, int], doppler, options: BpOptions, terrain: Terrain) -> BpPlan:
        k = options
        n_lines, nr = shape
        grid = plan_grid(raw, shape, doppler, k.azimuth_bandwidth_hz)
        la, lb = k.lines or (0, n_lines)
        sa, sb = k.samples or (0, nr)
        if not (0 <= la < lb <= n_lines and 0 <= sa < sb <= nr):
            raise ConfigError(f"backprojection window lines={k.lines} samples={k.samples} is outside the image "
                              f"({n_lines} x {nr})")
        ref = reference_pulse(raw.radar, raw.replica if k.use_replica else None)
        h, _ = range_filter(raw.radar, sfft.next_fast_len(nr + ref.size - 1), k.range_window,
                            raw.replica if k.use_replica else None, k.range_bandwidth_fraction)
        tc = float(0.5 * (raw.azimuth_time[0] + raw.azimuth_time[-1]))
        fdc, fr, v, _ = doppler_on_grid(doppler, grid.ranges, tc, grid.wavelength)
        n_out = lb - la
        return BpPlan(raw=raw, options=k, terrain=terrain, grid=grid, window=(la, lb, sa, sb),
                      output_shape=(n_out, sb - sa), n_blocks=int(math.ceil(n_out / k.block_lines)),
                      h=h.astype(np.complex128), t_out=grid.zero_doppler_times(raw.azimuth_time), centre_time=tc,
                      fdc=fdc, fr=fr, v=v)

    def focus_block(self, plan: BpPlan, b: int, read_lines: Callable[[int, int], np.ndarray]) -> np.ndarray:
        raw, g, k = plan.raw, plan.grid, plan.options
        la, _, sa, sb = plan.window
        s, e = plan.block_rows(b)
        nr = g.ranges.size
        a, z = self.raw_span(plan, b)
        t0 = time.perf_counter()
        data = np.asarray(read_lines(a, z))
        if data.shape != (z - a, nr):
            raise SarcliError(f"echo block has shape {data.shape}, expected {(z - a, nr)}")
        gain = raw.line_gain()
        if gain is not None:
            data = data * gain[a:z, None]
        rc = compress_lines(data, plan.h, nr, k.workers)
        plan.timings["range_compression_s"] = plan.timings.get("range_compression_s", 0.0) + time.perf_counter() - t0
        t0 = time.perf_counter()
        tt, rr = np.meshgrid(plan.t_out[la + s:la + e], g.ranges[sa:sb], indexing="ij")
        pix = zero_doppler_points(raw.orbit, raw.epoch_utc, tt, rr, g.wavelength, raw.look_side, plan.terrain)
        pos, vel = platform_state(raw.orbit, raw.epoch_utc, raw.azimuth_time[a:z])
        fdc_pix = np.broadcast_to(plan.fdc[sa:sb][None, :], tt.shape).ravel()
        img = self.image(plan, rc, a, pos, vel, pix, rr, fdc_pix)
        plan.timings["backprojection_s"] = plan.timings.get("backprojection_s", 0.0) + time.perf_counter() - t0
        return img.astype(np.complex64)

    def raw_span(self, plan: BpPlan, b: int) -> tuple[int, int]:
        """Raw lines [a, z) that block ``b`` reads: output line j sees raw lines j + offset - shift +-
        aperture / 2, which the RD overlap covers."""
        la, s, e, pad = plan.window[0], *plan.block_rows(b), plan.grid.pad
        return max(0, la + s - pad), min(plan.raw.azimuth_time.size, la + e + pad)

    def image(self, plan: BpPlan, rc: np.ndarray, a: int, pos: np.ndarray, vel: np.ndarray, pix: np.ndarray,
              rr: np.ndarray, fdc_pix: np.ndarray) -> np.ndarray:
        """The block's image from its range-compressed lines ``rc`` (raw lines from ``a``; positions and
        velocities ``pos``, ``vel``) at the pixels ``pix`` (lines, samples, 3) of ranges ``rr``, centroids
        ``fdc_pix`` (flat)."""
        raw, g, k = plan.raw, plan.grid, plan.options
        return backproject_grid(rc, raw.radar.first_range_m, C / (2 * raw.radar.range_sampling_rate_hz), g.wavelength,
                                pos, vel, pix.reshape(-1, 3), rr.ravel(), fdc_pix, g.ba, k.azimuth_window,
                                k.upsample, k.precision, first_line=a, device=k.device).reshape(rr.shape)

    def finish(self, plan: BpPlan) -> SLC:
        raw, g = plan.raw, plan.grid
        la, lb, sa, sb = plan.window
        n_lines = raw.azimuth_time.size
        first_full, last_full = g.full_lines(n_lines)
        params = {"algorithm": self.name, **to_mapping(plan.options, keep_none=True), "lines": [la, lb],
                  "samples": [sa, sb], "azimuth_bandwidth_hz": g.ba, "prf_hz": g.prf, "shift_lines": g.shift,
                  "overlap_lines": g.pad, "n_blocks": plan.n_blocks, "terrain": plan.terrain.describe()}
        rng = g.ranges[sa:sb].copy()
        return SLC.from_raw(raw, image=np.zeros((0, 0), np.complex64), azimuth_time=plan.t_out[la:lb],
                            slant_range=rng,
                            doppler=DopplerUsed(np.array([plan.centre_time]), rng.copy(), plan.fdc[None, sa:sb],
                                                plan.fr[None, sa:sb], plan.v[None, sa:sb]),
                            algorithm=self.name, azimuth_spacing_m=float(np.median(plan.v)) / g.prf,
                            first_full_line=max(0, first_full - la), last_full_line=min(lb - la - 1, last_full - la),
                            parameters=params, timings=dict(plan.timings))


BACKPROJECTION = Backprojection()


def focus_bp(raw: RawProduct, doppler, channel: int = 0, terrain: Terrain | None = None, **options) -> SLC:
    """Backprojected SLC of one channel of an in-memory raw product on (a window of) the RD grid."""
    from sarcli.focus.base import focus_in_memory

    return focus_in_memory(BACKPROJECTION, raw, doppler, options, terrain, channel)
