"""The CUDA backend measured on a lent GPU machine (issue "An optional GPU backend"); nothing to do elsewhere.

Run where ``--device cuda`` works (a GPU, CuPy, numba's CUDA target): ``python -m bench.bench_gpu``. Without a
GPU it says so and leaves the previous results alone (docs/parallel.md says which machine measured them).
``python -m bench.bench_gpu --smoke`` runs every section on tiny inputs under numba's CUDA simulator
(``NUMBA_ENABLE_CUDASIM=1``) to check the script itself; it writes nothing.

A. GOTCHA pass 1 HH, 1001 x 1001 grid (0.1 m), 469 pulses, :func:`sarcli.gpu.bp_cuda.grid_kernel`: kernel time
   (CUDA events, best of 5 after a warm-up; profiles and grid already on the card), backprojections per second,
   the same grid by the numba CPU kernel on all cores in the same run, largest difference against it.
B. A full Radarsat-1 scene (the real Vancouver block tiled to 23000 x 6354, in memory) through ``rd`` with
   ``device="cuda"``: end to end without the disk (host echo in, host image out, every block's copies
   included), against two ``cupy.fft.fft2`` of the same array (the yardstick) and the CPU focus on all cores.
C. ``sarcli batch`` of 8 simulated scenes (samples/rs1_point.toml) on 8 workers against the serial loop
   (``--workers 0``): efficiency = speed-up / 8 (CPU only: the machine's cores).
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

from bench.common import SARCLI, SHARED, markdown_table, write_results

REPO = Path(__file__).resolve().parents[1]
GOTCHA = SHARED / "gotcha_pass1_hh"


def _device():
    from sarcli.errors import ConfigError
    from sarcli.gpu.device import require_cuda

    try:
        return require_cuda()
    except ConfigError as exc:
        return str(exc)


def _sync(dev) -> None:
    if not dev.simulator:
        dev.xp.cuda.runtime.deviceSynchronize()


def _best(dev, fn, repeat: int) -> float:
    fn()
    _sync(dev)
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        _sync(dev)
        best = min(best, time.perf_counter() - t0)
    return best


def gotcha(dev, smoke: bool) -> dict:
    from sarcli.gbsar.backprojection import backproject_grid
    from sarcli.gbsar.rangecomp import range_compress
    from sarcli.gbsar.windows import taper
    from sarcli.gpu import bp_cuda
    from sarcli.io.scan import read_scan
    from sarcli.workflows import gbsar_import

    files = sorted(GOTCHA.glob("data_3dsar_pass1_az00?_HH.mat"))
    if len(files) != 4:
        return {"skipped": f"GOTCHA files not found in {GOTCHA}"}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "gotcha.h5"
        gbsar_import.run(gbsar_import.Config(inputs=tuple(files), output=path))
        scan = read_scan(path)
    n = 21 if smoke else 1001
    xs = ys = np.linspace(-50.0, 50.0, n)
    prof = range_compress(scan, "HH", "hamming", 4, centred=True)
    ant, ref = scan.antenna_xyz(), scan.reference_range
    if smoke:  # every 40th pulse
        prof.data, prof.weights, ant, ref = prof.data[::40], prof.weights[::40], ant[::40], ref[::40]
    w = taper("hamming", ant.shape[0]) * prof.weights
    xp = dev.xp
    args = [dev.asarray(np.ascontiguousarray(prof.data.real, np.float32)),
            dev.asarray(np.ascontiguousarray(prof.data.imag, np.float32)), float(prof.first_range_m),
            float(prof.dr_m), dev.asarray(ant), dev.asarray(ref), dev.asarray(w), dev.asarray(xs), dev.asarray(ys),
            0.0, 4 * np.pi / prof.wavelength_m]
    out = [xp.zeros((n, n), xp.float32), xp.zeros((n, n), xp.float32), xp.zeros((n, n), xp.float64)]
    block = (32, bp_cuda.THREADS // 32)
    grid = ((n + 31) // 32, (n + block[1] - 1) // block[1])

    def launch():
        bp_cuda.grid_kernel[grid, block](*args, *out)

    t_kernel = _best(dev, launch, 1 if smoke else 5)
    gpu = dev.to_host(out[0]) + 1j * dev.to_host(out[1])
    t0 = time.perf_counter()
    cpu, _ = backproject_grid(prof, ant, ref, xs, ys, 0.0, "hamming")
    t_cpu = time.perf_counter() - t0
    gpu = gpu / w.sum()
    n_bp = n * n * int(np.count_nonzero(w))
    return {"grid": [n, n], "pulses": int(np.count_nonzero(w)), "kernel_s": t_kernel, "bp_per_s": n_bp / t_kernel,
            "cpu_numba_s": t_cpu, "cpu_cores": os.cpu_count(), "speedup_vs_cpu": t_cpu / t_kernel,
            "max_diff_rel": float(np.abs(gpu - cpu).max() / np.abs(cpu).max())}


def _two_fft2(dev, echo: np.ndarray, repeat: int) -> float:
    """Two fft2 of the scene's array on the card (the yardstick), best of ``repeat``; the array freed after."""
    on_card = dev.asarray(echo)
    return _best(dev, lambda: dev.xp.fft.fft2(dev.xp.fft.fft2(on_card)), repeat)


