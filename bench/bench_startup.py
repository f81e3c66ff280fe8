"""Start-up and fixed cost per command: what a user waits for besides the processing.

Sections (one run, same machine):
  A. Warm commands (numba cache filled) as a user runs them, each a fresh process: a bare interpreter
     (``python -c pass``), the imports the processing commands cannot do without (numpy, scipy.fft,
     h5py, numba, typer: the floor of any such command), ``sarcli --help``, ``sarcli doppler`` and
     ``sarcli focus`` of the real
     RADARSAT-1 block (1536 x 2048, ``rs1_vancouver_block1.mat`` ingested), ``sarcli gbsar focus`` of
     the outdoor sample scan (auto: DF + BP). Interleaved rounds; best wall time and best CPU time
     (user + system) of each; ratios to the bare interpreter of the same run, since absolute times on
     a shared 2-core machine vary several-fold with its load.
  B. A fresh install's first commands: an empty numba cache folder, then the same commands (every
     kernel compiled), against an empty folder filled by ``make warm-cache`` (what ``make install``
     runs, on small samples) and then the same commands.
Run: ``.venv/bin/python -m bench.bench_startup`` (writes bench/results/bench_startup.md|json).
"""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.common import SARCLI, SHARED, markdown_table, write_results

REPO = Path(__file__).resolve().parents[1]
#: the imports every processing command needs: no such command starts faster than this process
_FLOOR = "imports only (numpy, scipy.fft, h5py, numba, typer)"
BIN = Path(sys.executable).parent


