"""Radarsat-1 CEOS RAW: reader (``read_ceos``) and writer (``write_ceos``), on the generic CEOS layer
(:mod:`sarcli.io.ceos`: record walking, fields, the signal data file).

Radarsat-1 specifics: ``aux`` (the 50-byte aux block of every signal record and the timing it encodes,
the beam table), ``samples`` (4-bit I/Q decoding, numba + numpy reference), ``leader`` (the leader's
data set summary and platform position values), ``datafile`` (record index with the aux block, the
data file descriptor), ``reader``, ``writer``. The sensor-reader plug-in is
:mod:`sarcli.io.readers.ceos_rs1`.
"""

from sarcli.io.ceos.radarsat1.reader import MISSING_POLICIES, find_scene_files, read_ceos
from sarcli.io.ceos.radarsat1.writer import SCENE_FILES, CeosExportError, check_representable, write_ceos

__all__ = ["MISSING_POLICIES", "SCENE_FILES", "CeosExportError", "check_representable", "find_scene_files",
           "read_ceos", "write_ceos"]
