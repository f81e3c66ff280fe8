"""Chirp scaling (``csa``) against RD: time on the same block, accuracy across squint.

1. Time: the 1536 x 2048 Radarsat-1-geometry block of bench_focus (random complex64 echoes, centroid
   -7044 Hz, one block), RD and CSA with their defaults, interleaved rounds, best of each, as ratios to
   two scipy.fft.fft2 passes over the same array in the same run.
2. Accuracy on plain-numpy point targets (tests/focus/test_csa.py scenes, rect windows):
   spaceborne (C band, 0 / 3.4 / 6 PRF of centroid): IRW, PSLR, position and peak phase against
   window theory and truth; airborne (V = 100 m/s, R0 = 2070 m, 100 MHz, X band at 0 / 20 / 40 degrees
   and C band at 40): against exact backprojection on the same grid (phase of the correlation over
   BP's main lobe, normalized correlation rho, IRW ratio along the deskewed axes, peak offset), and
   CSA with its reference range moved to mid-swath (RD's SRC reference) to show where the 40-degree
   difference comes from.

Run: ``python -m bench.bench_csa``.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.fft as sfft

from bench.common import best_time, markdown_table, write_results


def bench_time() -> dict:
    from bench.bench_focus import _doppler, _rs1_raw
    from sarcli.focus.csa import focus_csa
    from sarcli.focus.rda import focus_rd

    raw, dop = _rs1_raw(1536, 2048), _doppler()
    x = raw.echo.copy()
    fns = {"rd": focus_rd, "csa": focus_csa}
    for fn in fns.values():
        fn(raw, dop)  # numba compilation
    t_fft = float("inf")
    best = dict.fromkeys(fns, float("inf"))
    for _ in range(5):
        t_fft = min(t_fft, best_time(lambda: (sfft.fft2(x, workers=-1), sfft.fft2(x, workers=-1)), repeat=1,
                                     warmup=0))
        for name, fn in fns.items():
            best[name] = min(best[name], best_time(lambda fn=fn: fn(raw, dop), repeat=1, warmup=0))
    timings = {name: fn(raw, dop).timings for name, fn in fns.items()}
    return {"two_fft2_s": t_fft, "seconds": best, "ratio_to_2fft2": {k: v / t_fft for k, v in best.items()},
            "csa_over_rd": best["csa"] / best["rd"], "stages": timings}


def bench_accuracy() -> dict:
    from sarcli.focus.quality import point_target_metrics
    from sarcli.focus.rda import focus_rd
    from tests.focus import test_csa as t
    from tests.focus.theory import irf_theory

    th = irf_theory("rect")
    space = []
    for fdc in (0.0, t.SQUINT_FDC, -6 * t.PRF):
        for name, fn in (("rd", focus_rd), ("csa", t.focus_csa)):
            _, slc, row, col = t._spaceborne(fdc, "rect", focus=fn)
            m = point_target_metrics(slc.image, row, col, azimuth_carrier=fdc / t.PRF)
            space.append({"fdc_prf": fdc / t.PRF, "algorithm": name,
                          "irw_range_rel": m["irw_range_px"] / (th["irw"] * t.FS / t.B_RANGE) - 1,
                          "irw_azimuth_rel": m["irw_azimuth_px"] / (th["irw"] * t.PRF / t.BA) - 1,
                          "pslr_range_db": m["pslr_range_db"], "pslr_azimuth_db": m["pslr_azimuth_db"],
                          "position_px": max(abs(m["row"] - row), abs(m["col"] - col)),
                          "phase_rad": float(np.angle(np.exp(1j * (m["peak_phase_rad"] + 4 * np.pi * t.R0 / t.LAM))))})
    air = []
    for band, lam, prf, ba, deg in (("X", t.C / 9.6e9, 400.0, 300.0, 0.0), ("X", t.C / 9.6e9, 400.0, 300.0, 20.0),
                                    ("X", t.C / 9.6e9, 400.0, 300.0, 40.0), ("C", 0.0566, 200.0, 150.0, 40.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = t._airborne_case(lam, deg, prf, ba, csa_at_mid_swath=deg == 40.0)
        for name, r in res.items():
            air.append({"band": band, "squint_deg": deg, "algorithm": name, **r})
    return {"spaceborne": space, "airborne": air}


def main() -> None:
    tm = bench_time()
    acc = bench_accuracy()
    md = ["# bench_csa: chirp scaling vs RD\n",
          f"1536 x 2048 block: two fft2 {tm['two_fft2_s']:.3f} s; rd {tm['seconds']['rd']:.3f} s "
          f"({tm['ratio_to_2fft2']['rd']:.2f} x), csa {tm['seconds']['csa']:.3f} s "
          f"({tm['ratio_to_2fft2']['csa']:.2f} x): csa / rd = {tm['csa_over_rd']:.2f}\n",
          "## Spaceborne point target (rect), vs window theory and truth\n",
          markdown_table(["centroid (PRF)", "alg", "IRW rg", "IRW az", "PSLR rg dB", "PSLR az dB", "pos px",
                          "phase rad"],
                         [[f"{r['fdc_prf']:.1f}", r["algorithm"], f"{100 * r['irw_range_rel']:+.2f} %",
                           f"{100 * r['irw_azimuth_rel']:+.2f} %", f"{r['pslr_range_db']:.2f}",
                           f"{r['pslr_azimuth_db']:.2f}", f"{r['position_px']:.4f}", f"{r['phase_rad']:+.4f}"]
                          for r in acc["spaceborne"]]),
          "## Airborne (V 100 m/s, R0 2070 m, 100 MHz), vs exact backprojection\n",
          markdown_table(["band", "squint deg", "alg", "phase vs BP rad", "rho", "IRW rg vs BP", "IRW az vs BP",
                          "peak offset px"],
                         [[r["band"], f"{r['squint_deg']:.0f}", r["algorithm"], f"{r['phase']:+.3f}",
                           f"{r['rho']:.3f}", f"{100 * r['irw_range']:+.1f} %", f"{100 * r['irw_azimuth']:+.1f} %",
                           f"{r['pos']:.3f}"] for r in acc["airborne"]])]
    write_results("bench_csa", "\n".join(md), {"time": tm, "accuracy": acc})


if __name__ == "__main__":
    main()
