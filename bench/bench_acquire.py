"""GB-SAR acquisition overhead per stop with a zero-latency emulator (goal: < 50 ms at 1601
points x 4 polarizations).

The emulator runs in its own process (``sarcli gbsar emulate --time-scale 0``, a calibrated thru, so
that its own cost is formatting and pty I/O only); the scan runs here through the library, exactly
as ``sarcli gbsar scan`` does. With zero sweep and move time, everything a stop costs is overhead:

- ``stop wall``: whole stop (move + G4 finish check + status, 4 x [switch, OPC?;SING poll, OUTPDATA
  transfer, parse], HDF5 append + flush);
- ``controller overhead``: the part outside ``move_to`` and ``sweep`` (switching, data transfer and
  parsing, writing and flushing) -- the goal's "parsing, writing, flushing" figure, wall time, so it
  includes the emulator's formatting and the pty transfer (80 kB per sweep in FORM4);
- ``client CPU``: CPU time of the scanning process per stop (all protocol handling, parsing, HDF5);
- microbenchmarks of the parts: FORM4 / binary parsing vs. a plain ``np.frombuffer`` reference, and
  ``ScanWriter.append`` (write + flush of one 4 x 1601 stop) vs. ``np.save`` of the same array.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.common import best_time, markdown_table, peak_rss_bytes, write_results

N_STOPS = 20
POINTS = 1601
POLS = ["VV", "VH", "HV", "HH"]


def _emulator() -> tuple[subprocess.Popen, dict]:
    sarcli = os.path.join(os.path.dirname(sys.executable), "sarcli")
    p = subprocess.Popen([sarcli, "gbsar", "emulate", "--json", "--time-scale", "0", "--switch", "grbl"],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    return p, json.loads(p.stdout.readline())


def _scan(ports: dict, fmt: str, folder: Path) -> dict:
    from sarcli.acquire.config import load_config
    from sarcli.acquire.controller import connect, run_scan, scan_template
    from sarcli.io.scan import ScanWriter

    cfg = load_config(None, {
        "vna": {"points": POINTS, "data_format": fmt, "start_hz": 5.0e9, "stop_hz": 5.6e9},
        "rail": {"count": N_STOPS, "settle_s": 0.0, "step_m": 0.05, "feed_mm_min": 500.0},
        "polarization": {"polarizations": POLS, "switch": "grbl", "settle_s": 0.0}})
    inst = connect(cfg, ports["vna_port"], ports["rail_port"])
    try:
        path = folder / f"bench_{fmt}.h5"
        w = ScanWriter.create(path, scan_template(cfg, inst.identity, "2026-01-01T00:00:00Z"), N_STOPS)
        t0, c0 = time.perf_counter(), time.process_time()
        res = run_scan(cfg, inst, w, "2026-01-01T00:00:00Z")
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        assert res.status == "complete", res.error
        # back to X0 so that the next run makes the same moves
        inst.rail.move_to(0.0, 500.0)
    finally:
        inst.close()
    return {"format": fmt, "stop_wall_ms": 1e3 * wall / N_STOPS, "client_cpu_ms": 1e3 * cpu / N_STOPS,
            "overhead_mean_ms": 1e3 * float(np.mean(res.overhead_s)),
            "overhead_max_ms": 1e3 * float(np.max(res.overhead_s)),
            "file_mb": path.stat().st_size / 1e6}


def _parts(folder: Path) -> list[dict]:
    from sarcli.acquire.emulator.vna import binary_block, form4_block
    from sarcli.acquire.vna8753 import parse_binary, parse_form4
    from sarcli.io.scan import ScanWriter
    from sarcli.model.gbsar import Scan

    rng = np.random.default_rng(0)
    z = rng.standard_normal(POINTS) + 1j * rng.standard_normal(POINTS)
    f4, f2 = form4_block(z), binary_block(z, "FORM2")
    rows = []
    ref4 = best_time(lambda: np.array(f4.replace(b"\n", b",").split(b",")[:-1]).astype(np.float64), repeat=20)
    rows.append({"part": "FORM4 parse (1601 pts)", "ms": 1e3 * best_time(lambda: parse_form4(f4, POINTS), repeat=20),
                 "reference": "split + astype", "ref_ms": 1e3 * ref4})
    ref2 = best_time(lambda: np.frombuffer(f2[4:], ">f4").astype(np.float64), repeat=50)
    rows.append({"part": "FORM2 parse (1601 pts)",
                 "ms": 1e3 * best_time(lambda: parse_binary(f2[4:], POINTS, ">f4"), repeat=50),
                 "reference": "np.frombuffer", "ref_ms": 1e3 * ref2})
    tmpl = Scan(s21=np.zeros((4, 0, POINTS), np.complex64), frequency=np.linspace(5e9, 5.6e9, POINTS),
                rail_position=np.zeros(0), rail_height=np.zeros(0), polarizations=tuple(POLS),
                epoch_utc="2026-01-01T00:00:00Z", source="measured", status="interrupted")
    w = ScanWriter.create(folder / "append.h5", tmpl, 10_000)
    data = (rng.standard_normal((4, POINTS)) + 1j * rng.standard_normal((4, POINTS))).astype(np.complex64)
    k = iter(range(10_000))
    t_app = best_time(lambda: w.append(data, 0.05 * next(k), 1.5, 0.0), repeat=30)
    w.close()

    def npsave():
        with open(folder / "x.npy", "wb") as fh:
            np.save(fh, data)
            fh.flush()
            os.fsync(fh.fileno())
    rows.append({"part": "ScanWriter.append + flush (4 x 1601)", "ms": 1e3 * t_app,
                 "reference": "np.save + fsync", "ref_ms": 1e3 * best_time(npsave, repeat=30)})
    return rows


def main() -> None:
    p, ports = _emulator()
    try:
        with tempfile.TemporaryDirectory() as d:
            folder = Path(d)
            _scan(ports, "FORM2", folder)  # warm-up (imports, first connections)
            runs = [_scan(ports, fmt, folder) for fmt in ("FORM2", "FORM3", "FORM4")]
            parts = _parts(folder)
    finally:
        p.send_signal(signal.SIGINT)
        p.wait(timeout=20)
    md = [f"# Acquisition overhead per stop ({POINTS} points x {len(POLS)} pols, {N_STOPS} stops, "
          "zero-latency emulator in its own process)\n\n",
          "Target: controller overhead (outside sweep and move) < 50 ms per stop.\n\n",
          markdown_table(["data format", "stop wall (ms)", "controller overhead mean (ms)", "max (ms)",
                          "client CPU per stop (ms)", "file (MB)"],
                         [[r["format"], r["stop_wall_ms"], r["overhead_mean_ms"], r["overhead_max_ms"],
                           r["client_cpu_ms"], r["file_mb"]] for r in runs]),
          "\nParts (best of n, this process):\n\n",
          markdown_table(["part", "ms", "reference", "reference ms"],
                         [[r["part"], r["ms"], r["reference"], r["ref_ms"]] for r in parts]),
          f"\nPeak RSS of the client: {peak_rss_bytes() / 1e6:.0f} MB. Machine: 2 shared cores; the emulator "
          "shares them, so stop wall includes its formatting time.\n"]
    write_results("bench_acquire", "".join(md), {"runs": runs, "parts": parts, "n_stops": N_STOPS,
                                                 "points": POINTS, "pols": POLS})


if __name__ == "__main__":
    main()
