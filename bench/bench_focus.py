"""Focusing benchmarks: speed vs scipy.fft, memory, full-size scene, numba compilation, accuracy vs cost.

1. 1536 x 2048 block (Radarsat-1 Vancouver geometry, random complex64 echoes, centroid -7044 Hz): the
   whole RD focus (one block) against two scipy.fft.fft2 passes over a same-size complex64 array, in the
   same run, same workers; peak extra memory (tracemalloc, numpy + scipy buffers) against the input.
2. Full-size Radarsat-1 scene 23000 x 6354 through ``sarcli focus`` (streamed from HDF5, blocks of 4096
   lines) in a child process: wall time and peak RSS.
3. First-call numba compilation (fresh cache directory, child process) vs the steady-state call.
4. Accuracy vs cost on the simulator's Radarsat-1 point-target scene (samples/rs1_point.toml, rect
   windows, true Doppler): RCMC kernel, range oversampling, SRC on/off, float32 vs float64, RD vs
   backprojection -> IRW, PSLR, ISLR, position error and seconds; table and plot.
5. Block invariance on the same scene with the Doppler ESTIMATED by sarcli.doppler (it and the
   orbit's V vary along azimuth): blocks of 1024, 2048 and 4096 lines (3, 2 and 1 blocks) -> the
   largest phase, amplitude and position differences of the targets between block sizes.

Run: ``python -m bench.run_all bench_focus`` (BENCH_FOCUS_QUICK=1 skips the full-size scene).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
import scipy.fft as sfft

from bench.common import RESULTS, best_time, markdown_table, write_results

REPO = Path(__file__).resolve().parents[1]
C = 299792458.0


def _rs1_raw(n_lines: int, n_samples: int, seed: int = 1):
    from sarcli.model.raw import Radar, RawProduct

    rng = np.random.default_rng(seed)
    echo = np.empty((n_lines, n_samples), np.complex64)
    for a in range(0, n_lines, 2048):
        b = min(n_lines, a + 2048)
        echo[a:b].real = rng.standard_normal((b - a, n_samples), np.float32)
        echo[a:b].imag = rng.standard_normal((b - a, n_samples), np.float32)
    prf = 1256.98
    radar = Radar(carrier_frequency_hz=5.3e9, wavelength_m=C / 5.3e9, prf_hz=prf, range_sampling_rate_hz=32.317e6,
                  chirp_rate_hz_per_s=-0.72135e12, pulse_length_s=41.75e-6, window_start_s=6.5956e-3,
                  first_range_m=6.5956e-3 * C / 2)
    return RawProduct(echo=echo, azimuth_time=np.arange(n_lines) / prf, epoch_utc="2002-06-16T00:00:00Z",
                      radar=radar, source="bench")


def _doppler():
    from sarcli.model.doppler import GeometricDoppler

    return GeometricDoppler.from_centroid_and_rate(-7044.0, -1775.0, 993.4e3, C / 5.3e9)


def bench_block() -> dict:
    from sarcli.focus.rda import focus_rd

    raw = _rs1_raw(1536, 2048)
    dop = _doppler()
    x = raw.echo.copy()
    configs = {"default (sinc8, 2x oversampling, SRC, float32)": {},
               "no oversampling, no SRC": {"rcmc_oversample": 1, "src": False}}
    for kw in configs.values():  # warm-up (numba compilation)
        focus_rd(raw, dop, **kw)
    # interleaved rounds, best of each: the reference and the focus see the same machine load
    t_fft = float("inf")
    best = dict.fromkeys(configs, float("inf"))
    for _ in range(7):
        t_fft = min(t_fft, best_time(lambda: (sfft.fft2(x, workers=-1), sfft.fft2(x, workers=-1)), repeat=1,
                                     warmup=0))
        for name, kw in configs.items():
            best[name] = min(best[name], best_time(lambda kw=kw: focus_rd(raw, dop, **kw), repeat=1, warmup=0))
    rows = {}
    for name, kw in configs.items():
        tracemalloc.start()
        focus_rd(raw, dop, **kw)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        slc = focus_rd(raw, dop, **kw)
        t = best[name]
        rows[name] = {"seconds": t, "ratio_to_2fft2": t / t_fft, "peak_extra_bytes": peak,
                      "peak_extra_over_input": peak / raw.echo.nbytes, "timings": slc.timings}
    return {"shape": [1536, 2048], "two_fft2_s": t_fft, "input_bytes": raw.echo.nbytes, "configs": rows,
            "workers": os.cpu_count()}


_CHILD_FULL = r"""
import json, sys, time, h5py, numpy as np
sys.path.insert(0, {repo!r})
from bench.bench_focus import _rs1_raw
from sarcli.io.raw import write_raw
raw = _rs1_raw({n}, {m})
write_raw({path!r}, raw)
"""


def bench_full(tmp: Path) -> dict:
    n, m = 23000, 6354
    raw_path = tmp / "full_raw.h5"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", _CHILD_FULL.format(repo=str(REPO), n=n, m=m, path=str(raw_path))],
                   check=True)
    t_write = time.perf_counter() - t0
    t0 = time.perf_counter()
    out = subprocess.run([str(Path(sys.executable).parent / "sarcli"), "focus", str(raw_path), "-o",
                          str(tmp / "full_slc.h5"), "--fdc", "-7044", "--fr", "-1775", "--json"],
                         check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rep = json.loads(out.stdout)
    return {"shape": [n, m], "raw_write_s": t_write, "focus_wall_s": wall, "focus_total_s": rep["timings_s"]["focus_s"],
            "timings": rep["timings_s"], "peak_rss_bytes": rep["peak_rss_bytes"],
            "n_blocks": rep["parameters"]["n_blocks"], "overlap_lines": rep["parameters"]["overlap_lines"]}


_CHILD_COMPILE = r"""
import time, sys
sys.path.insert(0, {repo!r})
from bench.bench_focus import _rs1_raw, _doppler
from sarcli.focus.rda import focus_rd
raw = _rs1_raw(512, 1600)
t0 = time.perf_counter(); focus_rd(raw, _doppler(), block_lines=2048); t1 = time.perf_counter()
focus_rd(raw, _doppler(), block_lines=2048); t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def bench_compile(tmp: Path) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp / "numba_cache"))
    out = subprocess.run([sys.executable, "-c", _CHILD_COMPILE.format(repo=str(REPO))], env=env, check=True,
                         capture_output=True, text=True)
    first, steady = (float(v) for v in out.stdout.split())
    out2 = subprocess.run([sys.executable, "-c", _CHILD_COMPILE.format(repo=str(REPO))], env=env, check=True,
                          capture_output=True, text=True)
    cached, _ = (float(v) for v in out2.stdout.split())
    return {"first_call_fresh_cache_s": first, "steady_state_s": steady, "compile_s": first - steady,
            "first_call_with_cache_s": cached}


