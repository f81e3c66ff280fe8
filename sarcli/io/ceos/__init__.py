"""CEOS SAR files: what every CEOS format shares, and the sensor-specific layouts built on it.

Generic (any CEOS SAR product, "CEOS-SAR-CCT" family):

- ``fields``: the 12-byte record header, record type codes, ASCII (``In``, ``Fw.d``, ...) and
  big-endian binary fields, blank-padded writing;
- ``records``: walking a file record by record (each header gives the record's length), the file
  descriptor record that opens every file;
- ``signal``: the signal data file: its descriptor's record count, the signal data records and
  their 192-byte prefix (line number, acquisition date and time of day, chirp length).

Sensor specifics live in sub-packages: ``radarsat1`` (the 50-byte aux block, 4-bit samples, leader
values, beam table, reader ``read_ceos`` and writer ``write_ceos``). Format facts and traps:
``docs/products.md`` (CEOS section) and ``docs/ingest.md``.
"""
