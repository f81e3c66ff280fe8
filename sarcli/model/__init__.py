"""The data model shared by every part of sarcli: pure dataclasses and Protocols, no file formats.

- :mod:`sarcli.model.constants`: physical constants (one definition each);
- :mod:`sarcli.model.raw`: ``Radar``, ``Orbit``, ``Attitude``, ``RawProduct``;
- :mod:`sarcli.model.slc`: ``SLC``, ``DopplerUsed``;
- :mod:`sarcli.model.doppler`: the ``DopplerModel`` Protocol, ``PolyDoppler``, ``GeometricDoppler``;
- :mod:`sarcli.model.doppler_summary`: ``DopplerSummary`` (what a Doppler estimate reports);
- :mod:`sarcli.model.poly`: ``Poly2D``;
- :mod:`sarcli.model.gbsar`: ``Site``, ``Antenna``, ``Scan``, ``GbsarImage``.

Layering: ``model`` imports only ``orbit``, numpy and ``sarcli.errors``; readers and writers
(``sarcli.io``) and processing build on it.
"""
