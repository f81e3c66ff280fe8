"""Stripmap focusing: Range-Doppler algorithm (RDA), time-domain backprojection, quality metrics.

Public API (contract 5):

- :func:`sarcli.focus.rda.focus_rd` ``(raw, doppler, channel=0, **knobs) -> SLC`` (in memory);
- :data:`sarcli.focus.algorithms.ALGORITHMS` (name -> callable with the same signature) and
  :func:`sarcli.focus.algorithms.register` so that further processors (``optical``) plug into
  ``sarcli focus --algorithm NAME`` without editing the command.

A Doppler model is any object with vectorized ``fdc(range_m, t)`` (absolute centroid, Hz) and
``fr(range_m, t)`` (Doppler rate, Hz/s, negative), ``range_m`` the slant range of the RAW range sample
(beam-centre range) and ``t`` the raw (pulse) azimuth time in s after the product epoch.
"""
