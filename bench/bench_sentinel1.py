"""Sentinel-1 Level-0 decode throughput (MB of packets per second) against the ``sentinel1decoder``
package (PyPI, Rust decoder), on the same file.

The file: the real FDBAQ echo packet of ``../shared/data/s1_l0_packets`` (S3, 10779 quads, 15.6 kB)
repeated to ``SARCLI_BENCH_S1_MB`` MB (default 100: the decoded complex64 echo is 14 times the packet bytes, 1.1 GB
here, and the whole reader holds it twice), written to a temporary folder; page cache warm.
Measured, best of 3 (the peer: best of 2), from the file name to the complex64 echo array:

- ``sarcli decode``: read the file, walk the packets, decode all headers, decode all user data
  (:mod:`sarcli.io.sentinel1`), with all numba threads and with one;
- ``sarcli read_level0``: the whole reader (plus grouping, ancillary data, replica, product);
- ``sentinel1decoder``: ``Level0Decoder(path).decode_metadata()`` then ``decode_packets`` of the
  echo packets, run by the interpreter of its own virtual environment ``bench/.venv-peer`` (created
  here on first use with ``pip install sentinel1decoder==2.1.0``; never a dependency of sarcli).

Both decodes of the first line are compared sample for sample. numba compile / cache-load time is
reported separately (first call in this process).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.common import best_time, markdown_table, peak_rss_bytes, write_results

REPO = Path(__file__).resolve().parents[1]
PACKET = REPO.parent / "shared" / "data" / "s1_l0_packets" / "000408-echo.dat"
PEER_VENV = Path(__file__).parent / ".venv-peer"
PEER_PACKAGE = "sentinel1decoder==2.1.0"

PEER_SCRIPT = r"""
import json, sys, time
import numpy as np
from sentinel1decoder import Level0Decoder
path, out = sys.argv[1], sys.argv[2]
best_meta = best_dec = float("inf")
for _ in range(2):
    t0 = time.perf_counter()
    dec = Level0Decoder(path)
    df = dec.decode_metadata()
    t1 = time.perf_counter()
    echo = dec.decode_packets(df)
    t2 = time.perf_counter()
    best_meta, best_dec = min(best_meta, t1 - t0), min(best_dec, t2 - t0)
np.save(out, echo[0])
print(json.dumps({"metadata_s": best_meta, "total_s": best_dec, "n_lines": int(echo.shape[0])}))
"""


def _peer_python() -> Path | None:
    py = PEER_VENV / "bin" / "python"
    if not py.exists():
        try:
            subprocess.run([sys.executable, "-m", "venv", str(PEER_VENV)], check=True, capture_output=True)
            subprocess.run([str(py), "-m", "pip", "install", "-q", PEER_PACKAGE], check=True, capture_output=True)
        except (subprocess.CalledProcessError, OSError) as e:
            print(f"peer environment not available: {e}", file=sys.stderr)
            return None
    return py


def _our_decode(path: Path) -> np.ndarray:
    from sarcli.io.sentinel1.constants import HEADER_BYTES
    from sarcli.io.sentinel1.decode import decode_packets, decoder_kind
    from sarcli.io.sentinel1.headers import check_headers, decode_headers, walk_packets

    data = np.fromfile(path, np.uint8)
    h = decode_headers(data, walk_packets(data))
    check_headers(h)
    start = h["offset"].astype(np.int64) + HEADER_BYTES
    end = h["offset"].astype(np.int64) + h["packet_data_length"].astype(np.int64) + 7
    kind = np.full(h.size, decoder_kind(int(h["baq_mode"][0]), int(h["test_mode"][0])))
    return decode_packets(data, start, end, h["number_of_quads"], kind)


def main() -> None:
    import numba

    from sarcli.io.sentinel1.product import read_level0

    if not PACKET.is_file():
        print(f"{PACKET} not available: benchmark skipped", file=sys.stderr)
        return
    target_mb = float(os.environ.get("SARCLI_BENCH_S1_MB", "100"))
    packet = PACKET.read_bytes()
    n = int(target_mb * 1e6 // len(packet))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s1-echo.dat"
        path.write_bytes(packet * n)
        mb = path.stat().st_size / 1e6
        t_first = time.perf_counter()
        ours = _our_decode(path)
        t_first = time.perf_counter() - t_first
        threads = numba.get_num_threads()
        t_all = best_time(lambda: _our_decode(path), repeat=3, warmup=0)
        numba.set_num_threads(1)
        t_one = best_time(lambda: _our_decode(path), repeat=3, warmup=0)
        numba.set_num_threads(threads)
        t_read = best_time(lambda: read_level0(path), repeat=3, warmup=1)
        rows = [["sarcli decode", threads, t_all, mb / t_all],
                ["sarcli decode", 1, t_one, mb / t_one],
                ["sarcli read_level0", threads, t_read, mb / t_read]]
        peer = None
        py = _peer_python()
        if py is not None:
            out = Path(tmp) / "peer_line0.npy"
            r = subprocess.run([str(py), "-c", PEER_SCRIPT, str(path), str(out)], capture_output=True, text=True)
            if r.returncode == 0:
                peer = json.loads(r.stdout.strip().splitlines()[-1])
                line0 = np.load(out)
                peer["first_line_equal_bits"] = bool(np.array_equal(line0.view(np.uint32), ours[0].view(np.uint32)))
                peer["first_line_max_abs_diff"] = float(np.max(np.abs(line0 - ours[0])))
                rows.append(["sentinel1decoder 2.1.0", "peer", peer["total_s"], mb / peer["total_s"]])
            else:
                print(f"peer run failed: {r.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
    md = (f"# Sentinel-1 Level-0 decode throughput\n\nFile: the real FDBAQ echo packet repeated {n} times "
          f"({mb:.1f} MB, {n} lines x {ours.shape[1]} samples); best of 3 (peer: best of 2), page cache warm. "
          f"Machine: {os.cpu_count()} cores shared with other jobs.\n\n"
          + markdown_table(["decoder", "threads", "time (s)", "MB/s"], rows)
          + f"\nnumba compile / cache load + first decode: {t_first:.2f} s. "
          f"Peak RSS {peak_rss_bytes() / 1e9:.2f} GB.\n")
    if peer is not None:
        md += (f"\nsentinel1decoder metadata pass alone: {peer['metadata_s']:.2f} s. First line, both decoders: "
               f"bit-identical = {peer['first_line_equal_bits']}, max |difference| = "
               f"{peer['first_line_max_abs_diff']:.3g}.\n")
    write_results("bench_sentinel1", md, {"file_mb": mb, "packets": n, "numba_threads": threads,
                                          "sarcli_decode_s": t_all, "sarcli_decode_1thread_s": t_one,
                                          "sarcli_read_level0_s": t_read, "first_call_s": t_first, "peer": peer})


if __name__ == "__main__":
    main()
