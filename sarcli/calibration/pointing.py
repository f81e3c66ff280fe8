"""Antenna pointing from the data: the Doppler centroid measured on raw echoes against the one
predicted from orbit + attitude.

Input: a Doppler model from ``sarcli.doppler.api.estimate_doppler`` on a product with state vectors and
attitude (the blocks carry the measured baseband centroid ``fdc_baseband_hz``, its inverse phase
variance ``weight`` (rad^-2) and the geometric centroid ``fdc_orbit_hz`` of the beam-centre plane,
``sarcli.doppler.geometry``). Per valid block the difference d_k = wrap(fbb_k - fdc_orbit_k) into
[-PRF/2, PRF/2) removes the geometric variation over range and time; the scene difference is their
inverse-variance weighted mean d, and its standard error is given two ways:

- ``sigma_scatter_hz``: from the scatter of the blocks, sqrt(sum w (d_k - d)^2 / sum w / (N_eff - 1)),
  N_eff = (sum w)^2 / sum w^2 (what the data say, speckle and scene content included);
- ``sigma_model_hz``: from the CDE phase variance (1 - q^2) / (2 N q^2) of each block (``cde``):
  PRF / (2 pi sqrt(sum w)) (speckle only, for uncorrelated blocks).

Neither covers a scene-contrast bias common to all blocks: the centroid of the echo is the centroid
of the illuminated scene, and bright or dark areas across the beam footprint move it; a cut shorter
than the synthetic aperture sees one footprint only. The predicted baseband centroid is
``fbb_data - d``; ``ambiguity_prediction`` is the PRF ambiguity of the predicted absolute centroid.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sarcli.errors import SarcliError


def _wrap(f: np.ndarray, prf: float) -> np.ndarray:
    return np.mod(np.asarray(f, np.float64) + 0.5 * prf, prf) - 0.5 * prf


def centroid_comparison(model: Any) -> dict[str, Any]:
    """Measured vs orbit + attitude predicted Doppler centroid of an ``estimate_doppler`` model
    (module docstring). Refuses a model without the orbit prediction (no state vectors)."""
    b = model.blocks
    prf = float(model.prf_hz)
    valid = np.asarray(b["valid"], bool)
    pred = np.asarray(b["fdc_orbit_hz"], np.float64)
    if not np.any(valid & np.isfinite(pred)):
        raise SarcliError("no orbit + attitude prediction in the Doppler model (the product has no state vectors)")
    use = valid & np.isfinite(pred)
    w = np.asarray(b["weight"], np.float64)[use]
    fbb = np.asarray(b["fdc_baseband_hz"], np.float64)[use]
    p = pred[use]
    fbb_scene = float(model.summary.fdc_baseband_hz)
    # the blocks' differences, unwrapped around the scene's one (d_k within half a PRF of it)
    d0 = float(_wrap(fbb_scene - np.average(p, weights=w), prf))
    d = d0 + _wrap(_wrap(fbb - p, prf) - d0, prf)
    mean = float(np.average(d, weights=w))
    n_eff = float(w.sum() ** 2 / np.sum(w * w))
    scatter = float(np.sqrt(np.sum(w * (d - mean) ** 2) / w.sum() / max(n_eff - 1.0, 1e-12))) if n_eff > 1.5 \
        else float("nan")
    predicted_abs = float(np.average(p, weights=w))
    s = model.summary
    return {
        "fdc_baseband_data_hz": float(_wrap(mean + predicted_abs, prf)),
        "sigma_scatter_hz": scatter,
        "sigma_model_hz": float(prf / (2.0 * np.pi * np.sqrt(w.sum()))),
        "n_blocks": int(use.sum()), "n_eff_blocks": n_eff,
        "fdc_predicted_hz": predicted_abs,
        "fdc_baseband_predicted_hz": float(_wrap(predicted_abs, prf)),
        "ambiguity_prediction": int(np.floor(predicted_abs / prf + 0.5)),
        "data_minus_predicted_hz": mean,
        "ambiguity": s.ambiguity, "ambiguity_source": s.ambiguity_source,
        "ambiguity_confidence": s.ambiguity_confidence,
        "data_only": [e.to_dict() for e in s.data_only], "prf_hz": prf,
    }
