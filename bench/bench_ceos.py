"""CEOS RAW ingest speed against the I/O bound (``numpy.fromfile`` of the same bytes).

A synthetic Radarsat-1 fine-beam scene (9288 samples per line, a replica every 8th line, random
4-bit levels, code-exact PRF / window) is written by ``write_ceos`` into a temporary folder; then,
page cache warm, best of 3:

- ``fromfile``: ``numpy.fromfile`` of the whole data file (the I/O bound: bytes into memory);
- ``fromfile+out``: fromfile plus filling a complex64 (lines, samples) array of the output size (the
  memory bound of any reader that returns complex64: it must write 4x the echo bytes);
- ``numpy decode``: fromfile + a vectorized plain-numpy decode of the echo bytes, 256 lines per
  block (the reference);
- ``read_ceos``: the full reader (record walk, aux decode, timing, numba sample decode, orbit).

numba compile / cache-load time of the decode kernel is measured separately (first call in this
process). Peak RSS is that of the whole benchmark process.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from bench.common import best_time, markdown_table, peak_rss_bytes, write_results

N_SAMPLES = 9288
LINES = (1024, 2048, 3072)
BLOCK = 256  # lines per block of the numpy reference decode (bounded memory)


def _scene(n_lines: int):
    from orbit.propagate import Keplerian, kepler_to_state, propagate_j2
    from sarcli.io.ceos.radarsat1 import aux as A
    from sarcli.model.raw import Orbit, Radar, RawProduct

    rng = np.random.default_rng(1)
    prf = float(A.prf_from_code(4283, 0))
    tau0 = float(A.first_sample_time(1262, 4283, 0, 8))
    fs = 1.0 / float(A.clock_period_s(0))
    echo = np.empty((n_lines, N_SAMPLES), np.complex64)
    for a in range(0, n_lines, BLOCK):
        lev = 2 * rng.integers(-8, 8, (min(BLOCK, n_lines - a), N_SAMPLES, 2), dtype=np.int8) + 1
        echo[a:a + BLOCK].real, echo[a:a + BLOCK].imag = lev[..., 0], lev[..., 1]
    r0, v0 = kepler_to_state(Keplerian(7_167_000.0, 0.0011, np.radians(98.59), 0.7, 1.3, 2.1))
    t = -3360.0 + 480.0 * np.arange(15)
    pos, vel = propagate_j2(r0, v0, t)
    c = 299_792_458.0
    return RawProduct(
        echo=echo, azimuth_time=np.arange(n_lines) / prf, epoch_utc="2002-06-16T15:41:00.000000Z",
        radar=Radar(5.3e9, c / 5.3e9, prf, fs, -0.72135e12, 41.75e-6, tau0, c * tau0 / 2, 4),
        agc_db=rng.integers(2, 18, n_lines).astype(np.float32), orbit=Orbit(t, pos, vel, "ECI"),
        replica=echo[0, :1440].copy())


def _numpy_decode(path: Path) -> np.ndarray:
    """Reference: fromfile, then gather the echo bytes of every record and decode them with numpy."""
    from sarcli.io.ceos.radarsat1.datafile import index_records
    from sarcli.io.ceos.radarsat1.samples import decode_reference

    buf = np.fromfile(path, dtype=np.uint8)
    idx = index_records(buf, str(path))
    offsets = idx.echo_offsets()
    out = np.empty((idx.n, idx.n_samples), np.complex64)
    for a in range(0, idx.n, BLOCK):
        out[a:a + BLOCK] = decode_reference(buf[offsets[a:a + BLOCK, None] + np.arange(2 * idx.n_samples)])
    return out


def main() -> None:
    from sarcli.io.ceos.radarsat1 import read_ceos, write_ceos
    from sarcli.io.ceos.radarsat1.samples import decode_lines

    rows = []
    data = {"n_samples": N_SAMPLES, "runs": []}
    with tempfile.TemporaryDirectory(prefix="bench_ceos_") as tmp:
        t0 = time.perf_counter()
        decode_lines(np.zeros(4, np.uint8), np.zeros(1, np.int64), np.zeros(1, np.int64), 2,
                     np.zeros((1, 2), np.complex64))
        compile_s = time.perf_counter() - t0
        for n in LINES:
            raw = _scene(n)
            folder = Path(tmp) / f"s{n}"
            t_write = best_time(lambda raw=raw, folder=folder: write_ceos(folder, raw), repeat=1, warmup=0)
            dat = folder / "DAT_01.001"
            size = dat.stat().st_size
            t_io = best_time(lambda dat=dat: np.fromfile(dat, dtype=np.uint8))
            t_mem = best_time(lambda dat=dat, n=n: (np.fromfile(dat, dtype=np.uint8),
                                                    np.full((n, N_SAMPLES), 1 + 1j, np.complex64)))
            t_np = best_time(lambda dat=dat: _numpy_decode(dat))
            t_rd = best_time(lambda folder=folder: read_ceos(folder))
            assert np.array_equal(read_ceos(folder).echo, raw.echo)
            mb = size / 1e6
            rows.append([n, f"{mb:.1f}", t_io, t_mem, t_np, t_rd, mb / t_rd, t_rd / t_io, t_rd / t_mem,
                         t_np / t_rd, t_write])
            data["runs"].append({"lines": n, "file_mb": mb, "fromfile_s": t_io, "fromfile_plus_output_s": t_mem,
                                 "numpy_decode_s": t_np,
                                 "read_ceos_s": t_rd, "read_ceos_mb_per_s": mb / t_rd,
                                 "read_ceos_over_fromfile": t_rd / t_io,
                                 "read_ceos_over_memory_bound": t_rd / t_mem, "numpy_over_read_ceos": t_np / t_rd,
                                 "write_ceos_s": t_write})
            del raw
    data["numba_first_call_s"] = compile_s
    data["peak_rss_mb"] = peak_rss_bytes() / 1e6
    md = ("# CEOS RAW ingest vs numpy.fromfile (I/O bound)\n\n"
          f"Synthetic fine-beam scene, {N_SAMPLES} samples/line, replica every 8th line; best of 3, warm page "
          "cache; times in s.\n\n"
          + markdown_table(["lines", "file MB", "fromfile", "fromfile+out", "numpy decode", "read_ceos",
                            "read_ceos MB/s", "read_ceos / fromfile", "read_ceos / (fromfile+out)",
                            "numpy / read_ceos", "write_ceos"], rows)
          + f"\nnumba decode kernel first call (compile or cache load): {compile_s:.3f} s. "
          f"Peak RSS of the benchmark process: {data['peak_rss_mb']:.0f} MB.\n")
    write_results("bench_ceos", md, data)


if __name__ == "__main__":
    main()
