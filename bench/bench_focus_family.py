"""The accuracy-versus-time map of the registered focusers (``make bench``; docs/focusing.md, "Which algorithm?").

Scenes (:mod:`bench.family`): point targets with only the effects the map needs, across carrier
(L 1.27, C 5.3, X 9.6 GHz), squint (0-40 deg), platform (spaceborne ~5 m on an orbit, airborne ~0.3 m
on a straight line) and relative bandwidth (airborne X band, 150-1000 MHz). A scene whose raw block
would exceed ``MAX_SAMPLES`` is not made (the raw window must hold R0 and R0 / cos(theta): it grows as
R0 (1 / cos(theta) - 1)); the model's prediction is still given for it.

For every registered focuser with an entry in :data:`sarcli.focus.select.KNOB_SETTINGS` (each knob
setting on the ``KNOB_SCENES``, the focuser's own defaults elsewhere; whole-image ``ffbp`` up to
``TIME_DOMAIN_MAX_SAMPLES``, 0.6 M), against exact backprojection of the same lines on a 64 x 64
window around each target (:func:`bench.family.exact_chip`): range/azimuth IRW (ratio - 1), PSLR and
ISLR (dB difference), peak phase (rad) and position (pixels); the exact IRW against window theory;
time as a ratio to two ``scipy.fft.fft2`` of the same raw block (complex64) in the same run
(interleaved; rd best of 2; backprojection: the exact kernel's time per pixel and line, extrapolated
to the whole block); peak memory (tracemalloc) over the raw block; beside each measurement the
model's prediction (:func:`sarcli.focus.select.predict`) and both verdicts against the default
quality. Calibration for ``sarcli.focus.select`` (printed, not written into it): the median RD
ratio, the backprojection cost constant and the two-fft2 seconds per (sample x log2 samples).

Run: ``python -m bench.run_all bench_focus_family`` (9 minutes on 2 quiet cores with all five focusers, 24 scenes).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
import tracemalloc

import numpy as np
import scipy.fft as sfft

from bench.common import RESULTS, markdown_table, write_results
from bench.family import (
    CHIP,
    EXPOSURE,
    PLATFORMS,
    Case,
    compare,
    exact_chip,
    make_scene,
    pixel_of,
    scene_size,
    window_irw,
)

MAX_SAMPLES = 60_000_000
#: the scenes on which every knob setting of KNOB_SETTINGS runs; elsewhere each focuser runs with its own
#: defaults (the knob sweep on every scene would take the bench past half an hour once csa, omegak and
#: ffbp are registered)
KNOB_SCENES = ("C spaceborne 5 deg B=30 MHz", "X airborne 10 deg B=500 MHz")
#: whole-image time-domain focusers (ffbp) only on scenes up to this many samples (time)
TIME_DOMAIN_MAX_SAMPLES = 600_000
SQUINTS = (0.0, 5.0, 10.0, 20.0, 30.0, 40.0)
WINDOWS = {"range_window": "kaiser:2.5", "azimuth_window": "kaiser:2.5"}


def cases() -> list[Case]:
    if os.environ.get("BENCH_FAMILY_QUICK"):
        return [Case("C", "spaceborne", 0.0), Case("X", "airborne", 10.0), Case("C", "spaceborne", 40.0)]
    out = [Case(b, "spaceborne", s) for b in ("L", "C", "X") for s in SQUINTS]
    out += [Case(b, "airborne", s) for b in ("C", "X") for s in SQUINTS]
    out += [Case("X", "airborne", 5.0, range_bandwidth_hz=bw) for bw in (150e6, 1000e6)]
    return out


def _geometry(scene, case: Case):
    from sarcli.focus.select import geometry_of

    g = geometry_of(scene.raw, scene.raw.echo.shape, scene.doppler, WINDOWS)
    return dataclasses.replace(g, exposure_bandwidth_hz=EXPOSURE * PLATFORMS[case.platform]["ba"])


def _time_pair(fn, x: np.ndarray, rounds: int = 2) -> tuple[float, float]:
    """(best seconds of fn, best seconds of two fft2 of x), interleaved."""
    t_fn = t_fft = float("inf")
    for _ in range(rounds):
        t0 = time.perf_counter()
        sfft.fft2(x, workers=-1)
        sfft.fft2(x, workers=-1)
        t_fft = min(t_fft, time.perf_counter() - t0)
        t0 = time.perf_counter()
        fn()
        t_fn = min(t_fn, time.perf_counter() - t0)
    return t_fn, t_fft


def _peak_memory(fn):
    """(fn's result, peak traced bytes while it ran)."""
    tracemalloc.start()
    try:
        out = fn()
        return out, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def run_case(case: Case) -> dict:
    from sarcli.focus import FOCUSERS
    from sarcli.focus.base import focus_in_memory
    from sarcli.focus.select import KNOB_SETTINGS, TIME_DOMAIN, Quality, meets, predict

    q = Quality()
    scene = make_scene(case)
    raw = scene.raw
    geom = _geometry(scene, case)
    nl, nr = raw.echo.shape
    rec = {"case": case.name, "band": case.band, "platform": case.platform, "track": case.track,
           "squint_deg": case.squint_deg, "relative_bandwidth": geom.relative_bandwidth, "shape": [nl, nr],
           "aperture_lines": scene.aperture_lines, "fdc_hz": scene.fdc, "rows": [],
           "bandwidth_sweep": case.range_bandwidth_hz is not None}
    # exact reference on a window around each target (placed on the RD grid)
    from sarcli.focus.rda import plan_grid

    grid = plan_grid(raw, (nl, nr), scene.doppler, None)
    t_out, ranges = grid.zero_doppler_times(raw.azimuth_time), grid.ranges
    refs, bp_seconds = [], 0.0
    for tgt in scene.targets:
        row, col = pixel_of(t_out, ranges, tgt)
        r0, c0 = int(round(row)) - CHIP // 2, int(round(col)) - CHIP // 2
        chip, s = exact_chip(scene, r0, c0, WINDOWS["azimuth_window"])
        bp_seconds += s
        refs.append((tgt, row - r0, col - c0, r0, c0, chip))
    x = raw.echo.copy()
    irw_theory = window_irw(WINDOWS["range_window"])
    exact_irw = []
    for _, row, col, _, _, chip in refs:
        from bench.family import chip_metrics

        m = chip_metrics(chip, row, col, scene.fdc, raw.radar.prf_hz)
        exact_irw.append((m["irw_range_px"] / (irw_theory * raw.radar.range_sampling_rate_hz / geom.range_bandwidth_hz),
                          m["irw_azimuth_px"] / (window_irw(WINDOWS["azimuth_window"]) * grid.prf / grid.ba)))
    rec["exact_irw_over_theory"] = [float(np.max([e[0] for e in exact_irw])), float(np.max([e[1] for e in exact_irw]))]
    t0 = time.perf_counter()
    sfft.fft2(x, workers=-1)
    sfft.fft2(x, workers=-1)
    t_fft_once = time.perf_counter() - t0
    # the kernel visits every line of the scene per pixel (outside the band it stops early); the
    # backprojection focuser reads about an exposure's lines per output line: the full block's estimate
    per_pixel_line = bp_seconds / (len(refs) * CHIP * CHIP * nl)
    registered = FOCUSERS.names()
    for alg, table in KNOB_SETTINGS.items():
        if alg not in registered:
            continue
        settings = table if (case.name in KNOB_SCENES or alg in ("rd", "backprojection")) else [{}]
        for knobs in settings:
            pred = predict(alg, knobs, geom, ranges=tuple(t[1] for t, *_ in refs))
            row_rec = {"algorithm": alg, "knobs": knobs, "predicted": pred, "predicted_meets": meets(pred, q)}
            if alg == "backprojection":
                t_full = per_pixel_line * nl * nr * scene.aperture_lines * EXPOSURE
                rec["bp_full_s"] = t_full
                row_rec.update({"measured": {"irw_range": 0.0, "irw_azimuth": 0.0, "pslr_range_db": 0.0,
                                             "pslr_azimuth_db": 0.0, "islr_range_db": 0.0, "islr_azimuth_db": 0.0,
                                             "phase_rad": 0.0, "d_row": 0.0, "d_col": 0.0},
                                "meets": True, "ratio_to_2fft2": t_full / t_fft_once, "extrapolated": True,
                                "peak_memory_over_input": None, "note": "the reference itself"})
                rec["rows"].append(row_rec)
                continue
            focuser = FOCUSERS.get(alg)
            opts = {**WINDOWS, **knobs}
            try:
                from sarcli.focus.base import options_for

                options_for(focuser, opts)
            except Exception as e:  # noqa: BLE001 - a knob table the focuser does not know: said, skipped
                row_rec["note"] = f"skipped: {e}"
                rec["rows"].append(row_rec)
                continue

            if alg in TIME_DOMAIN and nl * nr > TIME_DOMAIN_MAX_SAMPLES:
                row_rec["note"] = f"skipped: whole-image {alg} on {nl} x {nr} is beyond the bench's time"
                rec["rows"].append(row_rec)
                continue

            def run(focuser=focuser, opts=opts):
                return focus_in_memory(focuser, raw, scene.doppler, opts)

            slc, peak = _peak_memory(run)  # the image measured is the one whose memory was traced
            errs = []
            for _, row, col, r0, c0, chip in refs:
                errs.append(compare(slc.image[r0:r0 + CHIP, c0:c0 + CHIP], chip, row, col, scene.fdc,
                                    raw.radar.prf_hz))
            worst = {k: max((e[k] for e in errs), key=abs) for k in errs[0] if not isinstance(errs[0][k], dict)}
            worst = {k: float(v) for k, v in worst.items()}
            t_fn, t_fft = _time_pair(run, x, rounds=2 if alg == "rd" else 1)
            ok = (max(abs(worst["irw_range"]), abs(worst["irw_azimuth"])) <= q.irw
                  and max(abs(worst["pslr_range_db"]), abs(worst["pslr_azimuth_db"])) <= q.pslr_db
                  and abs(worst["phase_rad"]) <= q.phase_rad)
            row_rec.update({"measured": worst, "meets": bool(ok), "ratio_to_2fft2": t_fn / t_fft, "seconds": t_fn,
                            "two_fft2_s": t_fft, "extrapolated": False,
                            "peak_memory_over_input": peak / raw.echo.nbytes})
            rec["rows"].append(row_rec)
    rec["two_fft2_s"] = t_fft_once
    rec["bp_seconds_per_pixel_line"] = per_pixel_line
    return rec


def limits(results: list[dict]) -> list[list]:
    """Per (algorithm, band, platform): the smallest squint where the measured verdict fails, and
    where the model's fails (over the squints measured), and the largest squint measured."""
    out = []
    series: dict[tuple, list] = {}
    for r in results:
        if r.get("skipped") or r.get("bandwidth_sweep"):
            continue
        for row in r["rows"]:
            if "measured" not in row:
                continue
            series.setdefault((row["algorithm"], json.dumps(row["knobs"]), r["band"], r["platform"]), []).append(
                (r["squint_deg"], row["meets"], row["predicted_meets"]))
    for (alg, knobs, band, plat), pts in sorted(series.items()):
        pts.sort()
        meas = next((s for s, m, _ in pts if not m), None)
        pred = next((s for s, _, p in pts if not p), None)
        out.append([alg, knobs, band, plat, "-" if meas is None else meas, "-" if pred is None else pred,
                    max(s for s, _, _ in pts)])
    return out


def _plot(results: list[dict], path) -> None:
    """Four panels against squint: the worst |PSLR change|, |peak phase error| and |IRW change| of each
    focuser against exact backprojection (measured: o, predicted: x; dashed: the default quality) and its
    time in two fft2 of the block (backprojection: extrapolated)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(19, 4.8))
    keys = (("pslr", "worst |PSLR change| (dB)", 1.0), ("phase", "|peak phase error| (rad)", 0.1),
            ("irw", "worst |IRW change| (%)", 2.0))
    styles: dict[str, int] = {}
    for r in results:
        if r.get("bandwidth_sweep") or r.get("skipped"):
            continue
        for row in r["rows"]:
            if "measured" not in row:
                continue
            label = f"{row['algorithm']} {json.dumps(row['knobs']) if row['knobs'] else ''} {r['band']} {r['platform']}"
            new = label not in styles
            styles.setdefault(label, len(styles))
            c = plt.get_cmap("tab20")(styles[label] % 20)
            axes[3].scatter(r["squint_deg"], row["ratio_to_2fft2"], color=c, marker="s" if row.get("extrapolated")
                            else "o", label=label if new else None)
            if row["algorithm"] == "backprojection":
                continue
            m, p = row["measured"], row["predicted"]
            vals = {"pslr": (max(abs(m["pslr_range_db"]), abs(m["pslr_azimuth_db"])), p["pslr_db"]),
                    "phase": (abs(m["phase_rad"]), p["phase_rad"]),
                    "irw": (100 * max(abs(m["irw_range"]), abs(m["irw_azimuth"])), 100 * p["irw"])}
            for ax, (k, _, _) in zip(axes, keys, strict=False):
                ax.scatter(r["squint_deg"], max(vals[k][0], 1e-4), color=c, marker="o")
                ax.scatter(r["squint_deg"], max(vals[k][1], 1e-4), color=c, marker="x")
    for ax, (_, lab, lim) in zip(axes, keys, strict=False):
        ax.axhline(lim, color="k", ls="--", lw=0.7)
        ax.set_ylabel(lab)
    axes[3].set_ylabel("time / two fft2 of the block (squares: extrapolated)")
    for ax in axes:
        ax.set_yscale("log")
        ax.set_xlabel("squint (deg)")
        ax.grid(alpha=0.3)
    axes[3].legend(fontsize=6, loc="center left", bbox_to_anchor=(1.0, 0.5))
    fig.suptitle("Focusers against exact backprojection: measured (o) and predicted by sarcli.focus.select (x); "
                 "dashed: the default quality")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _fmt(x: float, nd: int = 3) -> str:
    return f"{x:.{nd}g}"


def main() -> None:
    from sarcli.focus import FOCUSERS
    from sarcli.focus.select import KNOB_SETTINGS, Quality

    q = Quality()
    t_start = time.perf_counter()
    results = []
    for case in cases():
        size = scene_size(case)
        if size > MAX_SAMPLES:
            results.append({"case": case.name, "band": case.band, "platform": case.platform,
                            "squint_deg": case.squint_deg, "relative_bandwidth": 0.0, "skipped": True,
                            "estimated_samples": size})
            continue
        t0 = time.perf_counter()
        rec = run_case(case)
        rec["wall_s"] = time.perf_counter() - t0
        print(f"{case.name}: {rec['shape']} in {rec['wall_s']:.1f} s", flush=True)
        results.append(rec)
    done = [r for r in results if not r.get("skipped")]
    rd = [row["ratio_to_2fft2"] for r in done for row in r["rows"]
          if row["algorithm"] == "rd" and "ratio_to_2fft2" in row]
    cal = {"rd_ratio_median": float(np.median(rd)) if rd else None,
           # COST_BP: predicted_cost = COST_BP * aperture_lines / log2(n)
           "bp_cost_constant_median": float(np.median([r["bp_full_s"] / r["two_fft2_s"]
                                                       * math.log2(r["shape"][0] * r["shape"][1]) / r["aperture_lines"]
                                                       for r in done if "bp_full_s" in r])),
           "seconds_2fft2_per_n_log2n": float(np.median([r["two_fft2_s"] / (r["shape"][0] * r["shape"][1]
                                                                             * math.log2(r["shape"][0] * r["shape"][1]))
                                                         for r in done]))}
    missing = [a for a in KNOB_SETTINGS if a not in FOCUSERS.names()]
    rows = []
    for r in done:
        for row in r["rows"]:
            if "measured" not in row:
                rows.append([r["case"], row["algorithm"], json.dumps(row["knobs"]) if row["knobs"] else "-",
                             row.get("note", ""), "", "", "", "", "", "", ""])
                continue
            m, p = row["measured"], row["predicted"]
            rows.append([r["case"], row["algorithm"], json.dumps(row["knobs"]) if row["knobs"] else "-",
                         f"{100 * m['irw_range']:+.2f} / {100 * m['irw_azimuth']:+.2f}",
                         f"{m['pslr_range_db']:+.2f} / {m['pslr_azimuth_db']:+.2f}",
                         f"{m['phase_rad']:+.3f}", f"{m['d_col']:+.3f} / {m['d_row']:+.3f}",
                         _fmt(row["ratio_to_2fft2"]) + (" (extrap.)" if row.get("extrapolated") else ""),
                         "-" if row["peak_memory_over_input"] is None else _fmt(row["peak_memory_over_input"]),
                         "yes" if row["meets"] else "no",
                         f"{'yes' if row['predicted_meets'] else 'no'} ({100 * p['irw']:.1f} %, {p['pslr_db']:.2f} dB, "
                         f"{p['phase_rad']:.3f} rad)"])
    md = ["# Accuracy-versus-time map of the focusers", "",
          f"Scenes: point targets (bench/family.py), Kaiser 2.5 windows, against exact backprojection on 64 x 64 "
          f"windows; {len(done)} scenes measured, {len(results) - len(done)} beyond {MAX_SAMPLES / 1e6:g} M samples "
          f"(listed below); {time.perf_counter() - t_start:.0f} s on {os.cpu_count()} cores (shared).", "",
          "IRW: image / exact - 1 (range / azimuth, %); PSLR: image - exact (dB); phase: peak phase difference; "
          "position: peak offset (range / azimuth, pixels); time: whole focus / two fft2 of the raw block (same "
          "run); memory: tracemalloc peak / raw block; meets: the default quality (IRW 2 %, PSLR 1 dB, phase "
          "0.1 rad); predicted: sarcli.focus.select's verdict (worst IRW, PSLR, phase).", ""]
    md.append(markdown_table(["scene", "algorithm", "knobs", "IRW % rg / az", "PSLR dB rg / az", "phase rad",
                              "position px rg / az", "x two fft2", "memory / input", "meets", "predicted"], rows))
    md += ["", "## Where each algorithm stops meeting the quality (first failing squint, measured and predicted)", ""]
    md.append(markdown_table(["algorithm", "knobs", "band", "platform", "measured", "predicted",
                              "largest squint measured"], limits(results)))
    md += ["", "## Exact backprojection against window theory (IRW / theory, worst of range and azimuth)", ""]
    md.append(markdown_table(["scene", "shape", "aperture lines", "range", "azimuth"],
                             [[r["case"], f"{r['shape'][0]} x {r['shape'][1]}", _fmt(r["aperture_lines"]),
                               _fmt(r["exact_irw_over_theory"][0], 4), _fmt(r["exact_irw_over_theory"][1], 4)]
                              for r in done]))
    md += ["", "## Scenes beyond the budget (not made)", ""]
    md.append(markdown_table(["scene", "estimated samples"], [[r["case"], r["estimated_samples"]] for r in results
                                                              if r.get("skipped")]))
    md += ["", "## Not registered in this run (their knob settings are in sarcli.focus.select.KNOB_SETTINGS)", "",
           ", ".join(missing) if missing else "none", "",
           "## Calibration for sarcli.focus.select", "",
           f"RD / two fft2, median: {_fmt(cal['rd_ratio_median'] or float('nan'))}; backprojection constant "
           f"(s per pixel-line over s per sample-log2 of two fft2): {_fmt(cal['bp_cost_constant_median'])}; "
           f"two fft2 seconds per n log2 n: {cal['seconds_2fft2_per_n_log2n']:.3g}.", "",
           "Plot: bench/results/bench_focus_family.png (docs/images/focus_family_map.png)", ""]
    RESULTS.mkdir(parents=True, exist_ok=True)
    _plot(done, RESULTS / "bench_focus_family.png")
    write_results("bench_focus_family", "\n".join(md), json.loads(json.dumps(
        {"quality": dataclasses.asdict(q), "calibration": cal, "results": results}, default=float)))


if __name__ == "__main__":
    main()
