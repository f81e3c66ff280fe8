"""Accuracy-vs-cost studies of the orbit knobs (used by ``sarcli orbit accuracy`` and bench/bench_orbit.py).

Every table is computed, never typed in:
- ``hermite_table``: Hermite order N against a J2 truth orbit sampled like Radarsat-1 (15 vectors,
  480 s apart) and densely (2 s), max position/velocity error over the span, away from its ends
  (>= 2 spacings) and in the two end intervals, plus evaluations per second of the numba kernel.
- ``attitude_table``: exact Rz(yaw) Ry(pitch) vs the small-angle matrix of [Koh2003, eq. 1] at multiples of the
  Radarsat-1 attitude limits: pointing error (urad) and the resulting Doppler error (Hz) at C band.
- ``frame_table``: metres at the ground if the "inertial" vectors were really in another ECI
  (true-of-date, mean-of-date, J2000) or if UT1-UTC / polar motion are neglected (bounds).
Rows are plain dicts (JSON-friendly).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from orbit.constants import OMEGA_EARTH, WGS84_A
from orbit.frames import _rz as rz
from orbit.geometry import relative_velocity_eci, target_from_look
from orbit.pointing import beam_vector, small_angle_pointing_error
from orbit.precession import (
    AS2R,
    centuries_since_j2000,
    equation_of_equinoxes,
    nutation_matrix,
    precession_matrix,
)
from orbit.propagate import Keplerian, kepler_to_state, propagate_j2
from orbit.statevectors import StateVectors

RS1_EPOCH = "2002-06-16T15:41:00Z"  # the Vancouver scene date
RS1_ELEMENTS = Keplerian(7_167_000.0, 0.0011, np.radians(98.6), 0.3, 1.2, 0.4)
RS1_WAVELENGTH = 0.05656
RS1_PITCH_LIMIT = np.radians(0.03)
RS1_YAW_LIMIT = np.radians(0.004)


@dataclass
class TruthOrbit:
    """J2-integrated truth: ECI state vectors as delivered and a dense reference."""

    sv: StateVectors
    t: np.ndarray
    r: np.ndarray
    v: np.ndarray


def truth_orbit(elements: Keplerian, node_times, dense_times, epoch_utc: str = RS1_EPOCH) -> TruthOrbit:
    """Propagate ``elements`` (at t = 0) with J2 to the node and dense times: ECI vectors + reference."""
    tn = np.asarray(node_times, np.float64)
    td = np.asarray(dense_times, np.float64)
    r0, v0 = kepler_to_state(elements)
    r, v = propagate_j2(r0, v0, np.concatenate([tn, td]))
    return TruthOrbit(StateVectors(tn, r[:tn.size], v[:tn.size], "ECI", epoch_utc), td, r[tn.size:], v[tn.size:])


def rs1_truth(spacing_s: float = 480.0, n_vectors: int = 15, dense_step_s: float = 2.0,
              jitter_s: float = 0.0, seed: int = 0) -> TruthOrbit:
    """Radarsat-1-like truth orbit (a = 7167 km, e = 0.0011, i = 98.6 deg); optional node time jitter."""
    tn = np.arange(n_vectors) * spacing_s
    if jitter_s:
        tn = tn + np.random.default_rng(seed).uniform(-jitter_s, jitter_s, n_vectors)
    return truth_orbit(RS1_ELEMENTS, tn, np.arange(tn[0], tn[-1], dense_step_s))


def _zones(truth: TruthOrbit) -> dict[str, np.ndarray]:
    tn = truth.sv.time
    return {"span": np.ones(truth.t.size, bool),
            "interior": (truth.t >= tn[2]) & (truth.t <= tn[-3]),
            "ends": (truth.t <= tn[1]) | (truth.t >= tn[-2])}


def interpolation_errors(truth: TruthOrbit, n_nodes: int, sv: StateVectors | None = None) -> dict:
    """Max position (m) and velocity (m/s) error of Hermite(N) per zone against the truth."""
    sv = truth.sv if sv is None else sv
    p, v, _ = sv.interpolate(truth.t, n_nodes)
    ep = np.linalg.norm(p - truth.r, axis=-1)
    ev = np.linalg.norm(v - truth.v, axis=-1)
    out = {}
    for name, m in _zones(truth).items():
        out[f"pos_err_{name}_m"] = float(ep[m].max())
        out[f"vel_err_{name}_mps"] = float(ev[m].max())
    return out


def evals_per_second(sv: StateVectors, n_nodes: int, n_times: int = 1_000_000, repeat: int = 3) -> float:
    """Single-thread Hermite evaluations per CPU second (sorted random times; compile excluded)."""
    t = np.sort(np.random.default_rng(1).uniform(*sv.span, n_times))
    sv.interpolate(t[:4], n_nodes)
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()  # CPU time of this process: a per-core rate even on a busy machine
        sv.interpolate(t, n_nodes)
        best = min(best, time.process_time() - t0)
    return n_times / max(best, 1e-9)


def hermite_table(n_values=(2, 4, 6, 8, 10, 12), truth: TruthOrbit | None = None, timing: bool = True,
                  n_times: int = 1_000_000) -> list[dict]:
    """One row per N: errors per zone (see module doc) and, with ``timing``, evaluations per second."""
    truth = rs1_truth() if truth is None else truth
    rows = []
    for N in n_values:
        row = {"n_nodes": int(N), **interpolation_errors(truth, N)}
        if timing:
            row["evals_per_s"] = evals_per_second(truth.sv, N, n_times)
        rows.append(row)
    return rows


def truth_floor(truth: TruthOrbit | None = None) -> dict:
    """Self-consistency of the J2 truth: the default run (rtol 1e-13) vs rtol 3e-14 (DOP853's floor)."""
    truth = rs1_truth() if truth is None else truth
    r0, v0 = kepler_to_state(RS1_ELEMENTS)
    r, v = propagate_j2(r0, v0, truth.t, rtol=3e-14, atol=1e-8)
    return {"pos_m": float(np.linalg.norm(r - truth.r, axis=-1).max()),
            "vel_mps": float(np.linalg.norm(v - truth.v, axis=-1).max())}


def attitude_table(scales=(0.0, 1.0, 10.0, 100.0), looks_deg=(20.0, 30.0, 40.0, 50.0),
                   wavelength: float = RS1_WAVELENGTH, truth: TruthOrbit | None = None) -> list[dict]:
    """Exact vs small-angle control rotation at ``scale`` x (pitch 0.03 deg, yaw 0.004 deg).

    Per row, maxima over 8 orbit positions, the looks and the four sign combinations of the angles:
    ``pointing_err_urad`` angle between the two beams; ``doppler_err_hz`` = (2/lam) v_rel . (L_exact -
    L_small) in ECI ([Koh2003, eq. 4-5]); ``ground_err_m`` distance between the two beams' ground points;
    ``attitude_doppler_hz`` the Doppler the attitude itself causes (exact beam vs zero attitude), for scale.
    """
    truth = rs1_truth() if truth is None else truth
    t = np.linspace(*truth.sv.span, 8)
    r, v, _ = truth.sv.interpolate(t)
    re, ve, _ = truth.sv.to_ecef().interpolate(t)
    vrel = relative_velocity_eci(r, v)
    looks = np.radians(np.asarray(looks_deg))
    rows = []
    for s in scales:
        perr = ferr = gerr = fatt = 0.0
        for sp in (1.0, -1.0):
            for sy in (1.0, -1.0):
                p, y = s * sp * RS1_PITCH_LIMIT, s * sy * RS1_YAW_LIMIT
                perr = max(perr, float(small_angle_pointing_error(looks, p, y).max()))
                for g in looks:
                    le = beam_vector(r, v, g, p, y, exact=True)
                    ls = beam_vector(r, v, g, p, y, exact=False)
                    ls = ls / np.linalg.norm(ls, axis=-1, keepdims=True)
                    ferr = max(ferr, float(np.abs(2.0 / wavelength * np.sum(vrel * (le - ls), -1)).max()))
                    l0 = beam_vector(r, v, g)
                    fatt = max(fatt, float(np.abs(2.0 / wavelength * np.sum(vrel * (le - l0), -1)).max()))
                    ge, _ = target_from_look(re, ve, g, pitch=p, yaw=y, exact=True)
                    gs, _ = target_from_look(re, ve, g, pitch=p, yaw=y, exact=False)
                    gerr = max(gerr, float(np.linalg.norm(ge - gs, axis=-1).max()))
        rows.append({"scale": float(s), "pitch_deg": float(np.degrees(s * RS1_PITCH_LIMIT)),
                     "yaw_deg": float(np.degrees(s * RS1_YAW_LIMIT)), "pointing_err_urad": perr * 1e6,
                     "doppler_err_hz": ferr, "ground_err_m": gerr, "attitude_doppler_hz": fatt})
    return rows


def _ground_metres(M: np.ndarray) -> float:
    """Max displacement (m) of Earth-surface points under the rotation M (..., 3, 3)."""
    d = np.random.default_rng(0).normal(size=(2000, 3))
    d = WGS84_A * d / np.linalg.norm(d, axis=1)[:, None]
    M = M.reshape(-1, 3, 3)
    return float(max(np.linalg.norm(d @ (m - np.eye(3)).T, axis=1).max() for m in M))


def frame_table(epoch_utc: str = RS1_EPOCH, dut1_bound_s: float = 0.9, polar_motion_bound_as: float = 0.6,
                span_s: float = 7200.0) -> list[dict]:
    """Metres at the ground between the GMST-only frame and the alternatives (max over the span)."""
    t = np.linspace(0.0, span_s, 5)
    T = centuries_since_j2000(epoch_utc, t)
    ee = rz(equation_of_equinoxes(T))
    N = nutation_matrix(T)
    Pm = precession_matrix(T)
    return [
        {"hypothesis": "vectors true-of-date (GAST), not GMST", "ground_m": _ground_metres(ee)},
        {"hypothesis": "vectors mean-of-date", "ground_m": _ground_metres(ee @ N)},
        {"hypothesis": "vectors J2000 (EME2000)", "ground_m": _ground_metres(ee @ N @ Pm)},
        {"hypothesis": f"UT1-UTC neglected (up to {dut1_bound_s} s)",
         "ground_m": WGS84_A * OMEGA_EARTH * dut1_bound_s},
        {"hypothesis": f"polar motion neglected (up to {polar_motion_bound_as} arcsec)",
         "ground_m": WGS84_A * polar_motion_bound_as * AS2R},
    ]