def _run(cmd: list[str], env: dict | None = None) -> tuple[float, float]:
    """(wall s, CPU s of the child: user + system) of one run; a failing command stops the benchmark."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def _inputs(work: Path) -> dict[str, Path]:
    """The real block ingested and its Doppler product; the outdoor sample scan simulated."""
    van, dop, scan = work / "van.h5", work / "dop.h5", work / "outdoor.h5"
    subprocess.run([SARCLI, "-q", "ingest", "--matlab", str(SHARED / "rs1_vancouver_block1.mat"), "--params",
                    str(SHARED / "rs1_vancouver_run_params.mat"), "-o", str(van)], check=True)
    subprocess.run([SARCLI, "-q", "doppler", str(van), "-o", str(dop)], check=True)
    subprocess.run([SARCLI, "-q", "gbsar", "simulate", str(REPO / "samples" / "gbsar_outdoor.toml"), "-o",
                    str(scan)], check=True)
    return {"van": van, "dop": dop, "scan": scan}


def _commands(work: Path, f: dict[str, Path]) -> dict[str, list[str]]:
    return {
        "bare interpreter (python -c pass)": [sys.executable, "-c", "pass"],
        _FLOOR: [sys.executable, "-c",
                                                                "import numpy, scipy.fft, h5py, numba, typer"],
        "sarcli --help": [SARCLI, "--help"],
        "sarcli doppler (real block)": [SARCLI, "-q", "doppler", str(f["van"]), "-o", str(work / "dop2.h5")],
        "sarcli focus (real block)": [SARCLI, "-q", "focus", str(f["van"]), "--doppler", str(f["dop"]), "-o",
                                      str(work / "slc.h5")],
        "sarcli gbsar focus (outdoor scan, auto)": [SARCLI, "-q", "gbsar", "focus", str(f["scan"]), "-o",
                                                    str(work / "img.h5")],
    }


def section_warm(work: Path, f: dict[str, Path], out: dict, rounds: int = 5) -> str:
    cmds = _commands(work, f)
    for c in cmds.values():  # fill the numba cache, warm the page cache
        _run(c)
    best = {k: [float("inf"), float("inf")] for k in cmds}
    for _ in range(rounds):
        for k, c in cmds.items():
            w, cpu = _run(c)
            best[k] = [min(best[k][0], w), min(best[k][1], cpu)]
    bare_w, bare_c = best["bare interpreter (python -c pass)"]
    rows = [[k, w, cpu, w / bare_w, cpu / bare_c] for k, (w, cpu) in best.items()]
    out["warm"] = {k: {"wall_s": w, "cpu_s": cpu, "wall_vs_bare": w / bare_w, "cpu_vs_bare": cpu / bare_c}
                   for k, (w, cpu) in best.items()}
    out["warm_rounds"] = rounds
    return ("## A. Warm commands (numba cache filled), each a fresh process\n\n"
            f"Best of {rounds} interleaved rounds; load average {os.getloadavg()[0]:.1f} at the end.\n\n"
            + markdown_table(["command", "wall s", "CPU s", "wall / bare", "CPU / bare"], rows))


def section_cold(work: Path, f: dict[str, Path], out: dict) -> str:
    cmds = {k: c for k, c in _commands(work, f).items() if k.startswith("sarcli ") and "--help" not in k}
    res: dict[str, dict] = {}
    for label in ("empty cache", "after make warm-cache"):
        cache = Path(tempfile.mkdtemp(prefix="numba-", dir=work))
        env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
        res[label] = {}
        if label == "after make warm-cache":
            t0 = time.perf_counter()
            subprocess.run(["make", "-s", "-C", str(REPO), "warm-cache"], check=True, env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            res[label]["make warm-cache"] = {"wall_s": time.perf_counter() - t0}
        for k, c in cmds.items():
            w, cpu = _run(c, env)
            res[label][k] = {"wall_s": w, "cpu_s": cpu}
        shutil.rmtree(cache)
    out["first_command"] = res
    warm = out["warm"]
    rows = [[k, res["empty cache"][k]["wall_s"], res["after make warm-cache"][k]["wall_s"], warm[k]["wall_s"]]
            for k in cmds]
    return ("## B. A fresh install's first command\n\n"
            "Each command run once against an empty numba cache folder (every kernel compiled), and once "
            "against an empty folder that `make warm-cache` (part of `make install`: byte-compile, simulate, "
            "CEOS ingest, doppler, focus with GeoTIFF and quicklook of samples/rs1_point.toml, gbsar focus of "
            "samples/gbsar_indoor.toml with every algorithm) "
            f"filled first, in {res['after make warm-cache']['make warm-cache']['wall_s']:.0f} s; the warm "
            "time of section A for comparison.\n\n"
            + markdown_table(["command", "empty cache: first run s", "after make warm-cache: first run s",
                              "warm s (A)"], rows))


def main() -> None:
    if not (SHARED / "rs1_vancouver_block1.mat").is_file():
        print(f"bench_startup: SKIPPED, {SHARED} has no rs1_vancouver_block1.mat")
        return
    out: dict = {}
    with tempfile.TemporaryDirectory(prefix="bench_startup-") as tmp:
        work = Path(tmp)
        f = _inputs(work)
        parts = [section_warm(work, f, out), section_cold(work, f, out)]
    warm = out["warm"]
    first = out["first_command"]["after make warm-cache"]
    summary = markdown_table(["what", "figure"], [
        ["the imports alone (numpy, scipy.fft, h5py, numba, typer)",
         f"{warm[_FLOOR]['wall_s']:.2f} s wall, {warm[_FLOOR]['cpu_s']:.2f} s CPU"]] + [
        [f"warm `{k[7:]}`", f"{v['wall_s']:.2f} s wall, {v['cpu_s']:.2f} s CPU = {v['cpu_vs_bare']:.1f}x a bare "
                            f"interpreter's CPU"] for k, v in warm.items() if k.startswith("sarcli")] + [
        [f"first `{k[7:]}` after install", f"{v['wall_s']:.2f} s (empty cache: "
                                           f"{out['first_command']['empty cache'][k]['wall_s']:.2f} s)"]
        for k, v in first.items() if k.startswith("sarcli")])
    write_results("bench_startup", "# Start-up and fixed cost per command\n\n" + summary + "\n" + "\n".join(parts),
                  out)


if __name__ == "__main__":
    main()
