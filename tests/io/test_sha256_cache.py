"""The input hashes of provenance: one file version is read once per process, a changed file is read
again (the cache key is the file's device, inode, size and modification time)."""

from __future__ import annotations

import hashlib
import os

from sarcli.io import h5common


def test_a_rewritten_file_is_hashed_again_and_the_table_stays_bounded(tmp_path):
    p = tmp_path / "in.bin"
    p.write_bytes(b"a" * 1000)
    assert h5common.sha256_file(p) == hashlib.sha256(b"a" * 1000).hexdigest()
    st = os.stat(p)
    p.write_bytes(b"b" * 1000)  # same size, same inode
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns + 1000))  # a later modification time, as any write gives
    assert h5common.sha256_file(p) == hashlib.sha256(b"b" * 1000).hexdigest()
    for k in range(h5common._HASHED_KEPT + 10):
        q = tmp_path / f"f{k}"
        q.write_bytes(bytes([k % 256]))
        h5common.sha256_file(q)
    assert len(h5common._hashed) <= h5common._HASHED_KEPT
