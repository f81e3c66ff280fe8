"""Monitoring campaign store (docs/monitoring.md): the incremental update's cost against the number of scans
already stored (up to 1,000), and the offline rebuild (``gbsar series``) against a serial loop.

1. Incremental update: a campaign on the landslide sample's grid (162 x 111 pixels, one image focused
   from the sample) fed 1,000 synthetic scans 10 minutes apart (the first image with a moving area,
   a refractivity drift and noise applied): each ``Campaign.process`` is the monitor's full per-scan
   work after focusing: update, epoch file (fsynced), alarm log, state file (fsynced, the commit) and
   the live page. Wall and CPU time per scan, median over bins of scans; the state and epoch file
   sizes. Flat means the last bin costs what the first does.
2. Rebuild vs serial loop: 43 simulated scans of the landslide sample on disk; the serial loop is
   what the monitor does per scan (read, focus, update, commit, page); the rebuild focuses in worker
   processes and commits every 50 scans. Wall and CPU (this process plus its children) times.

Run: ``python -m bench.bench_monitor`` (about 3 to 10 min on the shared 2-core machine).
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.common import markdown_table, write_results

REPO = Path(__file__).resolve().parents[1]
N_SCANS = 1000
BINS = ((2, 11), (91, 111), (491, 511), (981, 1001))


def synthetic_images(first: np.ndarray, static, n: int):
    """Scan k: the first image moved by 0.3 mm/h over the slide's polygon and 0.05 mm/h elsewhere in
    range, a refractivity drift of 0.5 ppm per scan, and noise 30 dB under each pixel."""
    from sarcli.monitor.geometry import inside_polygon

    lam = static.wavelength_m
    rng_map = static.slant_range()
    rr, xx = np.meshgrid(static.ranges, static.azimuths, indexing="ij")
    slide = inside_polygon(xx, rr, ((-10.0, 204.0), (8.0, 204.0), (8.0, 241.0), (-10.0, 241.0)))
    amp = np.abs(first)
    for k in range(n):
        t_h = k / 6.0
        d_mm = np.where(slide, 0.3 * t_h, 0.0)
        dn = 0.5 * k
        phase = -4 * np.pi / lam * (d_mm * 1e-3 + 1e-6 * dn * rng_map)
        noise = np.random.default_rng(k).standard_normal((2, *first.shape)) * (amp * 10 ** (-30 / 20) / np.sqrt(2))
        yield (first * np.exp(1j * phase) + noise[0] + 1j * noise[1]).astype(np.complex64), t_h


def incremental(work: Path) -> dict:
    from sarcli.gbsar.scene import load_scene
    from sarcli.gbsar.simulate import simulate
    from sarcli.monitor.campaign import Campaign, focus, geometry
    from sarcli.monitor.config import load_monitor_config

    cfg = load_monitor_config(REPO / "samples" / "monitor.toml")
    scan = simulate(load_scene(REPO / "samples" / "gbsar_landslide.toml"))
    img = focus(scan, cfg)
    root = work / "incremental"
    page_cpu: list[float] = []

    class Timed(Campaign):
        def write_page(self) -> None:
            c0 = time.process_time()
            super().write_page()
            page_cpu.append(time.process_time() - c0)

    camp = Timed(root, cfg)
    camp.open()
    t0 = 1_777_615_200.0
    camp.first_image(img, geometry(scan), t0)
    wall, cpu = [], []
    for k, (z, t_h) in enumerate(synthetic_images(np.asarray(img.image[0]), camp.static, N_SCANS), start=1):
        w0, c0 = time.perf_counter(), time.process_time()
        camp.process(k, z, t0 + t_h * 3600)
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    rows = []
    for a, b in BINS:
        sl = slice(a - 1, b - 1)
        page = np.array(page_cpu[sl])
        rows.append({"scans": f"{a}-{b - 1}", "wall_ms": 1e3 * float(np.median(wall[sl])),
                     "cpu_ms": 1e3 * float(np.median(cpu[sl])),
                     "store_cpu_ms": 1e3 * float(np.median(np.array(cpu[sl]) - page)),
                     "page_cpu_ms": 1e3 * float(np.median(page))})
    st = camp.state
    return {"rows": rows, "state_bytes": (root / "store" / "state.h5").stat().st_size,
            "epoch_bytes": (root / "store" / "epochs" / f"scan_{N_SCANS:05d}.h5").stat().st_size,
            "page_bytes": (root / "index.html").stat().st_size, "accepted": st.n_accepted,
            "rejected": st.n_rejected, "n_points": st.last_record["n_points"], "grid": list(camp.static.shape),
            "wall_s": wall, "cpu_s": cpu}


def rebuild_vs_serial(work: Path) -> dict:
    from sarcli.monitor.campaign import Campaign
    from sarcli.monitor.config import load_monitor_config
    from sarcli.workflows import gbsar_series
    from tests.monitor.conftest import simulate_scans

    src = work / "scans43"
    simulate_scans(src, 43)
    scans = sorted((src / "scans").glob("scan_*.h5"))
    cfg = load_monitor_config(REPO / "samples" / "monitor.toml")
    out = {}
    w0, c0 = time.perf_counter(), time.process_time()
    camp = Campaign(work / "serial", cfg)
    camp.open()
    for k, p in enumerate(scans, start=1):
        camp.process_file(k, p)
    out["serial loop (monitor's per-scan work)"] = (time.perf_counter() - w0, time.process_time() - c0)
    for jobs in (1, 2):
        w0, c0 = time.perf_counter(), time.process_time()
        gbsar_series.run(gbsar_series.Config(inputs=tuple(scans), config=REPO / "samples" / "monitor.toml",
                                             out=work / f"series{jobs}", jobs=jobs))
        out[f"gbsar series --jobs {jobs}"] = (time.perf_counter() - w0, time.process_time() - c0)
    return out


def main() -> None:
    load0 = os.getloadavg()[0]
    work = Path(tempfile.mkdtemp(prefix="bench_monitor_"))
    try:
        inc = incremental(work)
        reb = rebuild_vs_serial(work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    load1 = os.getloadavg()[0]
    md = ["# bench_monitor: campaign store, incremental update and rebuild\n\n",
          f"Load average {load0:.1f} -> {load1:.1f} on the shared 2-core machine (wall times are pessimistic and "
          "vary with the load; CPU times are this process's).\n\n",
          f"## Incremental update vs scans stored ({N_SCANS} scans, grid {inc['grid'][0]} x {inc['grid'][1]}, "
          f"{inc['n_points']} points at the end)\n\n",
          "Per scan: update + epoch file + alarm log + state commit (fsync + rename) + live page; median of each "
          "bin. CPU of this process (`time.process_time`), split into the store's part and the page's (whose "
          "time series grow to 600 points per series, then stay there).\n\n",
          markdown_table(["scans already stored", "wall (ms)", "CPU (ms)", "store CPU (ms)", "page CPU (ms)"],
                         [[r["scans"], r["wall_ms"], r["cpu_ms"], r["store_cpu_ms"], r["page_cpu_ms"]]
                          for r in inc["rows"]]),
          f"\nState file {inc['state_bytes'] / 1e6:.2f} MB (the same after any number of scans), epoch file "
          f"{inc['epoch_bytes'] / 1e6:.2f} MB per scan, page {inc['page_bytes'] / 1e3:.0f} kB; "
          f"{inc['accepted']} accepted, {inc['rejected']} rejected.\n\n",
          "## Offline rebuild vs serial loop (43 scans of samples/gbsar_landslide.toml)\n\n",
          markdown_table(["run", "wall (s)", "CPU of this process (s)"], [[k, w, c] for k, (w, c) in reb.items()])]
    data = {"incremental": {k: v for k, v in inc.items()}, "rebuild": reb, "load": [load0, load1]}
    write_results("bench_monitor", "".join(md), data)


if __name__ == "__main__":
    main()
