"""Fast factorized backprojection of a raw product onto the RDA's grid (``sarcli focus --algorithm ffbp``).

The grid, the products, the streaming and the inputs are those of the ``backprojection`` focuser
(:mod:`sarcli.focus.bp_product`: zero-Doppler lines x raw slant ranges, optionally cut to ``lines`` /
``samples``, pixels on the terrain, antenna positions from the orbit, any track: orbit or linear);
the image comes from :func:`sarcli.focus.ffbp.ffbp` [UlaHelSte2003] instead of the exact kernel
(derivation, knobs, error model there). BP's azimuth window over the processed Doppler band,
``W((f_n(X) - fdc(X)) / Ba)``, is FFBP's aperture window of mode 1: applied at the last stage per top
subaperture (``aperture_split`` of them per synthetic aperture ``Ba / |fr|``), as the mean of W over its
pulses at the pixel (exact at a scatterer's peak; a sidelobe-level term elsewhere that falls as
``aperture_split`` rises). Block invariance: subapertures are aligned to the raw line index and a
block reads whole top subapertures (its raw span widened to their edges), and the polar samples lie on
one plane per plan (fitted to the whole output window), so a pixel's value does not depend on its
block (to rounding: 1e-5 of the peak, tests/focus/test_ffbp.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from sarcli.errors import ConfigError
from sarcli.focus.backprojection import upsample_range
from sarcli.focus.bp_product import Backprojection, BpOptions, BpPlan
from sarcli.focus.ffbp import ApertureWindow, FfbpKnobs, ffbp, fit_plane, top_length
from sarcli.focus.geolocation import zero_doppler_points
from sarcli.focus.rangecomp import C
from sarcli.focus.windows import window_table


@dataclass(frozen=True)
class FfbpOptions(BpOptions):
    """Backprojection's knobs (:class:`sarcli.focus.bp_product.BpOptions`: windows, bands, replica,
    ``upsample``, ``lines``/``samples``, ``block_lines``, ``workers``) and FFBP's
    (:class:`sarcli.focus.ffbp.FfbpKnobs`): ``base`` subapertures merged per stage, ``oversample`` the
    angular oversampling, ``order`` / ``range_order`` interpolation taps (2 linear, 4-8 Knab sinc),
    ``range_oversample`` of the polar grids' range spacing, ``aperture_split`` top subapertures per
    synthetic aperture. BP's ``precision`` keeps its default (single): FFBP has its own arithmetic; ``device``
    cuda runs its stages on the GPU (:mod:`sarcli.gpu.ffbp_cuda`, the same arithmetic). Defaults: GOTCHA's
    accuracy bar (peaks within 0.1 pixel, PSLR within 0.5 dB of
    BP; docs/focusing.md)."""

    base: int = FfbpKnobs.base
    oversample: float = FfbpKnobs.oversample
    order: int = FfbpKnobs.order
    range_order: int = FfbpKnobs.range_order
    range_oversample: float = FfbpKnobs.range_oversample
    aperture_split: int = FfbpKnobs.aperture_split

    def __post_init__(self) -> None:
        super().__post_init__()
        self.knobs()
        if self.precision != "single":
            raise ConfigError("ffbp has one precision (float64 geometry and phase, complex128 sums): drop "
                              "--double / precision")

    def knobs(self) -> FfbpKnobs:
        return FfbpKnobs(**{f.name: getattr(self, f.name) for f in fields(FfbpKnobs)})


@dataclass
class FfbpPlan(BpPlan):
    """BP's plan and FFBP's: the synthetic aperture in lines, the top subaperture length (lines) and the
    plane of the polar samples."""

    aperture_lines: float = 0.0
    top: int = 1
    plane: tuple[np.ndarray, np.ndarray] = ()
    stages: dict = field(default_factory=dict)


class Ffbp(Backprojection):
    """FFBP as a focuser (:mod:`sarcli.focus.base`): BP's plan, products and streaming, FFBP's image."""

    name = "ffbp"
    Options = FfbpOptions

    def plan(self, raw, shape, doppler, options: FfbpOptions, terrain) -> FfbpPlan:
        bp = super().plan(raw, shape, doppler, options, terrain)
        sa, sb = bp.window[2:]
        # the synthetic aperture in lines (the shortest: largest |fr|) sets the top subaperture length
        aperture = bp.grid.ba / float(np.max(np.abs(bp.fr[sa:sb]))) * bp.grid.prf
        if not (math.isfinite(aperture) and aperture > 0):
            raise ConfigError(f"ffbp needs a finite synthetic aperture; the Doppler model gives {aperture:g} lines")
        stub = ApertureWindow(mode=1, par=np.zeros(3), table=np.ones(2), aperture_pulses=aperture)
        return FfbpPlan(**{f.name: getattr(bp, f.name) for f in fields(BpPlan)}, aperture_lines=aperture,
                        top=top_length(options.knobs(), 0, stub), plane=_window_plane(bp))

    def raw_span(self, plan: FfbpPlan, b: int) -> tuple[int, int]:
        """BP's span widened to whole top subapertures (aligned to the raw line index)."""
        a, z = super().raw_span(plan, b)
        return (a // plan.top) * plan.top, min(plan.raw.azimuth_time.size, -(-z // plan.top) * plan.top)

    def image(self, plan: FfbpPlan, rc, a, pos, vel, pix, rr, fdc_pix) -> np.ndarray:
        g, k, radar = plan.grid, plan.options, plan.raw.radar
        up = upsample_range(np.asarray(rc), k.upsample, k.workers) if k.upsample > 1 else np.asarray(rc)
        band = min(abs(radar.chirp_rate_hz_per_s) * radar.pulse_length_s * k.range_bandwidth_fraction,
                   radar.range_sampling_rate_hz)
        win = ApertureWindow(mode=1, par=np.array([g.wavelength, g.ba, 0.0]), table=window_table(k.azimuth_window),
                             aperture_pulses=plan.aperture_lines, per_pixel=np.asarray(fdc_pix).reshape(rr.shape),
                             vel=vel)
        stats: dict = {}
        img, _ = ffbp(up, radar.first_range_m, C / (2 * radar.range_sampling_rate_hz * k.upsample), C / (2 * band),
                      g.wavelength, C / (radar.carrier_frequency_hz + band / 2), pos, np.zeros(pos.shape[0]),
                      np.ones(pos.shape[0]), pix, rr, k.knobs(), win, first_index=a, plane=plan.plane, stats=stats,
                      device=k.device)
        plan.stages = {"merge_stages": stats["merge_stages"], "top_lines": stats["top_pulses"]}
        return img

    def finish(self, plan: FfbpPlan):
        slc = super().finish(plan)
        slc.parameters.update({"ffbp_aperture_lines": plan.aperture_lines, **{f"ffbp_{k}": v
                                                                              for k, v in plan.stages.items()}})
        return slc


def _window_plane(plan: BpPlan) -> tuple[np.ndarray, np.ndarray]:
    """The plane of the polar samples: fitted to a 17 x 17 lattice of the whole output window's pixels."""
    raw, g = plan.raw, plan.grid
    la, lb, sa, sb = plan.window
    li = np.unique(np.linspace(la, lb - 1, 17).round().astype(int))
    si = np.unique(np.linspace(sa, sb - 1, 17).round().astype(int))
    tt, rr = np.meshgrid(plan.t_out[li], g.ranges[si], indexing="ij")
    pts = zero_doppler_points(raw.orbit, raw.epoch_utc, tt, rr, g.wavelength, raw.look_side, plan.terrain)
    return fit_plane(pts.reshape(-1, 3))


FFBP = Ffbp()


def focus_ffbp(raw, doppler, channel: int = 0, terrain=None, **options):
    """FFBP SLC of one channel of an in-memory raw product on (a window of) the RD grid."""
    from sarcli.focus.base import focus_in_memory

    return focus_in_memory(FFBP, raw, doppler, options, terrain, channel)
