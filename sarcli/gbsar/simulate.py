"""Stop-and-go VNA simulation of a GB-SAR scene: S21 per polarization, rail stop and frequency.

At a stop with antenna phase centre ``a`` the VNA measures, for every scatterer ``i`` at ``p_i``,

    S21(f) = sum_i  s_i[pol] * G_i * exp(-j*4*pi*f*(1 + N*1e-6)*|p_i - a| / c)  (+ noise)

with ``s_i`` the scatterer's scattering-matrix element, ``G_i`` the two-way antenna amplitude
pattern (1 unless ``antenna_pattern`` is listed) and ``N`` the refractivity of the ``atmosphere``
effect (0 unless listed). There is no range spreading loss: ``s_i`` is the reflectivity as seen by
the radar. The sweep is instantaneous at each stop (stop-and-go, the paper's model).

Antenna pattern (``antenna_pattern``): the boresight is horizontal along +y, tilted down by
``depression``; ``az`` and ``el`` are the angles of the line of sight in the azimuth (x) and
elevation planes of the antenna. ``pattern = "sinc"``: two-way amplitude
``sinc^2(L_x sin(az)/lam) * sinc^2(L_R sin(el)/lam)`` at the centre wavelength (the 11 % frequency
dependence of the beam over a 600 MHz sweep is neglected). ``pattern = "rect"``: the paper's ideal
beam ([LeeGBSAR-II-2007, eq. 22]): 1 inside ``|tan az| <= lam/(2 L_x)`` and ``|tan el| <= lam/(2 L_R)``,
0 outside; nothing is received from behind the antenna.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sarcli.errors import SarcliError
from sarcli.gbsar.scene import Scene
from sarcli.io.scan import POLARIZATIONS
from sarcli.memory import fits_in_memory
from sarcli.model.constants import C_LIGHT
from sarcli.model.gbsar import Scan

_ANCHOR = 64  # exact phase re-evaluated every _ANCHOR frequencies in the recurrence


@njit(cache=True)
def s21_stop_kernel(pos, amp, gain, antenna, freq, uniform, path_scale, out):
    """Accumulate into ``out`` (n_pol, n_freq) complex128 the echoes of scatterers ``pos`` (n, 3)
    with amplitudes ``amp`` (n_pol, n) complex128 and pattern ``gain`` (n,) seen from ``antenna`` (3,).

    For a uniform sweep (``uniform`` true) the phasor is advanced by a constant step and re-anchored
    exactly every ``_ANCHOR`` samples, so the rounding error stays below ~1e-13.
    """
    n_pol, n_f = out.shape
    k4 = -4.0 * np.pi * path_scale / C_LIGHT
    df = freq[1] - freq[0] if n_f > 1 else 0.0
    for i in range(pos.shape[0]):
        g = gain[i]
        if g == 0.0:
            continue
        dx = pos[i, 0] - antenna[0]
        dy = pos[i, 1] - antenna[1]
        dz = pos[i, 2] - antenna[2]
        kr = k4 * np.sqrt(dx * dx + dy * dy + dz * dz)
        step = np.exp(1j * kr * df)
        e = 0j
        for k in range(n_f):
            if not uniform or k % _ANCHOR == 0:
                e = np.exp(1j * kr * freq[k])
            else:
                e *= step
            for p in range(n_pol):
                out[p, k] += amp[p, i] * g * e


def s21_stop_reference(pos, amp, gain, antenna, freq, path_scale):
    """Plain-numpy reference of :func:`s21_stop_kernel` (returns (n_pol, n_freq) complex128)."""
    r = np.linalg.norm(pos - antenna[None, :], axis=1)
    ph = np.exp(-1j * 4 * np.pi * path_scale * np.outer(r, freq) / C_LIGHT)  # (n, n_f)
    return (amp * gain[None, :]) @ ph


def antenna_gain(scene: Scene, antenna_pos: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """Two-way amplitude pattern (n,) of scatterers ``pos`` (n, 3) seen from ``antenna_pos`` (3,)."""
    if "antenna_pattern" not in scene.effects:
        return np.ones(pos.shape[0])
    v = pos - antenna_pos[None, :]
    d = scene.depression_rad
    vb = v[:, 1] * np.cos(d) - v[:, 2] * np.sin(d)  # along the boresight
    ve = v[:, 1] * np.sin(d) + v[:, 2] * np.cos(d)  # elevation axis (up, normal to the boresight)
    va = v[:, 0]
    lam = scene.wavelength_m
    lx, lr = scene.antenna.length_azimuth_m, scene.antenna.length_range_m
    front = vb > 0
    if scene.pattern == "rect":
        g = front & (np.abs(va) <= vb * lam / (2 * lx)) & (np.abs(ve) <= vb * lam / (2 * lr))
        return g.astype(np.float64)
    rn = np.linalg.norm(v, axis=1)
    rn = np.where(rn > 0, rn, 1.0)
    return np.where(front, np.sinc(lx * va / rn / lam) ** 2 * np.sinc(lr * ve / rn / lam) ** 2, 0.0)


def _is_uniform(freq: np.ndarray) -> bool:
    if freq.size < 3:
        return True
    d = np.diff(freq)
    return bool(np.all(np.abs(d - d[0]) <= 1e-9 * abs(d[0])))


def _noise_rng(scene: Scene, position_m: float, height_m: float) -> np.random.Generator:
    bits = np.array([position_m, height_m], np.float64).view(np.uint64)
    return np.random.default_rng([scene.seed, 0x4E015E, int(bits[0]), int(bits[1])])


def simulate_stop(scene: Scene, position_m: float, height_m: float, frequency_hz, polarizations,
                  rng: np.random.Generator | None = None) -> np.ndarray:
    """S21 (n_pol, n_freq) complex128 at one rail stop (x = position_m, z = height_m).

    ``frequency_hz`` and ``height_m`` are used as given (a planned acquisition of the scene uses
    :meth:`Scene.frequencies` and :meth:`Scene.rail_heights`, which apply the frequency_shift and
    vertical_baseline effects). Noise (if listed) comes from ``rng`` or, when it is None, from a
    generator seeded by (scene seed, position, height), so a stop is reproducible.
    """
    freq = np.ascontiguousarray(np.atleast_1d(np.asarray(frequency_hz, np.float64)))
    pols = tuple(str(p).upper() for p in polarizations)
    bad = [p for p in pols if p not in POLARIZATIONS]
    if bad or not pols:
        raise SarcliError(f"unknown polarization(s) {','.join(bad) or '(none)'}; use VV, VH, HV, HH")
    if not np.all(np.isfinite(freq)) or np.any(freq <= 0):
        raise SarcliError("simulate_stop: frequencies must be finite and positive")
    sc = scene.scatterers
    antenna = np.array([position_m, 0.0, height_m], np.float64)
    amp = np.ascontiguousarray(sc.reflectivity[[POLARIZATIONS.index(p) for p in pols]])
    gain = antenna_gain(scene, antenna, sc.position)
    scale = 1.0 + 1e-6 * scene.effects.get("atmosphere", {}).get("refractivity_ppm", 0.0)
    out = np.zeros((len(pols), freq.size), np.complex128)
    s21_stop_kernel(np.ascontiguousarray(sc.position), amp, gain, antenna, freq, _is_uniform(freq), scale, out)
    if "noise" in scene.effects:
        rng = rng if rng is not None else _noise_rng(scene, position_m, height_m)
        sigma = np.sqrt(10 ** (scene.effects["noise"]["power_db"] / 10) / 2)
        out += sigma * (rng.standard_normal(out.shape) + 1j * rng.standard_normal(out.shape))
    return out


def simulate(scene: Scene, progress=None) -> Scan:
    """Simulate a whole scan of ``scene`` (every planned stop); ``progress`` wraps the stop iterator."""
    n = scene.positions_m.size
    fits_in_memory(f"a scan of {len(scene.polarizations)} x {n} x {scene.points} samples",
                   len(scene.polarizations) * n * scene.points * 8.0 + scene.points * 40.0)
    freq = scene.frequencies()
    heights = scene.rail_heights()
    s21 = np.empty((len(scene.polarizations), n, freq.size), np.complex64)
    stops = range(n) if progress is None else progress(range(n))
    for i in stops:
        s21[:, i, :] = simulate_stop(scene, scene.positions_m[i], heights[i], freq, scene.polarizations)
    sc = scene.scatterers
    truth = {
        "scene_toml": scene.source_toml,
        "scatterer_position": sc.position,
        "scatterer_reflectivity": sc.reflectivity.astype(np.complex128),
        "scatterer_kind": sc.kind,
        "scatterer_displacement": sc.displacement,
        "scatterer_los_displacement": sc.los_displacement,
    }
    return Scan(s21=s21, frequency=freq, rail_position=scene.positions_m.copy(), rail_height=heights,
                polarizations=scene.polarizations, epoch_utc=scene.epoch_utc, stop_time=scene.stop_times(),
                stop_flags=np.zeros(n, np.uint8), site=scene.site, antenna=scene.antenna,
                instrument={"simulator": "sarcli.gbsar.simulate", "effects": ",".join(sorted(scene.effects)),
                            "seed": scene.seed},
                truth=truth, source="simulated", status="simulated", n_planned=n)
