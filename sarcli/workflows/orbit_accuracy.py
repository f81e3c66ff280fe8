"""Workflow ``orbit_accuracy``: accuracy vs cost of the orbit knobs, computed now (a few seconds).

Hermite order N = 2..12 against a J2-integrated Radarsat-1-like truth sampled 15 x 480 s (max position
and velocity error away from the span ends and in the end intervals, evaluations per CPU second); exact
vs small-angle attitude rotation at 0, 1, 10, 100 x the Radarsat-1 limits (pointing, Doppler and ground
error); the Earth-frame model differences in metres at the ground (``orbit.accuracy``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sarcli.workflows import base


@dataclass(frozen=True)
class Config:
    """plot: also write a PNG of the position/velocity error vs time per N; timing: measure evaluations
    per CPU second."""

    plot: Path | None = None
    timing: bool = True


@dataclass
class Report(base.Report):
    """The tables (``--json`` keys): hermite, truth_floor, attitude, frames."""

    hermite: list[dict[str, Any]]
    truth_floor: dict[str, float]
    attitude: list[dict[str, Any]]
    frames: list[dict[str, Any]]
    timing: bool

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        d.pop("timing")
        return d

    def lines(self) -> list[str]:
        out = ["Hermite interpolation, 15 x 480 s J2 truth (interior = >= 2 spacings from the ends):",
               f"{'N':>3} {'pos int. m':>11} {'vel int. m/s':>13} {'pos ends m':>11} {'vel ends m/s':>13}"
               + (f" {'M evals/s':>10}" if self.timing else "")]
        for r in self.hermite:
            out.append(f"{r['n_nodes']:3d} {r['pos_err_interior_m']:11.3g} {r['vel_err_interior_mps']:13.3g} "
                       f"{r['pos_err_ends_m']:11.3g} {r['vel_err_ends_mps']:13.3g}"
                       + (f" {r['evals_per_s'] / 1e6:10.1f}" if self.timing else ""))
        fl = self.truth_floor
        out.append(f"  (truth floor {fl['pos_m']:.2g} m, {fl['vel_mps']:.2g} m/s)")
        out.append("Control rotation, exact vs small-angle (x Radarsat-1 limits pitch 0.03 deg, yaw 0.004 deg):")
        for r in self.attitude:
            out.append(f"  x{r['scale']:<5g} pointing {r['pointing_err_urad']:10.4g} urad, "
                       f"Doppler {r['doppler_err_hz']:10.4g} Hz, ground {r['ground_err_m']:10.4g} m")
        out.append("Earth frame model, metres at the ground:")
        for r in self.frames:
            out.append(f"  {r['hypothesis']:<48} {r['ground_m']:10.1f} m")
        return out


def _accuracy_plot(path: Path, truth) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from sarcli.io.atomic import atomic_path

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, dpi=100)
    for N in (2, 4, 6, 8, 10, 12):
        p, v, _ = truth.sv.interpolate(truth.t, N)
        ax1.semilogy(truth.t, np.maximum(np.linalg.norm(p - truth.r, axis=1), 1e-9), lw=0.8, label=f"N = {N}")
        ax2.semilogy(truth.t, np.maximum(np.linalg.norm(v - truth.v, axis=1), 1e-12), lw=0.8)
    for ax in (ax1, ax2):
        for tn in truth.sv.time:
            ax.axvline(tn, color="0.85", lw=0.5, zorder=0)
    ax1.axhline(1e-3, color="k", ls="--", lw=0.8)
    ax2.axhline(1e-6, color="k", ls="--", lw=0.8)
    ax1.set_ylabel("position error (m)")
    ax2.set_ylabel("velocity error (m/s)")
    ax2.set_xlabel("time after first state vector (s); grey: nodes; dashed: acceptance bars")
    ax1.set_title("Hermite interpolation of 15 x 480 s state vectors vs J2 truth")
    ax1.legend(ncol=3, fontsize=8)
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


def run(config: Config, provenance: base.Provenance | None = None, progress: base.Progress | None = None) -> Report:
    """Compute the tables (module docstring) and the optional plot."""
    from orbit import accuracy as A

    with base.using(provenance):
        truth = A.rs1_truth()
        report = Report(hermite=A.hermite_table(truth=truth, timing=config.timing, n_times=200_000),
                        truth_floor=A.truth_floor(truth), attitude=A.attitude_table(truth=truth),
                        frames=A.frame_table(), timing=config.timing)
        if config.plot is not None:
            _accuracy_plot(config.plot, truth)
        return report
