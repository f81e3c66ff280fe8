"""Fast factorized backprojection against the exact backprojection, same run, same inputs [UlaHelSte2003].

1. GOTCHA pass 1 HH (``../shared/data/gotcha_pass1_hh``): the 100 m x 100 m scene on a 0.1 m grid
   (1001 x 1001 pixels, 469 pulses) through the grid backprojection (numba kernel of
   :mod:`sarcli.gbsar.backprojection`) and :func:`sarcli.gbsar.ffbp.ffbp_grid` at several knob settings
   (best of 2 after a warm-up each): time, ratio to BP, and against BP at the point-like bright returns
   (local maxima 4 m apart whose BP PSLR is below -13 dB along both cuts): peak position (pixels),
   PSLR, peak amplitude and phase; and the largest difference over the image (of the peak).
2. The Radarsat-1-like stripmap scene (``samples/rs1_point.toml``, orbit, rotating Earth, no noise):
   256 x 256 pixels around the first target by ``focus --algorithm backprojection`` and ``ffbp``
   (range compression and upsampling included in both), the same metrics.

Timings on the shared 2-core machine: ratios within one run are what count.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.common import best_time, markdown_table, write_results
from sarcli.focus.ffbp import FfbpKnobs
from sarcli.focus.quality import TruthDoppler, point_target_metrics

REPO = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("SARCLI_SHARED", REPO.parent / "shared")) / "data" / "gotcha_pass1_hh"
KNOBS = [("default (base 4, beta 2, 6 x 6 taps, U 2)", FfbpKnobs()),
         ("base 8", FfbpKnobs(base=8)),
         ("4 x 4 taps", FfbpKnobs(order=4, range_order=4)),
         ("beta 1.5, 8 x 8 taps, U 1.5", FfbpKnobs(oversample=1.5, order=8, range_order=8, range_oversample=1.5)),
         ("beta 3, 8 x 8 taps, U 3", FfbpKnobs(oversample=3.0, order=8, range_order=8, range_oversample=3.0))]


def compare_images(bp: np.ndarray, ff: np.ndarray, cells) -> dict:
    """``ff`` against the reference ``bp`` at the point-like returns ``cells`` (row, column): the largest peak
    position difference (pixels), PSLR difference (dB, both cuts), relative amplitude and phase differences,
    and the largest difference over the image (of the reference's peak)."""
    mb = [point_target_metrics(bp, *c, half=32) for c in cells]
    mf = [point_target_metrics(ff, *c, half=32) for c in cells]
    pairs = list(zip(mf, mb, strict=True))
    return {"position_px": max(max(abs(f["row"] - b["row"]), abs(f["col"] - b["col"])) for f, b in pairs),
            "pslr_db": max(abs(f[f"pslr_{a}_db"] - b[f"pslr_{a}_db"]) for f, b in pairs
                           for a in ("range", "azimuth")),
            "amplitude": max(abs(f["peak_amplitude"] / b["peak_amplitude"] - 1) for f, b in pairs),
            "phase_rad": max(abs(np.angle(np.exp(1j * (f["peak_phase_rad"] - b["peak_phase_rad"]))))
                             for f, b in pairs),
            "max_difference": float(np.abs(ff - bp).max() / np.abs(bp).max())}


def point_like(img: np.ndarray, n: int = 12, apart: int = 40) -> list[tuple[int, int]]:
    """The ``n`` brightest local maxima ``apart`` pixels apart (and from the edges) whose PSLR is below -13 dB
    along both cuts (isolated point-like returns)."""
    a = np.abs(img)
    cells: list[tuple[int, int]] = []
    for k in np.argsort(a, axis=None)[::-1]:
        r, c = (int(v) for v in np.unravel_index(k, a.shape))
        if min(r, c) < apart or max(r, c) > min(a.shape) - apart or any(np.hypot(r - p, c - q) < apart
                                                                       for p, q in cells):
            continue
        cells.append((r, c))
        if len(cells) == n:
            break
    return [c for c in cells if max(point_target_metrics(img, *c, half=32)[f"pslr_{x}_db"]
                                    for x in ("range", "azimuth")) < -13]


def bench_gotcha() -> dict | None:
    from sarcli.gbsar.backprojection import backproject_grid
    from sarcli.gbsar.ffbp import ffbp_grid
    from sarcli.gbsar.rangecomp import range_compress
    from sarcli.io.scan import read_scan
    from sarcli.workflows import gbsar_import

    files = sorted(DATA.glob("data_3dsar_pass1_az00?_HH.mat"))
    if len(files) != 4:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        gbsar_import.run(gbsar_import.Config(inputs=tuple(files), output=Path(tmp) / "g.h5"))
        scan = read_scan(Path(tmp) / "g.h5")
    prof = range_compress(scan, "HH", "hamming", 4, centred=True)
    ant, ref = scan.antenna_xyz(), scan.reference_range
    xs = np.arange(-50.0, 50.0 + 1e-9, 0.1)
    bp, _ = backproject_grid(prof, ant, ref, xs, xs, 0.0, "hamming")
    t_bp = best_time(lambda: backproject_grid(prof, ant, ref, xs, xs, 0.0, "hamming"), repeat=2, warmup=0)
    cells = point_like(bp)
    rows = []
    for name, kn in KNOBS:
        stats: dict = {}
        ff, _ = ffbp_grid(prof, ant, ref, xs, xs, 0.0, "hamming", kn, stats=stats)
        t = best_time(lambda kn=kn: ffbp_grid(prof, ant, ref, xs, xs, 0.0, "hamming", kn), repeat=2, warmup=0)
        rows.append({"knobs": name, "seconds": t, "bp_over_ffbp": t_bp / t, "merge_stages": stats["merge_stages"],
                     "polar_samples": stats["polar_samples"], **compare_images(bp, ff, cells)})
    return {"pixels": [xs.size, xs.size], "pulses": int(ant.shape[0]), "bp_seconds": t_bp, "points": cells,
            "rows": rows}


def bench_stripmap() -> dict:
    from sarcli.focus.bp_product import focus_bp
    from sarcli.focus.ffbp_product import focus_ffbp
    from sarcli.focus.quality import truth_targets
    from sarcli.focus.rda import plan_grid
    from sarcli.sim.scene import parse_scene
    from sarcli.sim.stripmap import simulate

    text = (REPO / "samples" / "rs1_point.toml").read_text()
    raw = simulate(parse_scene(text.replace('"chirp_replica", "noise", "quantization"]', '"chirp_replica"]')))

    dop = TruthDoppler.of(raw)
    tz, r0 = truth_targets(raw.truth)[0]
    g = plan_grid(raw, raw.echo.shape, dop, None)
    row = int(round(np.interp(tz, g.zero_doppler_times(raw.azimuth_time), np.arange(raw.azimuth_time.size))))
    col = int(round((r0 - g.ranges[0]) / (g.ranges[1] - g.ranges[0])))
    win = {"lines": (row - 128, row + 128), "samples": (col - 128, col + 128), "range_window": "kaiser:2.5",
           "azimuth_window": "kaiser:2.5"}
    focus_ffbp(raw, dop, **{**win, "lines": (row - 8, row + 8), "samples": (col - 8, col + 8)})  # compile
    t0 = time.perf_counter()
    bp = focus_bp(raw, dop, **win)
    t_bp = time.perf_counter() - t0
    rows = []
    for name, kw in (("default (aperture_split 16)", {}), ("aperture_split 4", {"aperture_split": 4}),
                     ("beta 3, 8 x 8 taps", {"oversample": 3.0, "order": 8, "range_order": 8})):
        t0 = time.perf_counter()
        ff = focus_ffbp(raw, dop, **win, **kw)
        t = time.perf_counter() - t0
        rows.append({"knobs": name, "seconds": t, "bp_over_ffbp": t_bp / t,
                     "top_lines": ff.parameters["ffbp_top_lines"], **compare_images(bp.image, ff.image, [(128, 128)])})
    return {"pixels": [256, 256], "aperture_lines": ff.parameters["ffbp_aperture_lines"], "bp_seconds": t_bp,
            "rows": rows}


def _table(rows: list[dict]) -> str:
    return markdown_table(
        ["knobs", "time s", "BP / FFBP", "position px", "PSLR dB", "amplitude", "phase rad", "max diff / peak"],
        [[r["knobs"], r["seconds"], r["bp_over_ffbp"], r["position_px"], r["pslr_db"], r["amplitude"], r["phase_rad"],
          r["max_difference"]] for r in rows])


def main() -> None:
    load = os.getloadavg()[0]
    got = bench_gotcha()
    strip = bench_stripmap()
    md = [f"# FFBP against the exact backprojection\n\nRun {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"2 shared cores, load average {load:.1f} (timings under load: compare the ratios).\n\n"]
    if got is None:
        md.append("GOTCHA: skipped (files not found).\n\n")
    else:
        md.append(f"## GOTCHA pass 1 HH, {got['pixels'][0]} x {got['pixels'][1]} pixels, {got['pulses']} pulses\n\n"
                  f"Exact grid backprojection (numba): {got['bp_seconds']:.2f} s. Differences to it at "
                  f"{len(got['points'])} point-like returns (largest over them).\n\n" + _table(got["rows"]) + "\n\n")
    md.append(f"## Stripmap, Radarsat-1-like scene, 256 x 256 pixels (aperture {strip['aperture_lines']:.0f} lines)\n\n"
              f"`backprojection`: {strip['bp_seconds']:.2f} s (range compression and upsampling included, as in "
              "FFBP's times).\n\n" + _table(strip["rows"]) + "\n")
    write_results("bench_ffbp", "".join(md), {"load_average": load, "gotcha": got, "stripmap": strip})


if __name__ == "__main__":
    main()
