"""Radarsat-1 RAW signal data file: imagery-options file descriptor (16252 B) [S B-17] and one
variable-length signal data record per range line [S B-18]:

    record = 192-byte prefix (``sarcli.io.ceos.signal``)
           + 50-byte aux block (``sarcli.io.ceos.radarsat1.aux``)
           + replica (2 * floor(44.559 us / T_b) bytes, only when the aux replica bit is set)
           + echo samples (2 bytes per complex sample, ``sarcli.io.ceos.radarsat1.samples``)

The generic walk (``sarcli.io.ceos.signal.index_signal_records``) finds the records by their headers,
never by assuming a fixed length or a replica period (doc trap 1); ``index_records`` adds the aux
block of every line and the Radarsat-1 consistency checks; ``build_descriptor`` is the writer's side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sarcli.errors import FormatError
from sarcli.io.ceos import fields as F
from sarcli.io.ceos.radarsat1 import aux as A
from sarcli.io.ceos.signal import PREFIX_BYTES, SignalRecords, index_signal_records

DESCRIPTOR_BYTES = 16252
ECHO_START = PREFIX_BYTES + A.AUX_BYTES  # 242: first byte after the aux block


@dataclass
class RecordIndex(SignalRecords):
    """The signal records, with every field of the aux block (``aux.FIELDS``, (n,) int64 each) per line."""

    aux: dict[str, np.ndarray]
    n_samples: int
    replica_bytes: int

    def echo_offsets(self) -> np.ndarray:
        """Byte offset of the first echo sample of every record (after any replica)."""
        return self.offsets + ECHO_START + self.aux["replica_present"] * self.replica_bytes


def index_records(buf: np.ndarray, src: str) -> RecordIndex:
    """Walk and validate all complete signal records of a Radarsat-1 RAW data file held in ``buf`` (uint8)."""
    rec = index_signal_records(buf, src, min_length=ECHO_START)
    offsets, lengths = rec.offsets, rec.lengths
    aux_bytes = buf[offsets[:, None] + PREFIX_BYTES + np.arange(A.AUX_BYTES)]
    aux = {name: A.get_field(aux_bytes, name) for name in A.FIELDS}
    if not np.any(aux["sync"] == A.AUX_SYNC):
        raise FormatError(f"{src}: no aux block carries the Radarsat-1 sync marker 0x352EF853 "
                          "(not Radarsat-1 RAW signal data)")
    adc = np.unique(aux["adc_code"])
    if adc.size != 1 or int(adc[0]) > 2:
        raise FormatError(f"{src}: ADC rate codes {adc.tolist()} (need one of 0, 1, 2 for the whole file)")
    dur = np.unique(aux["window_duration_code"])
    if dur.size != 1:
        k = int(np.flatnonzero(aux["window_duration_code"] != aux["window_duration_code"][0])[0])
        raise FormatError(f"{src}: the number of samples per line changes at line {k + 1} "
                          "(receive-window duration code); not supported")
    n_samples = int(A.samples_from_code(dur[0]))
    rep_bytes = 2 * A.replica_samples(int(adc[0]))
    expected = ECHO_START + aux["replica_present"] * rep_bytes + 2 * n_samples
    bad = np.flatnonzero(lengths != expected)
    if bad.size:
        k = int(bad[0])
        raise FormatError(
            f"{src}: inconsistent record length at line {k + 1} (byte {offsets[k]}): header says "
            f"{lengths[k]} bytes, the aux block implies {expected[k]} ({n_samples} samples, replica "
            f"flag {aux['replica_present'][k]})")
    return RecordIndex(**vars(rec), aux=aux, n_samples=n_samples, replica_bytes=rep_bytes)


def build_descriptor(n_records: int, max_length: int, n_samples: int, software_id: str) -> bytes:
    """The 16252-byte imagery-options file descriptor of a RAW data file."""
    d = F.file_descriptor(DESCRIPTOR_BYTES, 2, "DAT_01.001", software_id)
    F.put(d, 181, F.format_int(n_records, 6) + F.format_int(max_length, 6))
    F.put(d, 217, F.format_int(8, 4) + F.format_int(2, 4) + F.format_int(2, 4))
    F.put(d, 237, F.format_int(n_records, 8) + F.format_int(0, 4) + F.format_int(n_samples, 8))
    F.put(d, 277, F.format_int(PREFIX_BYTES - F.HEADER_BYTES, 4) + F.format_int(2 * n_samples, 8)
          + F.format_int(0, 4))
    F.put(d, 297, b"  13 4PB  49 2PB  45 4PB  21 4PB  29 4PB")
    F.put(d, 401, F.format_text("COMPLEX INTEGER*2", 28) + F.format_text("CI*2", 4))
    F.put(d, 433, F.format_int(4, 4) + F.format_int(0, 4) + F.format_int(15, 8))
    return bytes(d)
