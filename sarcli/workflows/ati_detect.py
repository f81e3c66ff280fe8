"""Workflow ``ati_detect``: RD-focus both channels of a two-channel raw product, co-register, form the
ATI interferogram and detect movers (CFAR on magnitude and on the ATI phase; ``sarcli.ati``).

Shared by the ATI workflows: :func:`load_two_channel`, :func:`cfar_knobs`, :func:`write_product`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.config import to_mapping
from sarcli.errors import ConfigError, ProductError
from sarcli.workflows import base

_log = logging.getLogger(__name__)


def check_pfa(pfa: float) -> None:
    """A false-alarm probability per pixel in (0, 0.1)."""
    if not 0.0 < pfa < 0.1:
        raise ConfigError(f"pfa must be in (0, 0.1), got {pfa}")


@dataclass(frozen=True)
class Config:
    """raw: two-channel raw product (HDF5) of a straight flight (LOCAL frame); output: write an ATI
    product (images, ATI phase, candidates); pfa: false-alarm probability per pixel of each CFAR test."""

    raw: Path
    output: Path | None = None
    pfa: float = 1e-6

    def __post_init__(self) -> None:
        check_pfa(self.pfa)


@dataclass
class Report(base.Report):
    """candidates (one dict per detected mover) and the detection summary (``--json`` keys)."""

    candidates: list[dict[str, Any]]
    summary: dict[str, Any]
    output: str | None = None

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        d.pop("output")
        return d

    def lines(self) -> list[str]:
        out = [f"mover {c['id']}: t = {c['azimuth_time_s']:.4f} s, R = {c['slant_range_m']:.1f} m, ATI phase "
               f"{c['ati_phase_rad']:+.4f} rad, vx = {c['vx_mps']:+.2f} m/s, confidence {c['confidence']:.3f}"
               + (" (AMBIGUOUS: phase near +-pi)" if c["ati_ambiguous"] else "") for c in self.candidates]
        s = self.summary
        out.append(f"{len(self.candidates)} candidate(s); bright-mover LOS speed floor "
                   f"{s['min_vr_los_bright_mps']:.2f} m/s, blind speed {s['blind_speed_mps']:.1f} m/s")
        return out + ([f"wrote {self.output}"] if self.output else [])


def load_two_channel(path: Path) -> Any:
    """The raw product at ``path``, refused in one line unless it has two channels."""
    from sarcli.io.raw import read_raw

    raw = read_raw(path)
    if raw.n_channels < 2:
        raise ProductError(f"{path}: has {raw.n_channels} channel; ATI needs two (simulate with second_channel)")
    return raw


def cfar_knobs(pfa: float) -> Any:
    from sarcli.ati.detect import CfarKnobs

    return CfarKnobs(pfa_magnitude=pfa, pfa_phase=pfa)


def write_product(out: Path, raw_path: Path, pair: Any, summary: dict, movers: list[dict], workflow: str,
                  config: Any, after: Any = None) -> None:
    """The ATI product: channel-0 image (and the compensated one), ATI phase, movers table, detection."""
    import numpy as np

    from sarcli.io.ati_product import write_ati

    params = {"command": workflow.removeprefix("ati_"), "workflow": workflow,
              "config": {k: v for k, v in to_mapping(config).items() if k != "output"}}
    write_ati(out, epoch_utc=pair.slc0.epoch_utc, t_ref_s=pair.t_ref, look_side=pair.slc0.look_side,
              azimuth_time=pair.slc0.azimuth_time, slant_range=pair.slc0.slant_range, image_before=pair.z0,
              ati_phase=np.angle(pair.z1 * np.conj(pair.z0)), movers=movers, detection=summary,
              image_after=after, parameters=params, inputs=(raw_path,))
    _log.info("wrote %s", out)


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Focus, co-register and detect (module docstring)."""
    from sarcli.ati.pipeline import detect_pair, focus_pair

    with base.using(provenance):
        base.refuse_overwriting_inputs([config.raw], [config.output])
        raw = load_two_channel(config.raw)
        pair = focus_pair(raw)
        cands, summary = detect_pair(pair, cfar_knobs(config.pfa))
        rows = [c.as_dict() for c in cands]
        if config.output is not None:
            write_product(config.output, config.raw, pair, summary, rows, "ati_detect", config)
        return Report(rows, summary, None if config.output is None else str(config.output))
