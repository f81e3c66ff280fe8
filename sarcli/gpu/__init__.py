"""The optional CUDA backend: ``--device cuda`` on ``sarcli focus`` and ``sarcli gbsar focus``.

Nothing here is imported unless a caller asks for the ``cuda`` device, and no GPU package is ever imported at
module level: :mod:`sarcli.gpu.device` decides what ``cuda`` means on this machine (a CUDA GPU with CuPy and
numba's CUDA target; or numba's CUDA *simulator* under ``NUMBA_ENABLE_CUDASIM=1``, where the kernels run on the
CPU in Python and the array namespace is numpy: that is how CI tests the GPU code without a GPU).

- :mod:`sarcli.gpu.bp_cuda`: time-domain backprojection kernels (stripmap, GB-SAR/phase-history grid) as
  numba.cuda kernels: the only code here that only a card (or the simulator) can run.
- :mod:`sarcli.gpu.rd_xp`, :mod:`sarcli.gpu.csa_xp` and :mod:`sarcli.gpu.omegak_xp`: one block of the
  Range-Doppler, chirp-scaling and omega-k focusers, written once against an array namespace ``xp`` (numpy in
  CI, CuPy on the card): FFTs by ``xp.fft``, the filters and the range reads as array expressions, tile by
  tile in azimuth-frequency rows so that a full scene fits the card.

Results equal the CPU's within the float32 bounds derived in each module (tests/gpu/).
"""
