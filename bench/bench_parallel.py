"""Parallel and streaming benchmarks (docs/parallel.md). Ratios of the same run only.

1. Many scenes: 8 simulated Radarsat-1 scenes (``samples/rs1_point.toml``, 2048 x 2400) through
   ``sarcli batch`` (doppler -> focus -> GeoTIFF + quicklook): ``--workers 0`` (one process, one scene
   after the other, every step with all cores) vs ``--workers 2`` (a LocalCluster of 2 processes x 1
   thread, each task with one thread), whole commands, alternated ``ROUNDS`` times, best of each:
   speed-up, efficiency (speed-up / processes), scenes per hour per node. Products identical.
2. Big scene 23000 x 6354 (random echo, Radarsat-1 radar and the sample's orbit, so that the GeoTIFF
   can be made): ``sarcli focus --fdc/--fr --geotiff --quicklook`` as a process vs the yardstick
   process (import h5py + scipy, read /echo whole, two ``scipy.fft.fft2`` with all cores), alternated,
   best of each; its peak RSS vs the raw file size. Goals (docs/parallel.md): <= 1.6 x yardstick, <= 1.0 x input.
3. The same scene block-parallel (``sarcli focus --scheduler`` on a LocalCluster of 2 processes x 1
   thread started here) vs single-process: wall time, peak RSS of the client and of each worker, and
   the two images compared bit for bit.

Run: ``python -m bench.run_all bench_parallel`` (BENCH_PARALLEL_QUICK=1: section 1 only;
BENCH_PARALLEL_ONLY=big: sections 2 and 3 only, section 1 kept from the previous results file; ROUNDS env).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.common import RESULTS, SARCLI, markdown_table, peak_rss_bytes, write_results

REPO = Path(__file__).resolve().parents[1]
ROUNDS = int(os.environ.get("ROUNDS", "2"))
BIG = (23000, 6354)
FDC, FR = "-6690", "-1990"


def _run(args: list[str], env: dict | None = None) -> tuple[float, subprocess.CompletedProcess]:
    t0 = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed: {r.stderr[-2000:]}")
    return wall, r


def _images_equal(a: Path, b: Path) -> bool:
    import h5py

    with h5py.File(a) as fa, h5py.File(b) as fb:
        da, db = fa["image"], fb["image"]
        if da.shape != db.shape:
            return False
        return all(np.array_equal(da[s:s + 2048], db[s:s + 2048]) for s in range(0, da.shape[0], 2048))


def bench_many(tmp: Path) -> dict:
    env = dict(os.environ, SARCLI_NO_PROGRESS="1")
    inp = tmp / "many"
    inp.mkdir()
    _run([SARCLI, "simulate", str(REPO / "samples" / "rs1_point.toml"), "-o", str(inp / "s0.h5")], env)
    for k in range(1, 8):
        shutil.copy(inp / "s0.h5", inp / f"s{k}.h5")
    warm = tmp / "warm_in"
    warm.mkdir()
    shutil.copy(inp / "s0.h5", warm / "w.h5")
    _run([SARCLI, "batch", str(warm), "-o", str(tmp / "warm_out"), "--workers", "0"], env)  # numba cache
    best = {"serial": float("inf"), "cluster": float("inf")}
    runs: dict[str, list[float]] = {"serial": [], "cluster": []}
    for r in range(ROUNDS):
        for name, workers in (("serial", "0"), ("cluster", "2")):
            out = tmp / f"many_{name}_{r}"
            wall, proc = _run([SARCLI, "batch", str(inp), "-o", str(out), "--workers", workers, "--json"], env)
            rep = json.loads(proc.stdout)
            assert rep["counts"]["done"] == 16 and not rep["failures"], rep
            runs[name].append(wall)
            best[name] = min(best[name], wall)
    same = all(_images_equal(tmp / "many_serial_0" / f"s{k}.slc.h5", tmp / "many_cluster_0" / f"s{k}.slc.h5")
               for k in range(8))
    task_s = [s["seconds"] for k in range(8) for s in json.loads((tmp / "many_cluster_0" / f"s{k}.json").read_text())
              ["steps"]]
    speedup = best["serial"] / best["cluster"]
    return {"scenes": 8, "shape": [2048, 2400], "rounds": ROUNDS, "runs_s": runs, "serial_s": best["serial"],
            "cluster_s": best["cluster"], "speedup": speedup, "efficiency": speedup / 2,
            "scenes_per_hour_per_node_2_cores": 3600 * 8 / best["cluster"], "identical_images": same,
            "mean_task_s_on_cluster": float(np.mean(task_s)), "n_tasks": len(task_s)}


_WRITE_BIG = r"""
import sys
import numpy as np
from sarcli.io.raw import read_raw, write_raw
from sarcli.model.raw import RawProduct
n, m = {n}, {m}
sim = read_raw({sim!r}, load_echo=False)
rng = np.random.default_rng(1)
echo = np.empty((n, m), np.complex64)
for a in range(0, n, 2048):
    b = min(n, a + 2048)
    echo[a:b].real = rng.standard_normal((b - a, m), np.float32)
    echo[a:b].imag = rng.standard_normal((b - a, m), np.float32)