def _measure(slc, raw) -> dict:
    from sarcli.focus.quality import measure_targets, truth_targets

    res = measure_targets(slc, truth_targets(raw.truth), truth_known=True)
    keys = ("irw_range_m", "irw_azimuth_m", "pslr_range_db", "pslr_azimuth_db", "islr_range_db", "islr_azimuth_db",
            "position_error_m")
    return {k: float(np.mean([r[k] for r in res])) for k in keys}


def bench_accuracy() -> dict:
    from sarcli.focus.bp_product import focus_bp
    from sarcli.focus.quality import TruthDoppler
    from sarcli.focus.rda import focus_rd
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    raw = simulate(load_scene(REPO / "samples" / "rs1_point.toml"))

    dop = TruthDoppler.of(raw)
    base = {"range_window": "rect", "azimuth_window": "rect"}
    configs = [("RD sinc8 x2 SRC f32 (default)", {}),
               ("RD nearest x2", {"rcmc": "nearest"}), ("RD linear x2", {"rcmc": "linear"}),
               ("RD sinc4 x2", {"rcmc": "sinc4"}), ("RD sinc16 x2", {"rcmc": "sinc16"}),
               ("RD sinc8 x1", {"rcmc_oversample": 1}), ("RD sinc16 x1", {"rcmc": "sinc16", "rcmc_oversample": 1}),
               ("RD sinc8 x2 no SRC", {"src": False}), ("RD sinc8 x2 float64", {"precision": "double"}),
               ("RD no orbit timing", {"orbit_timing": False})]
    rows = []
    focus_rd(raw, dop, **base)  # warm-up (compilation)
    for name, kw in configs:
        t0 = time.perf_counter()
        slc = focus_rd(raw, dop, **base, **kw)
        rows.append({"config": name, "seconds": time.perf_counter() - t0, **_measure(slc, raw)})
    # backprojection on 96 x 96 pixels around each target (the whole image would take hours)
    rd = focus_rd(raw, dop, **base)
    t_bp = 0.0
    res = []
    from sarcli.focus.quality import measure_targets, truth_targets

    for tz, r0 in truth_targets(raw.truth):
        row = int(round((tz - rd.azimuth_time[0]) * rd.prf_hz))
        col = int(round((r0 - rd.slant_range[0]) / rd.range_spacing_m))
        t0 = time.perf_counter()
        bp = focus_bp(raw, dop, lines=(row - 48, row + 48), samples=(col - 48, col + 48), **base)
        t_bp += time.perf_counter() - t0
        res += measure_targets(bp, [(tz, r0)], truth_known=True)
    keys = ("irw_range_m", "irw_azimuth_m", "pslr_range_db", "pslr_azimuth_db", "islr_range_db", "islr_azimuth_db",
            "position_error_m")
    rows.append({"config": "backprojection (3 x 96 x 96 px)", "seconds": t_bp,
                 **{k: float(np.mean([r[k] for r in res])) for k in keys}})
    return {"scene": "samples/rs1_point.toml (2048 x 2400, 3 targets, all effects), rect windows, true Doppler",
            "theory_rect": {"irw_range_m": 0.886 * C / (2 * 0.72135e12 * 41.74e-6), "pslr_db": -13.26,
                            "islr_db": -9.91},
            "rows": rows}


