"""Omega-k benchmarks: time against RD and two fft2 in the same run, accuracy against RD across squint,
the Stolt kernel's error per length.

1. 1536 x 2048 block (Radarsat-1 Vancouver geometry, random complex64 echoes, centroid -7044 Hz, as
   bench_focus section 1): RD (default), omegak full Stolt (sinc16 default, sinc8; oversampling 2)
   and monochromatic; interleaved rounds, best of 5; ratios to two scipy.fft.fft2 of the block.
2. Airborne X-band point targets at 0 / 20 / 40 deg squint (tests/focus/test_omegak.py's scene:
   relative bandwidth 1 %, rect windows, targets 62 and 112 samples short of mid-swath): deskewed
   IRW against window theory (%), PSLR (dB), the phase error at the target's pixel (rad) for omegak
   full, omegak monochromatic and RD; the worst of the two targets.
3. Stolt kernel error (relative rms on one row, 40 deg, relative band 0.8 fs) per kernel length, for
   content at t = 0.05 / 0.15 / 0.25 cycle per bin (0.25: the default oversampling's edge).

Run: ``python -m bench.run_all bench_omegak`` (or ``python -m bench.bench_omegak``).
"""

from __future__ import annotations

import os

import numpy as np
import scipy.fft as sfft

from bench.common import best_time, markdown_table, write_results


def bench_time() -> dict:
    from bench.bench_focus import _doppler, _rs1_raw
    from sarcli.focus.omegak import focus_omegak
    from sarcli.focus.rda import focus_rd

    raw = _rs1_raw(1536, 2048)
    dop = _doppler()
    x = raw.echo.copy()
    configs = {"rd (default)": (focus_rd, {}),
               "omegak full, sinc16 (default)": (focus_omegak, {}),
               "omegak full, sinc8": (focus_omegak, {"stolt_kernel": "sinc8"}),
               "omegak monochromatic": (focus_omegak, {"stolt": "monochromatic"})}
    for fn, kw in configs.values():  # warm-up (numba compilation)
        fn(raw, dop, **kw)
    t_fft = float("inf")
    best = dict.fromkeys(configs, float("inf"))
    for _ in range(5):
        t_fft = min(t_fft, best_time(lambda: (sfft.fft2(x, workers=-1), sfft.fft2(x, workers=-1)), repeat=1,
                                     warmup=0))
        for name, (fn, kw) in configs.items():
            best[name] = min(best[name], best_time(lambda fn=fn, kw=kw: fn(raw, dop, **kw), repeat=1, warmup=0))
    rows = {}
    for name, (fn, kw) in configs.items():
        slc = fn(raw, dop, **kw)
        rows[name] = {"seconds": best[name], "ratio_to_2fft2": best[name] / t_fft, "ratio_to_rd": best[name] /
                      best["rd (default)"], "range_fft_length": slc.parameters["range_fft_length"],
                      "timings": slc.timings}
    return {"shape": [1536, 2048], "two_fft2_s": t_fft, "configs": rows, "workers": os.cpu_count()}


def bench_squint() -> dict:
    from sarcli.focus.omegak import focus_omegak
    from sarcli.focus.quality import point_target_metrics
    from sarcli.focus.rda import focus_rd
    from tests.focus import test_omegak as t
    from tests.focus.theory import irf_theory

    th = irf_theory("rect")
    out = {}
    for sq in (0.0, 20.0, 40.0):
        raw, dop, targets = t.air_scene(sq)
        fdc = -2 * t.A_V * np.sin(np.radians(sq)) / t.A_LAM
        d = np.cos(np.radians(sq))
        common = dict(range_window="rect", azimuth_window="rect", range_bandwidth_fraction=t.A_FRACTION,
                      azimuth_bandwidth_hz=t.A_BA)
        for name, slc in (("omegak full", focus_omegak(raw, dop, **common)),
                          ("omegak monochromatic", focus_omegak(raw, dop, stolt="monochromatic", **common)),
                          ("rd", focus_rd(raw, dop, **common))):
            worst = {"irw_range_err_pct": 0.0, "irw_azimuth_err_pct": 0.0, "pslr_range_db": -99.0,
                     "pslr_azimuth_db": -99.0, "phase_err_rad": 0.0}
            for r0, line, col in targets:
                m = point_target_metrics(t.deskew(slc.image, fdc, col), line, col, azimuth_carrier=fdc / t.A_PRF)
                er = 100 * (m["irw_range_px"] / (th["irw"] * t.A_FS / (t.A_FRACTION * t.A_B / d)) - 1)
                ea = 100 * (m["irw_azimuth_px"] / (th["irw"] * t.A_PRF / t.A_BA) - 1)
                ph = t._truth_phase(slc, r0, line, col)
                worst = {"irw_range_err_pct": max(worst["irw_range_err_pct"], er, key=abs),
                         "irw_azimuth_err_pct": max(worst["irw_azimuth_err_pct"], ea, key=abs),
                         "pslr_range_db": max(worst["pslr_range_db"], m["pslr_range_db"]),
                         "pslr_azimuth_db": max(worst["pslr_azimuth_db"], m["pslr_azimuth_db"]),
                         "phase_err_rad": max(worst["phase_err_rad"], ph, key=abs)}
            out[f"{name} @ {sq:.0f} deg"] = worst
    return out


def bench_kernels() -> dict:
    from tests.focus.test_omegak import _stolt_error

    out = {}
    for interp in ("linear", "sinc4", "sinc8", "sinc16"):
        out[interp] = {f"t={x:.2f}": _stolt_error(interp, 0.8, 40.0, x)[0] for x in (0.05, 0.15, 0.25)}
    return out


def main() -> None:
    res = {"time": bench_time(), "squint": bench_squint(), "kernels": bench_kernels()}
    tm = res["time"]
    md = ["# bench_omegak", "", f"## 1. Time, {tm['shape'][0]} x {tm['shape'][1]} block (two fft2: "
          f"{tm['two_fft2_s']:.3f} s, {tm['workers']} cores)", ""]
    md.append(markdown_table(["config", "s", "/ 2 fft2", "/ rd", "range FFT"],
                             [[k, v["seconds"], v["ratio_to_2fft2"], v["ratio_to_rd"], v["range_fft_length"]]
                              for k, v in tm["configs"].items()]))
    md += ["", "## 2. Point targets across squint (airborne X band, rect; worst of two targets)", ""]
    md.append(markdown_table(["focuser @ squint", "IRW rg %", "IRW az %", "PSLR rg dB", "PSLR az dB", "phase rad"],
                             [[k, v["irw_range_err_pct"], v["irw_azimuth_err_pct"], v["pslr_range_db"],
                               v["pslr_azimuth_db"], v["phase_err_rad"]] for k, v in res["squint"].items()]))
    md += ["", "## 3. Stolt kernel error (relative rms, one row, 40 deg, band 0.8 fs)", ""]
    md.append(markdown_table(["kernel", "t = 0.05", "t = 0.15", "t = 0.25"],
                             [[k, *v.values()] for k, v in res["kernels"].items()]))
    write_results("bench_omegak", "\n".join(md) + "\n", res)


if __name__ == "__main__":
    main()
