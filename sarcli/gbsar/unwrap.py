"""Spatial phase unwrapping of GB-SAR interferograms with SNAPHU (the ``snaphu`` Python package).

Why SNAPHU [ChenZebker2001]: it is the unwrapper of the InSAR processors (ISCE, GAMMA's MCF is its cousin), a
statistical-cost network flow whose costs come from the coherence, so it routes the unavoidable 2 pi
discontinuities through the decorrelated pixels instead of across the coherent ones; it reports
connected components (regions unwrapped consistently with each other). scikit-image's
``unwrap_phase`` [Herraez2002] (reliability-sorted path following) uses no coherence and no
mask-aware cost: on a GB-SAR scene, where the coherent rocks and walls sit among vegetation, it
smears errors from the noisy pixels into the coherent ones. ``snaphu`` installs as a wheel with
its own SNAPHU build (numpy its only dependency), so it is a plain dependency of sarcli.

Model: the wrapped residual ``psi = W(phi)`` (``W`` wraps to (-pi, pi]) of a smooth phase ``phi``;
SNAPHU returns ``phi_u = psi + 2 pi k`` (integer ``k`` per pixel) minimising its cost, ``smooth``
mode (deformation and residual phases are smooth fields), ``nlooks`` the independent looks of the
coherence estimate. Unwrapping fixes ``phi`` up to one 2 pi multiple per connected component: each
component is shifted by the multiple of 2 pi that puts its median in (-pi, pi] (the scene moves less
than a quarter wavelength on the median: the stable-ground assumption of GB-SAR monitoring); pixels
outside every component (too small, or decorrelated islands) are NaN. A picture with fewer than
``min_region_pixels`` valid pixels, or one pixel wide, is left wrapped (one component).
"""

from __future__ import annotations

import contextlib
import logging
import os
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from sarcli.errors import SarcliError

log = logging.getLogger(__name__)


@dataclass
class Unwrapped:
    """``phase`` (rad, NaN outside the components), ``component`` (int32, 0 = none, 1.. = SNAPHU's
    connected components), and the unwrapper's name and version."""

    phase: np.ndarray
    component: np.ndarray
    method: str


@contextlib.contextmanager
def _stdout_to_log() -> Iterator[None]:
    """SNAPHU prints its progress on file descriptor 1: keep it off sarcli's stdout (``--json``) and
    pass it to the DEBUG log."""
    with tempfile.TemporaryFile() as tmp:
        saved = os.dup(1)
        os.dup2(tmp.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)
            tmp.seek(0)
            log.debug("snaphu: %s", tmp.read().decode(errors="replace").strip())


def unwrap(wrapped: np.ndarray, coherence: np.ndarray, nlooks: float = 1.0,
           min_region_pixels: int = 20) -> Unwrapped:
    """Unwrap ``wrapped`` (rad, NaN = no data) weighted by ``coherence`` (module docstring).

    ``nlooks``: independent looks of the coherence estimate (a w x w boxcar on an oversampled image
    has fewer than w^2); ``min_region_pixels``: smallest connected component kept.
    """
    import snaphu

    psi = np.asarray(wrapped, np.float64)
    if psi.ndim != 2:
        raise SarcliError(f"unwrapping needs a 2-D phase, got shape {psi.shape}")
    mask = np.isfinite(psi) & np.isfinite(coherence)
    out = np.full(psi.shape, np.nan, np.float32)
    comp = np.zeros(psi.shape, np.int32)
    method = f"snaphu {snaphu.__version__} (smooth cost, MCF init)"
    if np.count_nonzero(mask) < max(min_region_pixels, 2) or min(psi.shape) < 2:
        out[mask] = psi[mask]
        comp[mask] = 1
        return Unwrapped(out, comp, "none: too few pixels to unwrap, the residual stays wrapped")
    igram = np.where(mask, np.exp(1j * np.where(mask, psi, 0.0)), 0.0).astype(np.complex64)
    corr = np.clip(np.where(mask, coherence, 0.0), 0.0, 1.0).astype(np.float32)
    frac = min_region_pixels / float(np.count_nonzero(mask))
    with _stdout_to_log():
        try:
            unw, cc = snaphu.unwrap(igram, corr, nlooks=max(float(nlooks), 1.0), cost="smooth", init="mcf",
                                    mask=mask, min_conncomp_frac=min(frac, 1.0), min_region_size=min_region_pixels)
        except RuntimeError as e:  # SNAPHU's own message (a failed network solve)
            raise SarcliError(f"phase unwrapping failed: {' '.join(str(e).split())[:200]}") from None
    unw = np.asarray(unw, np.float64)
    cc = np.asarray(cc, np.int64)
    for k in np.unique(cc[mask & (cc > 0)]):
        sel = (cc == k) & mask
        shift = 2 * np.pi * np.round(np.median(unw[sel]) / (2 * np.pi))
        out[sel] = (unw[sel] - shift).astype(np.float32)
        comp[sel] = int(k)
    return Unwrapped(out, comp, method)