def bench_block_invariance() -> dict:
    from sarcli.doppler.api import estimate_doppler
    from sarcli.focus.quality import point_target_metrics, truth_targets
    from sarcli.focus.rda import focus_rd
    from sarcli.sim.scene import load_scene
    from sarcli.sim.stripmap import simulate

    raw = simulate(load_scene(REPO / "samples" / "rs1_point.toml"))
    dop = estimate_doppler(raw)
    res = {}
    for bl in (1024, 2048, 4096):
        slc = focus_rd(raw, dop, block_lines=bl)
        nv = slc.parameters["block_output_lines"]
        rows = []
        for tz, r0 in truth_targets(raw.truth):
            row = (tz - slc.azimuth_time[0]) * slc.prf_hz
            col = (r0 - slc.slant_range[0]) / slc.range_spacing_m
            b = min(int(round(row)) // nv, slc.doppler.block_time.size - 1)
            m = point_target_metrics(slc.image, row, col,
                                     azimuth_carrier=slc.doppler.fdc_hz[b, int(round(col))] / slc.prf_hz)
            rows.append((m["peak_amplitude"], m["peak_phase_rad"], m["row"] - row))
        res[bl] = (np.array(rows), slc.parameters["n_blocks"])
    ref = res[4096][0]
    out = {}
    for bl in (1024, 2048):
        m = res[bl][0]
        out[str(bl)] = {"n_blocks": res[bl][1],
                        "max_phase_diff_rad": float(np.max(np.abs(np.angle(np.exp(1j * (m[:, 1] - ref[:, 1])))))),
                        "max_amplitude_diff": float(np.max(np.abs(m[:, 0] / ref[:, 0] - 1))),
                        "max_position_diff_lines": float(np.max(np.abs(m[:, 2] - ref[:, 2])))}
    out["max_position_error_lines"] = float(max(np.max(np.abs(res[b][0][:, 2])) for b in res))
    return out


def _plot(acc: dict, path: Path) -> None:
    """Three panels against run time; each configuration is a numbered marker, named once in a shared
    legend below (labels written beside the points overlapped where the runs cluster)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    rows = acc["rows"]
    fig, axes = plt.subplots(1, 3, figsize=(14, 5.6))
    colours = plt.get_cmap("tab20")(np.linspace(0, 1, max(len(rows), 2)))
    handles = []
    for ax, key, label in ((axes[0], "pslr_range_db", "range PSLR (dB)"), (axes[1], "islr_range_db", "range ISLR (dB)"),
                           (axes[2], "position_error_m", "position error (m)")):
        for k, (r, c) in enumerate(zip(rows, colours, strict=False), start=1):
            h = ax.scatter(r["seconds"], r[key], color=c, s=70, edgecolor="k", lw=0.4, zorder=3,
                           label=f"{k}: {r['config'].replace('RD ', '')}")
            ax.text(r["seconds"], r[key], str(k), fontsize=6, ha="center", va="center", zorder=4)
            if ax is axes[0]:
                handles.append(h)
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("run time (s)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].axhline(-13.26, color="k", lw=0.6, ls="--", label="theory (rect)")
    axes[1].axhline(-9.91, color="k", lw=0.6, ls="--")
    axes[2].set_yscale("log")
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle("RD focusing: accuracy vs cost (rs1_point, rect windows; dashed: rect-window theory)")
    fig.tight_layout(rect=(0, 0.16, 1, 1))
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> None:
    quick = bool(os.environ.get("BENCH_FOCUS_QUICK"))
    data: dict = {}
    with tempfile.TemporaryDirectory() as td:
        tmp = Path(td)
        data["block"] = bench_block()
        data["compile"] = bench_compile(tmp)
        data["accuracy"] = bench_accuracy()
        data["block_invariance"] = bench_block_invariance()
        if not quick:
            data["full"] = bench_full(tmp)
    RESULTS.mkdir(parents=True, exist_ok=True)
    _plot(data["accuracy"], RESULTS / "bench_focus_accuracy.png")
    b = data["block"]
    md = ["## bench_focus", "",
          f"Machine: {os.cpu_count()} cores (shared; figures are ratios measured in the same run).",
          "", "### 1536 x 2048 block (one RD block, Radarsat-1 geometry, fdc -7044 Hz)", "",
          f"Two scipy.fft.fft2 passes (complex64, workers=-1): {b['two_fft2_s']:.4f} s (best of 7 rounds"
          " interleaved with the focus runs; each figure below is also the best of those 7 rounds).", ""]
    md.append(markdown_table(["config", "seconds", "x two fft2", "peak extra memory / input"],
                             [[k, v["seconds"], v["ratio_to_2fft2"], v["peak_extra_over_input"]]
                              for k, v in b["configs"].items()]))
    c = data["compile"]
    md += ["", "### numba compilation", "",
           f"First call with an empty cache {c['first_call_fresh_cache_s']:.2f} s, steady state "
           f"{c['steady_state_s']:.2f} s (compilation {c['compile_s']:.2f} s); first call with the on-disk cache "
           f"{c['first_call_with_cache_s']:.2f} s (512 x 1600 scene).", ""]
    if "full" in data:
        f = data["full"]
        md += ["### Full-size scene 23000 x 6354 (sarcli focus, streamed, --fdc/--fr)", "",
               f"Focus {f['focus_total_s']:.1f} s ({f['n_blocks']} blocks, overlap {f['overlap_lines']} lines), "
               f"peak RSS {f['peak_rss_bytes'] / 2**30:.2f} GiB.", ""]
    a = data["accuracy"]
    md += ["### Accuracy vs cost", "", a["scene"] + "; theory (rect): range IRW "
           f"{a['theory_rect']['irw_range_m']:.3f} m, PSLR -13.26 dB, ISLR -9.91 dB (20 half-widths).", ""]
    md.append(markdown_table(["config", "s", "IRW rg m", "IRW az m", "PSLR rg", "PSLR az", "ISLR rg", "ISLR az",
                              "pos. err m"],
                             [[r["config"], r["seconds"], r["irw_range_m"], r["irw_azimuth_m"], r["pslr_range_db"],
                               r["pslr_azimuth_db"], r["islr_range_db"], r["islr_azimuth_db"], r["position_error_m"]]
                              for r in a["rows"]]))
    md.append("\nPlot: bench/results/bench_focus_accuracy.png\n")
    bi = data["block_invariance"]
    md += ["### Block invariance (rs1_point, estimated Doppler, orbit timing; vs blocks of 4096 lines)", ""]
    md.append(markdown_table(["block lines", "blocks", "max phase diff rad", "max amplitude diff",
                              "max position diff lines"],
                             [[k, v["n_blocks"], v["max_phase_diff_rad"], v["max_amplitude_diff"],
                               v["max_position_diff_lines"]] for k, v in bi.items() if isinstance(v, dict)]))
    md.append(f"\nLargest azimuth position error against the truth, any block size: "
              f"{bi['max_position_error_lines']:.4f} line.\n")
    write_results("bench_focus", "\n".join(md), json.loads(json.dumps(data, default=float)))


if __name__ == "__main__":
    main()
