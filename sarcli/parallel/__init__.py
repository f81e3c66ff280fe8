"""Parallel and distributed execution of sarcli's workflows on Dask (``dask.distributed``).

- :mod:`sarcli.parallel.cluster`: where the work runs: a ``LocalCluster`` of worker processes on this
  machine (the default), or a running scheduler (``--scheduler tcp://host:8786`` or
  ``SARCLI_SCHEDULER``); the thread budget of every task (no oversubscription).
- :mod:`sarcli.parallel.graph`: a graph of named tasks with dependencies run on a cluster (or in this
  process, one after the other): a retry for unexpected failures, progress over tasks, every outcome
  collected, one bad task never stops the others.
- :mod:`sarcli.parallel.focus`: block-parallel focusing of one scene (a focuser's blocks as tasks,
  assembled in order on the client).
- :mod:`sarcli.parallel.gbsar`: GB-SAR time series: the temporal coherence and PS reduction over pixel
  blocks, the images read lazily, block by block.

Layer: beside ``sarcli/workflows`` (which call it), above processing and I/O. Workers must see the
same files as the client under the same paths (one machine, or a shared file system); see
``docs/parallel.md``.
"""
