"""NISAR HDF5 products in and out: L0B (RRSD) raw echoes and L1 RSLC focused images.

NISAR (and ISCE3, which repackages ALOS-1/2 and other sensors into the same layouts) stores a product
under ``/science/{LSAR|SSAR}/``: ``identification/`` (mission, look direction, pass direction, times),
and a product group (``RRSD`` for L0B, ``RSLC`` for the focused image) with ``swaths/frequency{A,B}/``
for the data and ``lowRateTelemetry/`` (L0B) or ``metadata/`` (RSLC) for the orbit (ECEF state
vectors) and the attitude (quaternions). Times are float64 seconds after an epoch written in the
dataset's ``units`` attribute (``seconds since 2011-01-13 00:00:00``).

Modules:

- :mod:`.h5util`   the conventions shared by both products (band root, epochs in ``units``, strings,
                   complex32, one-line errors for missing or malformed items);
- :mod:`.attitude` quaternions (antenna RCS frame -> ECEF) and their conversion to sarcli's attitude
                   convention (pitch, yaw of the beam-centre plane in the flight frame);
- :mod:`.l0b`      the L0B reader: :func:`~.l0b.sniff_l0b`, :func:`~.l0b.read_l0b`;
- :mod:`.rslc`     the RSLC writer and reader: :func:`~.rslc.write_rslc`, :func:`~.rslc.read_rslc`,
                   :func:`~.rslc.sniff_rslc`.

The layout facts (dataset names, units, conventions) come from ISCE3's NISAR readers and writers
(github.com/isce-framework/isce3, ``python/packages/nisar/products``) and the NISAR product
specifications they implement [NISAR-L0B], [NISAR-RSLC]; no ISCE3 code is used. See docs/nisar.md.
"""
