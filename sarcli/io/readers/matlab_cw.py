"""Reader plug-in ``matlab-cw``: a Cumming & Wong MATLAB raw block and its run-parameter file.

Decoding is in :mod:`sarcli.io.matlab`; this adapts it to the reader interface (:mod:`sarcli.io.readers`).
Sources: ``DATA.mat PARAMS.mat`` (or ``--matlab DATA.mat --params PARAMS.mat`` on the command line).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sarcli.config import to_mapping
from sarcli.errors import ConfigError
from sarcli.io.readers import Ingested


@dataclass(frozen=True)
class MatlabOptions:
    """epoch: ISO-8601 UTC time of the first line (a block carries none); variable: the array's name in
    the data file (default ``data``, or the only variable)."""

    epoch: str | None = None
    variable: str | None = None


def _is_mat(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(10).startswith(b"MATLAB 5.0")


class MatlabCwReader:
    name = "matlab-cw"
    description = "Cumming & Wong MATLAB raw block: DATA.mat PARAMS.mat"
    Options = MatlabOptions

    def sniff(self, sources: Sequence[Path]) -> bool:
        return len(sources) == 2 and all(Path(s).is_file() and _is_mat(Path(s)) for s in sources)

    def read(self, sources: Sequence[Path], options: MatlabOptions) -> Ingested:
        from sarcli.io.matlab import read_matlab_block

        if len(sources) != 2:
            raise ConfigError("a MATLAB block needs two files: DATA.mat PARAMS.mat")
        data, params = (Path(s) for s in sources)
        raw = read_matlab_block(data, params, variable=options.variable, epoch_utc=options.epoch)
        return Ingested({"": raw}, (data, params), {"format": self.name, **to_mapping(options)})


READER = MatlabCwReader()
