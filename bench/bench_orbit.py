"""Orbit benchmark: what each accuracy knob costs (Hermite order, attitude rotation, Earth frame model,
geometry solves). Writes bench/results/bench_orbit.md and .json.

Rates are per CPU second of this process (``time.process_time``) so that they mean "per core" even on
a shared machine; wall-clock rates are given next to them. Numba compile time is reported separately.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit

from bench.common import markdown_table, peak_rss_bytes, write_results
from orbit import accuracy as A
from orbit import geometry as G
from orbit.frames import eci_to_ecef
from orbit.pointing import beam_vector
from orbit.precession import j2000_to_eci
from orbit.statevectors import DEFAULT_N_NODES, _hermite_kernel, hermite_reference


def _cpu_and_wall(fn, repeat: int = 3) -> tuple[float, float]:
    fn()
    cpu = wall = np.inf
    for _ in range(repeat):
        c0, w0 = time.process_time(), time.perf_counter()
        fn()
        cpu = min(cpu, time.process_time() - c0)
        wall = min(wall, time.perf_counter() - w0)
    return max(cpu, 1e-9), max(wall, 1e-9)


def hermite_section(truth: A.TruthOrbit) -> tuple[str, dict]:
    n_t = 1_000_000
    t = np.sort(np.random.default_rng(1).uniform(*truth.sv.span, n_t))
    t_ref = t[:: 10]
    rows, data = [], []
    sv = truth.sv
    for row in A.hermite_table(truth=truth, timing=False):
        N = row["n_nodes"]
        cpu, wall = _cpu_and_wall(lambda N=N: sv.interpolate(t, N))
        ref_cpu, _ = _cpu_and_wall(lambda N=N: hermite_reference(sv.time, sv.position, sv.velocity, t_ref, N), 1)
        row.update(evals_per_cpu_s=n_t / cpu, evals_per_wall_s=n_t / wall, numpy_ref_evals_per_s=t_ref.size / ref_cpu)
        data.append(row)
        ratio = row["evals_per_cpu_s"] / row["numpy_ref_evals_per_s"]
        rows.append([N, row["pos_err_interior_m"], row["vel_err_interior_mps"], row["pos_err_ends_m"],
                     row["vel_err_ends_mps"], f"{row['evals_per_cpu_s'] / 1e6:.1f}",
                     f"{row['evals_per_wall_s'] / 1e6:.1f}", f"{ratio:.0f}x"])
    md = markdown_table(["N", "pos err interior (m)", "vel err interior (m/s)", "pos err end intervals (m)",
                         "vel err end intervals (m/s)", "M evals/CPU-s", "M evals/wall-s", "vs numpy ref"], rows)
    # compile time of a fresh (uncached) copy of the kernel
    fresh = njit(fastmath={"contract"})(_hermite_kernel.py_func)
    tabs = truth.sv._table(DEFAULT_N_NODES)
    outs = [np.empty((4, 3)) for _ in range(3)]
    w0 = time.perf_counter()
    fresh(truth.sv.time, *tabs, t[:4].copy(), *outs)
    compile_s = time.perf_counter() - w0
    floor = A.truth_floor(truth)
    # frame of interpolation and uneven spacing, at the default order
    ecef_truth = A.TruthOrbit(truth.sv.to_ecef(), truth.t, *eci_to_ecef(truth.sv.epoch_utc, truth.t, truth.r, truth.v))
    e_ecef = A.interpolation_errors(ecef_truth, DEFAULT_N_NODES)
    uneven = A.rs1_truth(jitter_s=0.5)
    e_uneven = A.interpolation_errors(uneven, DEFAULT_N_NODES)
    md += (f"\nTruth self-consistency (DOP853 rtol 1e-13 vs 3e-14): {floor['pos_m']:.2g} m, {floor['vel_mps']:.2g} m/s "
           f"(the floor of the error columns).\n"
           f"Default N = {DEFAULT_N_NODES}: interpolating ECEF vectors instead of ECI: interior "
           f"{e_ecef['pos_err_interior_m']:.2g} m / {e_ecef['vel_err_interior_mps']:.2g} m/s; node times jittered "
           f"by +-0.5 s: interior {e_uneven['pos_err_interior_m']:.2g} m / "
           f"{e_uneven['vel_err_interior_mps']:.2g} m/s.\n"
           f"Numba compile time of the kernel (no cache): {compile_s:.2f} s.\n")
    return md, {"rows": data, "truth_floor": floor, "ecef_default": e_ecef, "uneven_default": e_uneven,
                "compile_s": compile_s}


def attitude_section(truth: A.TruthOrbit) -> tuple[str, dict]:
    rows = A.attitude_table(truth=truth)
    r, v, _ = truth.sv.interpolate(np.linspace(*truth.sv.span, 100_000))
    cost = {}
    for exact in (True, False):
        cpu, _ = _cpu_and_wall(lambda exact=exact: beam_vector(r, v, 0.5, 5e-4, 7e-5, exact=exact), 3)
        cost["exact" if exact else "small"] = r.shape[0] / cpu
    md = markdown_table(["x RS-1 limits", "pitch (deg)", "yaw (deg)", "pointing err (urad)", "Doppler err (Hz)",
                         "ground err (m)", "attitude's own Doppler (Hz)"],
                        [[x["scale"], x["pitch_deg"], x["yaw_deg"], x["pointing_err_urad"], x["doppler_err_hz"],
                          x["ground_err_m"], x["attitude_doppler_hz"]] for x in rows])
    md += (f"\nBeam vectors per CPU second (numpy, incl. flight frame via pyproj): exact {cost['exact'] / 1e6:.2f} M, "
           f"small-angle {cost['small'] / 1e6:.2f} M.\n")
    return md, {"rows": rows, "beam_vectors_per_s": cost}


def frame_section(truth: A.TruthOrbit) -> tuple[str, dict]:
    rows = A.frame_table()
    t = np.linspace(0, 7200.0, 200_000)
    r = np.broadcast_to(truth.r[0], (t.size, 3))
    c_gmst, _ = _cpu_and_wall(lambda: eci_to_ecef(truth.sv.epoch_utc, t, r), 3)
    c_full, _ = _cpu_and_wall(lambda: eci_to_ecef(truth.sv.epoch_utc, t, j2000_to_eci(truth.sv.epoch_utc, t, r)), 3)
    md = markdown_table(["if the state vectors were ... / if we neglect ...", "ground error (m)"],
                        [[x["hypothesis"], x["ground_m"]] for x in rows])
    md += (f"\nConversions per CPU second: GMST-only {t.size / c_gmst / 1e6:.2f} M, J2000 full (P, N, EE, GMST) "
           f"{t.size / c_full / 1e6:.2f} M.\n")
    return md, {"rows": rows, "gmst_per_s": t.size / c_gmst, "full_per_s": t.size / c_full}


def geometry_section(truth: A.TruthOrbit) -> tuple[str, dict]:
    sv = truth.sv.to_ecef()
    t = np.linspace(sv.span[0] + 500, sv.span[1] - 500, 101)
    r, v, _ = sv.interpolate(t)
    worst_t = worst_r = 0.0
    for look in np.radians([15.0, 30.0, 45.0, 55.0]):
        for h in (0.0, 5000.0):
            for fdc in (0.0, -7000.0):
                rho = G.slant_range_from_look(r, v, look, "right", h)
                p = G.geolocate(sv, t, rho, A.RS1_WAVELENGTH, fdc, h)
                t2, rho2 = G.doppler_time(sv, p, A.RS1_WAVELENGTH, fdc, t_guess=t)
                worst_t = max(worst_t, float(np.abs(t2 - t).max()))
                worst_r = max(worst_r, float(np.abs(rho2 - rho).max()))
    n = 100_000
    tt = np.random.default_rng(2).uniform(sv.span[0] + 500, sv.span[1] - 500, n)
    rho = np.random.default_rng(3).uniform(8.5e5, 1.1e6, n)
    c_geo, _ = _cpu_and_wall(lambda: G.geolocate(sv, tt, rho, A.RS1_WAVELENGTH, -7000.0, 0.0), 1)
    p = G.geolocate(sv, tt, rho, A.RS1_WAVELENGTH, -7000.0, 0.0)
    c_dt, _ = _cpu_and_wall(lambda: G.doppler_time(sv, p, A.RS1_WAVELENGTH, -7000.0, t_guess=tt), 1)
    md = (f"Round trip geolocate(t, R, fdc, h) -> Doppler time and range, 101 times x looks 15-55 deg x h 0/5 km x "
          f"fdc 0/-7000 Hz: max |dt| = {worst_t:.2g} s, max |dR| = {worst_r:.2g} m.\n"
          f"Throughput per CPU second: geolocate {n / c_geo / 1e3:.0f} k points, Doppler time "
          f"{n / c_dt / 1e3:.0f} k points.\n")
    return md, {"round_trip_dt_s": worst_t, "round_trip_dR_m": worst_r, "geolocate_per_s": n / c_geo,
                "doppler_time_per_s": n / c_dt}


def main() -> None:
    truth = A.rs1_truth()
    parts, data = [], {}
    for title, fn in (("Hermite interpolation (15 x 480 s J2 truth)", hermite_section),
                      ("Control rotation: exact vs small-angle", attitude_section),
                      ("Earth frame model: GMST-only vs alternatives (2002-06-16)", frame_section),
                      ("Geometry solves", geometry_section)):
        md, d = fn(truth)
        parts.append(f"### {title}\n\n{md}")
        data[fn.__name__] = d
    data["peak_rss_bytes"] = peak_rss_bytes()
    md = "## bench_orbit\n\n" + "\n".join(parts) + f"\nPeak RSS: {data['peak_rss_bytes'] / 2**20:.0f} MiB.\n"
    write_results("bench_orbit", md, data)


if __name__ == "__main__":
    main()
