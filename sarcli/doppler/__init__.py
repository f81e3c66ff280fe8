"""Doppler centroid and Doppler rate estimation for stripmap raw data.

Modules, one job each:

- ``api``        :func:`estimate_doppler`: the entry point (options, terrain, progress -> PolyDoppler).
- ``options``    :class:`DopplerOptions`: every knob, frozen and validated.
- ``inputs``     stage 0: refuse implausible products, undo the receiver gain (``agcsteps`` for steps).
- ``estimators`` centroid estimators (stage 1) behind the ``CentroidEstimator`` Protocol, registered in
                 ``ESTIMATORS``: ``cde``, ``sde``, ``rc-cde``, ``lb``; a plug-in is one more.
- ``pipeline``   the named stages after the estimator (unwrap, ambiguity, fit, rate) and the assembly.
- ``cde``        lag-1 azimuth correlation per (azimuth block, range block): CDE and SDE kernels (numba),
                 with plain-numpy references; per-block quality and SNR-aware validity flag.
- ``rangecomp``  range compression (matched filter from the replica or the chirp parameters) used by the
                 range-compressed CDE, MLCC/MLBF and map-drift.
- ``ambiguity``  PRF ambiguity from a predicted absolute centroid, margins, the half-integer case,
                 unwrapping of the baseband centroid over blocks.
- ``polyfit``    weighted 2-D polynomial fit (range x azimuth) with outlier flags.
- ``dataonly``   MLCC / MLBF data-only ambiguity resolution with an honest confidence.
- ``geometry``   fdc and fr from orbit + attitude (full vector form and the closed form [Koh2003, eq. 6],
                 look-angle inversion, exact -(2/lam) d2R/deta2) over the terrain under the beam.
- ``lookbalance`` the look-balance centroid (used by the ``lb`` estimator).
- ``mapdrift``   data-driven Doppler rate by map-drift autofocus.
- ``plot``       the ``--plot`` PNG.

The model and its summary are shared types: :class:`sarcli.model.doppler.PolyDoppler`,
:class:`sarcli.model.doppler_summary.DopplerSummary`.

Sign conventions: a scatterer at one-way range R contributes exp(-j*4*pi*R/lam), so the Doppler
frequency is f = -(2/lam) dR/deta, the centroid is positive when the beam looks forward (squint towards
the flight direction), and the Doppler rate fr = -(2/lam) d2R/deta2 is negative for a side-looking radar.
"""
