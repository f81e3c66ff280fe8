"""Temporal coherence, persistent-scatterer (PS) selection and PS time series ([LeeGBSAR-I-2007, §3.6]).

For N co-registered images ``z_i`` of the same geometry the temporal coherence of a pixel is
``gamma = |sum_i z_i| / sum_i |z_i|`` (0..1): 1 when the phase never changes. [LeeGBSAR-I-2007, §3.6] observed
gamma > 0.9 -> phase changes < 10 deg and gamma > 0.99 -> < 1 deg. PS are pixels with gamma at or
above a threshold and an amplitude within ``dynamic_range_db`` of the brightest pixel. Their phase
relative to the first image, unwrapped along time, converts to LOS displacement
``d = -phase lam/(4 pi)`` (+ = away from the radar, DInSAR sign of :mod:`sarcli.gbsar.interferometry`).
"""

from __future__ import annotations

import numpy as np

from sarcli.errors import SarcliError
from sarcli.gbsar.interferometry import check_same_grid


def temporal_coherence(stack: np.ndarray) -> np.ndarray:
    """``|sum z| / sum |z|`` over axis 0 of an (N, ...) complex stack (0 where all are zero)."""
    if stack.shape[0] < 2:
        raise SarcliError("temporal coherence needs at least 2 images")
    return coherence_from_sums(np.sum(stack, axis=0, dtype=np.complex128),
                               np.sum(np.abs(stack), axis=0, dtype=np.float64))


def coherence_from_sums(sum_z: np.ndarray, sum_abs: np.ndarray) -> np.ndarray:
    """``|sum z| / sum |z|`` from the two sums (accumulated image by image: :mod:`sarcli.parallel.gbsar`)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(sum_abs > 0, np.abs(sum_z) / sum_abs, 0.0).astype(np.float32)


def select_ps(gamma: np.ndarray, mean_amplitude: np.ndarray, threshold: float,
              dynamic_range_db: float = 40.0) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) of pixels with gamma >= threshold and amplitude within dynamic_range_db of the max."""
    if not 0.0 < threshold <= 1.0:
        raise SarcliError("the coherence threshold must be in (0, 1]")
    top = float(np.max(mean_amplitude)) if mean_amplitude.size else 0.0
    floor = top * 10 ** (-dynamic_range_db / 20)
    return np.nonzero((gamma >= threshold) & (mean_amplitude > floor) & (mean_amplitude > 0))


def ps_series(z: np.ndarray, wavelength_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Phase (rad, unwrapped in time, first = 0) and LOS displacement (mm) of PS pixels whose values
    in the N images are ``z`` (n_ps, N): (n_ps, N) each."""
    ph = np.unwrap(np.angle(z * np.conj(z[:, :1])), axis=1)
    return ph.astype(np.float32), (-ph * wavelength_m / (4 * np.pi) * 1e3).astype(np.float32)


def check_series(images: list, pol: str, names: list[str]) -> None:
    """One-line errors for images that cannot form a PS series: every image must share the first one's
    frequency grid, pixel grid and polarization (``check_same_grid``) and its geometry -- rail height and
    centre frequency -- since a PS series is repeat-pass, zero-baseline DInSAR (a different rail height
    or frequency adds the cross-track or delta-f phase to every pixel and breaks the temporal coherence)."""
    ref = images[0]
    for img, name in zip(images[1:], names[1:], strict=True):
        check_same_grid(ref, img, pol)
        bv = img.rail_height_m - ref.rail_height_m
        df = img.center_frequency_hz - ref.center_frequency_hz
        if abs(bv) > 1e-6 or abs(df) > 1e-3:
            what = f"a rail height {bv:+g} m" if abs(bv) > 1e-6 else f"a centre frequency {df:+g} Hz"
            raise SarcliError(f"{name} has {what} off {names[0]}: a PS series needs scans of one geometry "
                              f"(interfere that pair with --mode {'crosstrack' if abs(bv) > 1e-6 else 'deltaf'} "
                              "or combined instead)")
