"""Radarsat-1 CEOS RAW: reader (``read_ceos``) and writer (``write_ceos``).

Modules: ``fields`` (record header, ASCII/binary fields), ``aux`` (the 50-byte aux block and the timing
it encodes), ``samples`` (4-bit I/Q decoding, numba + numpy reference), ``leader`` (leader records),
``datafile`` (signal data file walking and records), ``reader``, ``writer``.
Format facts and traps: ``docs/products.md`` (CEOS section) and the shared ``ceos-radarsat-raw.md``.
"""

from sarcli.io.ceos.reader import MISSING_POLICIES, find_scene_files, read_ceos
from sarcli.io.ceos.writer import CeosExportError, write_ceos

__all__ = ["MISSING_POLICIES", "CeosExportError", "find_scene_files", "read_ceos", "write_ceos"]
