"""Reader plug-in ``nisar-l0b``: a NISAR L0B (RRSD) HDF5 file, from NISAR or repackaged by ISCE3 (ALOS ...).

Decoding is in :mod:`sarcli.io.nisar.l0b`; this adapts it to the reader interface (:mod:`sarcli.io.readers`).
One product per frequency / transmit group (the receive polarizations of a group are its channels),
named ``"A_HH"``, ``"A_HH_HV"``, ...
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.io.readers import Ingested

POLARIZATIONS = ("HH", "HV", "VH", "VV", "LH", "LV", "RH", "RV")


@dataclass(frozen=True)
class NisarL0bOptions:
    """frequencies: sub-bands to read (A, B; default all); polarizations: transmit-receive pairs to read
    (default all)."""

    frequencies: tuple[str, ...] = ()
    polarizations: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        bad = [f for f in self.frequencies if f not in ("A", "B")]
        if bad:
            raise ConfigError(f"frequencies must be A or B, got {', '.join(bad)}")
        bad = [p for p in self.polarizations if p not in POLARIZATIONS]
        if bad:
            raise ConfigError(f"polarizations must be among {', '.join(POLARIZATIONS)}, got {', '.join(bad)}")


class NisarL0bReader:
    name = "nisar-l0b"
    description = "NISAR L0B raw data (HDF5, RRSD layout; also ALOS repackaged by ISCE3): FILE.h5"
    Options = NisarL0bOptions

    def sniff(self, sources: Sequence[Path]) -> bool:
        from sarcli.io.nisar.l0b import sniff_l0b

        return len(sources) == 1 and sniff_l0b(sources[0])

    def read(self, sources: Sequence[Path], options: NisarL0bOptions) -> Ingested:
        from sarcli.io.nisar.l0b import read_l0b

        if len(sources) != 1:
            raise ConfigError("a NISAR L0B is one HDF5 file: give one path")
        path = Path(sources[0])
        c = read_l0b(path, options.frequencies, options.polarizations)
        return Ingested(c.products, (path,), {"format": self.name, **to_mapping(options)}, c.notes)


READER = NisarL0bReader()