def full_scene(dev, smoke: bool) -> dict:
    import dataclasses

    from sarcli.focus.base import focus_in_memory
    from sarcli.focus.rda import RD
    from sarcli.io.matlab import read_matlab_block
    from sarcli.model.doppler import GeometricDoppler

    block = SHARED / "rs1_vancouver_block1.mat"
    if not block.exists():
        return {"skipped": f"{block} not found"}
    raw = read_matlab_block(block, SHARED / "rs1_vancouver_run_params.mat")
    shape = (2048, 1600) if smoke else (23000, 6354)
    reps = (-(-shape[0] // raw.echo.shape[0]), -(-shape[1] // raw.echo.shape[1]))
    echo = np.ascontiguousarray(np.tile(raw.echo, reps)[:shape[0], :shape[1]], np.complex64)
    raw = dataclasses.replace(raw, echo=echo,
                              azimuth_time=raw.azimuth_time[0] + np.arange(shape[0]) / raw.radar.prf_hz)
    lam = raw.radar.wavelength_m
    r_mid = raw.radar.first_range_m + 0.5 * shape[1] * 299792458.0 / (2 * raw.radar.range_sampling_rate_hz)
    dop = GeometricDoppler.from_centroid_and_rate(-6900.0, -1733.0, r_mid, lam)
    opts = {"orbit_timing": False, "block_lines": 1024 if smoke else 8192}
    t0 = time.perf_counter()
    gpu = focus_in_memory(RD, raw, dop, {**opts, "device": "cuda"})
    t_gpu_first = time.perf_counter() - t0
    t0 = time.perf_counter()
    gpu = focus_in_memory(RD, raw, dop, {**opts, "device": "cuda"})
    t_gpu = time.perf_counter() - t0
    fft2 = _two_fft2(dev, echo, 1 if smoke else 3)
    t0 = time.perf_counter()
    cpu = focus_in_memory(RD, raw, dop, opts)
    t_cpu = time.perf_counter() - t0
    peak = float(np.abs(cpu.image).max())
    return {"shape": list(shape), "gpu_end_to_end_s": t_gpu, "gpu_first_call_s": t_gpu_first,
            "two_fft2_on_gpu_s": fft2, "ratio_to_two_fft2": t_gpu / fft2, "cpu_s": t_cpu, "cpu_cores": os.cpu_count(),
            "speedup_vs_cpu": t_cpu / t_gpu, "max_diff_rel_to_peak": float(np.abs(gpu.image - cpu.image).max() / peak)}


def batch_efficiency(smoke: bool) -> dict:
    env = dict(os.environ, SARCLI_NO_PROGRESS="1")
    n = 2 if smoke else 8
    with tempfile.TemporaryDirectory() as tmp:
        inp = Path(tmp) / "in"
        inp.mkdir()
        subprocess.run([SARCLI, "simulate", str(REPO / "samples" / "rs1_point.toml"), "-o", str(inp / "s0.h5")],
                       env=env, check=True, capture_output=True)
        for k in range(1, n):
            shutil.copy(inp / "s0.h5", inp / f"s{k}.h5")
        wall = {}
        for name, workers in (("serial", "0"), ("cluster", str(n))):
            t0 = time.perf_counter()
            subprocess.run([SARCLI, "batch", str(inp), "-o", str(Path(tmp) / name), "--workers", workers, "--json"],
                           env=env, check=True, capture_output=True)
            wall[name] = time.perf_counter() - t0
    speedup = wall["serial"] / wall["cluster"]
    return {"scenes": n, "workers": n, "serial_s": wall["serial"], "cluster_s": wall["cluster"], "speedup": speedup,
            "efficiency": speedup / n, "cpu_cores": os.cpu_count()}


def main(argv: list[str] | None = None) -> None:
    smoke = "--smoke" in (argv if argv is not None else sys.argv[1:])
    dev = _device()
    if isinstance(dev, str) or (dev.simulator and not smoke):
        why = dev if isinstance(dev, str) else "numba's CUDA simulator is not a GPU"
        print(f"bench_gpu: skipped, no CUDA device here ({why}); previous results, if any, are kept")
        return
    res = {"device": dev.name, "gotcha": gotcha(dev, smoke), "full_scene_rd": full_scene(dev, smoke),
           "batch": batch_efficiency(smoke)}
    if smoke:
        print(json.dumps(res, indent=1, default=str))
        return
    g, f, b = res["gotcha"], res["full_scene_rd"], res["batch"]
    rows = [["GOTCHA 1001 x 1001 BP kernel (goal <= 10 ms)", g.get("kernel_s"), g.get("bp_per_s"),
             g.get("speedup_vs_cpu"), g.get("max_diff_rel")],
            ["full scene RD 23000 x 6354, end to end without disk (goal <= 3 s)", f.get("gpu_end_to_end_s"),
             f.get("ratio_to_two_fft2"), f.get("speedup_vs_cpu"), f.get("max_diff_rel_to_peak")],
            ["batch 8 scenes on 8 workers, efficiency (goal >= 0.85)", b["cluster_s"], b["efficiency"],
             b["speedup"], None]]
    md = (f"# bench_gpu: the CUDA backend on {dev.name}\n\n"
          + markdown_table(["what", "seconds", "throughput / ratio / efficiency", "speed-up vs CPU", "difference"],
                           rows)
          + f"\n\nCPU figures on the same machine's {os.cpu_count()} cores, in the same run.\n")
    write_results("bench_gpu", md, res)


if __name__ == "__main__":
    main()
