"""Block-parallel focusing of one scene: a focuser's blocks as Dask tasks, assembled on the client.

A focuser's block is a pure function of (plan, block index, raw lines read) (:mod:`sarcli.focus.base`):
each task reads the raw lines its block needs from the raw product (the file must be visible to the
workers under the same path), focuses them with its share of the worker's cores, computes the block's
per-line statistics sums (:func:`sarcli.focus.quality.line_sums`, so the client does not) and returns
the block. The client hands every block to the focus workflow's sink as it arrives (any order: rows
are written where they belong, :mod:`sarcli.focus.sink`), so the image is the single-process image
bit for bit.

Why the client writes: an HDF5 file has one writer. The alternatives -- per-block files assembled
afterwards, or a Zarr store converted to HDF5 -- move every byte of the image once more (written by
the worker, read back and written by the assembler); collecting on the client moves each block once,
from the worker's memory to the writer. At most ``ahead`` blocks are in flight (default two per Dask
thread), so neither the workers nor the client hold more than a few blocks. The plan is submitted
once, as a task of its own (rebuilt by the scheduler if the worker holding it dies), and fetched once
by every worker. The plan's ``timings`` are summed over the blocks' own (diagnostics).
"""

from __future__ import annotations

import copy
import os
from collections.abc import Callable
from typing import Any

import numpy as np

from sarcli.errors import ProductError
from sarcli.parallel.cluster import host_threads, task_threads


def _identity(x: Any) -> Any:
    return x


def focus_block_task(focuser: Any, plan: Any, b: int, raw_path: str, channel: int,
                     threads_by_host: dict[str, int]) -> tuple[int, np.ndarray, np.ndarray, dict[str, float]]:
    """One block on a worker: (first line, block complex64, its line sums, its timings)."""
    from sarcli.focus.quality import line_sums
    from sarcli.io.raw import read_raw_echo_block

    local = copy.copy(plan)  # the worker's plan is shared by its threads: each block its own timings
    if hasattr(local, "timings"):
        local.timings = {}
    first, stop = plan.block_rows(b)
    with task_threads(threads_by_host):
        block = np.asarray(focuser.focus_block(local, b, lambda a, z: read_raw_echo_block(raw_path, a, z, channel)))
        if block.shape != (stop - first, plan.output_shape[1]):
            raise ProductError(f"focuser {focuser.name} returned block {b} with shape {block.shape}, expected "
                               f"{(stop - first, plan.output_shape[1])}")
        return first, block, line_sums(block), dict(getattr(local, "timings", {}))


def focus_blocks(client: Any, focuser: Any, plan: Any, raw_path: str | os.PathLike, channel: int,
                 sink: Callable[..., None], on_block: Callable[[int, int], None] | None = None,
                 ahead: int | None = None) -> Any:
    """Every block of ``plan`` as a task on ``client``; ``sink(first, block, sums)`` for each as it
    arrives; then ``focuser.finish(plan)`` (the SLC metadata). Module docstring."""
    from distributed import as_completed

    threads = host_threads(client)
    ahead = ahead or max(2, 2 * sum(threads.values()))
    plan_future = client.submit(_identity, plan, pure=False, key=f"focus-plan-{os.urandom(8).hex()}")
    path = os.fspath(os.path.abspath(raw_path))

    def submit(b: int) -> Any:
        return client.submit(focus_block_task, focuser, plan_future, b, path, channel, threads, pure=False,
                             key=f"focus-block-{b}-{os.urandom(8).hex()}")

    n = plan.n_blocks
    pending = as_completed([submit(b) for b in range(min(ahead, n))], loop=client.loop)
    submitted, done = min(ahead, n), 0
    timings = getattr(plan, "timings", None)
    try:
        for future in pending:
            first, block, sums, t = future.result()
            future.release()
            sink(first, block, sums)
            del block
            if timings is not None:
                for k, v in t.items():
                    timings[k] = timings.get(k, 0.0) + v
            done += 1
            if on_block is not None:
                on_block(done, n)
            if submitted < n:
                pending.add(submit(submitted))
                submitted += 1
    except BaseException:
        pending.clear()
        raise
    finally:
        plan_future.release()
    return focuser.finish(plan)