t = (np.arange(n) - n / 2) / sim.radar.prf_hz
write_raw({out!r}, RawProduct(echo=echo, azimuth_time=t, epoch_utc=sim.epoch_utc, radar=sim.radar,
                              look_side=sim.look_side, source="bench", orbit=sim.orbit, attitude=sim.attitude))
"""

_YARDSTICK = r"""
import h5py, scipy.fft as f
x = h5py.File({raw!r})["echo"][()]
f.fft2(x, workers=-1, overwrite_x=True)
f.fft2(x, workers=-1, overwrite_x=True)
"""


def _focus_args(raw: Path, out: Path, tag: str) -> list[str]:
    return [SARCLI, "focus", str(raw), "-o", str(out / f"{tag}.slc.h5"), "--fdc", FDC, "--fr", FR,
            "--geotiff", str(out / f"{tag}.tif"), "--quicklook", str(out / f"{tag}.png"), "--json"]


def bench_big(tmp: Path) -> dict:
    env = dict(os.environ, SARCLI_NO_PROGRESS="1")
    sim = tmp / "rs1.h5"
    _run([SARCLI, "simulate", str(REPO / "samples" / "rs1_point.toml"), "-o", str(sim)], env)
    raw = tmp / "big_raw.h5"
    _run([sys.executable, "-c", _WRITE_BIG.format(n=BIG[0], m=BIG[1], sim=str(sim), out=str(raw))], env)
    out = tmp / "big"
    out.mkdir()
    yard, focus, rss = [], [], []
    rep = {}
    for r in range(ROUNDS):
        yard.append(_run([sys.executable, "-c", _YARDSTICK.format(raw=str(raw))], env)[0])
        wall, proc = _run(_focus_args(raw, out, f"single{r}"), env)
        focus.append(wall)
        rep = json.loads(proc.stdout)
        rss.append(rep["peak_rss_bytes"])
    size = raw.stat().st_size
    single = {"yardstick_s": min(yard), "focus_s": min(focus), "runs": {"yardstick_s": yard, "focus_s": focus},
              "ratio": min(focus) / min(yard), "peak_rss_bytes": min(rss), "raw_file_bytes": size,
              "echo_bytes": BIG[0] * BIG[1] * 8, "rss_over_input": min(rss) / size, "timings": rep["timings_s"],
              "n_blocks": rep["parameters"]["n_blocks"]}
    single["goals_met"] = {"time_le_1.6x": single["ratio"] <= 1.6, "rss_le_1.0x": single["rss_over_input"] <= 1.0}
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        # the workers' first block compiles nothing (shared numba cache) but imports sarcli: warm them up
        client.run(lambda: __import__("sarcli.focus.rda"))
        wall, proc = _run(_focus_args(raw, out, "parallel") + ["--scheduler", cluster.scheduler_address], env)
        prep = json.loads(proc.stdout)
        workers = client.run(peak_rss_bytes)
    parallel = {"focus_s": wall, "client_peak_rss_bytes": prep["peak_rss_bytes"],
                "worker_peak_rss_bytes": sorted(workers.values()),
                "identical_to_single_process": _images_equal(out / "single0.slc.h5", out / "parallel.slc.h5"),
                "tif_bytes_identical": _rasters_equal(out / "single0.tif", out / "parallel.tif")}
    return {"shape": list(BIG), "single": single, "parallel": parallel}


def _rasters_equal(a: Path, b: Path) -> bool:
    import rasterio

    with rasterio.open(a) as ra, rasterio.open(b) as rb:
        return bool(np.array_equal(ra.read(), rb.read(), equal_nan=True))


def main() -> None:
    quick = bool(os.environ.get("BENCH_PARALLEL_QUICK"))
    only_big = os.environ.get("BENCH_PARALLEL_ONLY") == "big"
    data: dict = {"cores": os.cpu_count(), "load_average_start": os.getloadavg()}
    with tempfile.TemporaryDirectory(dir=os.environ.get("BENCH_TMP")) as td:
        tmp = Path(td)
        if only_big:
            data["many"] = {**json.loads((RESULTS / "bench_parallel.json").read_text())["many"], "earlier_run": True}
        else:
            data["many"] = bench_many(tmp)
        if not quick:
            data["big"] = bench_big(tmp)
    data["load_average_end"] = os.getloadavg()
    m = data["many"]
    md = ["## bench_parallel", "",
          f"Machine: {data['cores']} cores, shared (load average {data['load_average_start'][0]:.1f} at the start, "
          f"{data['load_average_end'][0]:.1f} at the end): compare the ratios of this run, not the seconds.", "",
          f"### 1. Eight simulated Radarsat-1 scenes ({m['shape'][0]} x {m['shape'][1]}), sarcli batch, "
          f"best of {m['rounds']} alternated rounds"
          + (" (from an earlier run: this one re-ran sections 2 and 3 only)" if m.get("earlier_run") else ""), ""]
    md.append(markdown_table(
        ["run", "wall s", "speed-up", "efficiency", "scenes / hour / node"],
        [["serial loop (--workers 0, one process, all cores per step)", m["serial_s"], 1.0, 1.0,
          3600 * 8 / m["serial_s"]],
         ["LocalCluster 2 processes x 1 thread (--workers 2)", m["cluster_s"], m["speedup"], m["efficiency"],
          m["scenes_per_hour_per_node_2_cores"]]]))
    md += ["", f"{m['n_tasks']} tasks, mean {m['mean_task_s_on_cluster']:.2f} s on the cluster; images identical to "
           f"the serial loop's: {m['identical_images']}. Runs (s): {m['runs_s']}.", ""]
    if "big" in data:
        s, p = data["big"]["single"], data["big"]["parallel"]
        md += [f"### 2. One big scene {BIG[0]} x {BIG[1]} (sarcli focus --geotiff --quicklook, streamed)", ""]
        md.append(markdown_table(
            ["process", "wall s", "x yardstick", "peak RSS GiB", "x input file"],
            [["yardstick: read /echo + two fft2", s["yardstick_s"], 1.0, "", ""],
             ["sarcli focus --geotiff --quicklook", s["focus_s"], s["ratio"], s["peak_rss_bytes"] / 2**30,
              s["rss_over_input"]]]))
        md += ["", f"Input file {s['raw_file_bytes'] / 2**30:.2f} GiB (echo {s['echo_bytes'] / 2**30:.2f} GiB), "
               f"{s['n_blocks']} blocks. Goals: time <= 1.6 x yardstick: {s['goals_met']['time_le_1.6x']}; "
               f"peak RSS <= 1.0 x input: {s['goals_met']['rss_le_1.0x']}. Runs: {s['runs']}.", "",
               "Stage times of the last run (s): " + ", ".join(f"{k} {v:.2f}" for k, v in s["timings"].items()), "",
               "### 3. The same scene block-parallel (LocalCluster 2 processes x 1 thread)", ""]
        md.append(markdown_table(
            ["run", "wall s", "peak RSS GiB (client)", "peak RSS GiB per worker"],
            [["single process (2 threads)", s["focus_s"], s["peak_rss_bytes"] / 2**30, ""],
             ["block-parallel, sarcli focus --scheduler", p["focus_s"], p["client_peak_rss_bytes"] / 2**30,
              ", ".join(f"{v / 2**30:.2f}" for v in p["worker_peak_rss_bytes"])]]))
        md += ["", f"Image identical to the single-process one, bit for bit: {p['identical_to_single_process']}; "
               f"GeoTIFF pixels identical: {p['tif_bytes_identical']}.", ""]
    RESULTS.mkdir(parents=True, exist_ok=True)
    write_results("bench_parallel", "\n".join(md), json.loads(json.dumps(data, default=float)))


if __name__ == "__main__":
    main()
